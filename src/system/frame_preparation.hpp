// Private to the runner: bringing a source's frames and the camera to the size tracking runs at
// (--resize / Camera.newWidth, and frames recorded at another size than the calibration's).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "orbis/adapters/frame_source.hpp"

namespace orbis::run_detail {

// Decided once, from the first frame: the scale of the images and of the intrinsics.
struct FrameScaling {
  double imageScale = 1.0;       // delivered image -> tracked image
  int inputWidth = 0, inputHeight = 0;
  int width = 0, height = 0;     // tracked size
};

// The scaling for frames of inputSize: to resizeWidth when > 0. With adaptCalibrationSize (a
// source that brings no calibration of its own), the calibration's size (camera width/height,
// when set) must be the frames' or of their aspect: the intrinsics are then scaled to the frames
// with a warning; another aspect throws orbis::Error(calibrationSource). Dataset runs keep their
// calibration as it is. Scales `camera` in place (intrinsics and width/height) only when the
// images or the calibration are scaled.
FrameScaling planScaling(DatasetCamera& camera, int inputWidth, int inputHeight, int resizeWidth,
                         const std::string& calibrationSource, bool adaptCalibrationSize, std::vector<std::string>& warnings);

// Scales the frame's images by the plan (depth by nearest neighbour: no invented readings).
// Returns false, leaving it, when the frame is not of the planned input size.
bool applyScaling(SourceFrame& frame, const FrameScaling& scaling);

}  // namespace orbis::run_detail
