// orbis/calibration/stereo_calibrate.hpp — calibration of a stereo rig from pairs of pattern views.
//
// Contract: calibrateStereo() takes the views of the left and right camera, pair i being
// left[i] and right[i] (taken at the same moment), and
//   1. calibrates each camera on its own with calibrate() (every view of that camera counts, with
//      the same selection and rejection as a single camera);
//   2. fits the rig's extrinsics (rightFromLeft: x_right = R x_left + t) over the pairs whose
//      views both cameras kept, with the intrinsics fixed (orbis's Gauss-Newton over the rig and
//      the board poses, pairs inconsistent with the others left out; for pinholes OpenCV's
//      stereoCalibrate when it fits at least as well), and gives the baseline's standard
//      deviation (residual σ times the square root of the inverse normal matrix, board poses
//      marginalised, numeric Jacobian: the same quantity calibrate() reports per parameter);
//   3. rectifies the pair (orbis::rectifyStereo: cv::stereoRectify, or fisheye::stereoRectify
//      to a pinhole pair; alpha/balance 0, only valid pixels) into the RectifiedStereoCamera
//      `orbis run` works on, with the LEFT./RIGHT. blocks of ORB-SLAM2's stereo settings.
// Throws orbis::Error naming `source` and saying what to do for: different numbers of left and
// right views, cameras of different image sizes, fewer than minViews usable pairs, a rig whose
// right camera is not to the right of the left, and everything calibrate() refuses (its source
// naming the camera: "SOURCE (left camera)").
#pragma once

#include <string>
#include <vector>

#include "orbis/calibration/calibrate.hpp"
#include "orbis/camera/rectification.hpp"

namespace orbis::calibration {

// What became of one stereo pair in the extrinsics' fit.
struct StereoPairOutcome {
  // @{
  // The left view's name, and whether the pair was used for the extrinsics.
  std::string name;
  bool used = false;
  // @}
  std::string rejected;  // why not: "no pattern in left", "left: blurred", "too few common corners", ...
  // @{
  // RMS reprojection error of the pair's corners in each camera under the fitted rig (pixels).
  double rmsLeft = 0, rmsRight = 0;
  // @}
};

// The result of a stereo calibration: both cameras, the extrinsics, the rectification.
struct StereoCalibrationResult {
  // @{
  // Each camera's own calibration.
  CalibrationResult left, right;
  // @}
  SE3d rightFromLeft;        // x_right = R x_left + t
  double baseline = 0;       // |t|, metres
  double baselineSigma = 0;  // metres (intrinsics taken as exact)
  double rms = 0;            // pixels, over both cameras' corners of the used pairs
  // Pairs used for the extrinsics.
  int pairsUsed = 0;
  std::vector<StereoPairOutcome> pairs;  // one per input pair
  // The rectified pair: camera (fx, fy, cx, cy, baseline), LEFT./RIGHT. blocks and remap tables.
  StereoRectification rectification;
  // What the user should know.
  std::vector<std::string> warnings;
};

// The rectification of a rig of two calibrated cameras (x_right = rightFromLeft x_left).
StereoRectification rectifyRig(const CalibratedCamera& left, const CalibratedCamera& right, const SE3d& rightFromLeft);

// Calibrates a stereo rig; see the file comment. options.model applies to both cameras.
StereoCalibrationResult calibrateStereo(const std::vector<CalibrationView>& left,
                                        const std::vector<CalibrationView>& right, const CalibrationPattern& pattern,
                                        const CalibrationOptions& options, const std::string& source);

// The rig's two cameras written as ORB-SLAM2's rectified stereo settings (Camera.* the rectified
// pinhole, Camera.bf, LEFT./RIGHT. K D R P width height; a fisheye pair adds LEFT.type and
// RIGHT.type: "KannalaBrandt8" with k1..k4 in D), which `orbis run --settings` takes for raw
// stereo frames and rectifies them on load.
void writeStereoCalibrationSettings(const std::filesystem::path& file, const StereoCalibrationResult& result,
                                    double fps = 30.0);

// `orbis calibrate --json` of a stereo rig: the left camera's keys (fx fy cx cy distortion rms
// views_used model ...) at the top, `right` (the same keys), `baseline`, `baseline_std`,
// `stereo_rms`, `rotation_deg` (R as a rotation vector, degrees), `translation`, `rectified`
// (fx fy cx cy bf width height) and `pairs` (per pair: name used rms_left rms_right rejected).
std::string stereoCalibrationJson(const StereoCalibrationResult& result, const CalibrationPattern& pattern,
                                  const std::filesystem::path& settings);

// Writes left/ and right/ (each camera's report, as writeCalibrationReport), report.json (the
// stereo JSON) and, given a raw pair, rectified.png: the pair rectified side by side with
// horizontal lines every 32 rows (a point must sit on the same line in both halves).
void writeStereoCalibrationReport(const std::filesystem::path& folder, const StereoCalibrationResult& result,
                                  const CalibrationPattern& pattern, const cv::Mat& leftPreview,
                                  const cv::Mat& rightPreview);

}  // namespace orbis::calibration
