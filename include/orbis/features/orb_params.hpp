// orbis/features/orb_params.hpp — parameters of the ORB extractor (settings keys ORBextractor.*).
//
// Contract: plain values with ORB-SLAM2's defaults; the settings reader fills them from
// ORBextractor.nFeatures, .scaleFactor, .nLevels, .iniThFAST and .minThFAST, and the optional
// orbis key ORBextractor.rightFeaturesFactor.
#pragma once

namespace orbis {

// The extractor's parameters (settings ORBextractor.*).
struct OrbParams {
  int features = 1000;       // total keypoint budget over all pyramid levels
  float scaleFactor = 1.2f;  // ratio between consecutive pyramid levels
  int levels = 8;            // pyramid levels
  int iniThFast = 20;        // FAST threshold tried first in each grid cell
  int minThFast = 7;         // fallback FAST threshold for cells where nothing was found
  // Stereo only: the right image's budget is features x this. The right keypoints serve only as
  // stereo partners; 1 is ORB-SLAM2 (see Stereo in sensor/sensor.hpp for what 3 changes).
  int rightFeaturesFactor = 1;
};

}  // namespace orbis
