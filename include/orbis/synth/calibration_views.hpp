// orbis/synth/calibration_views.hpp — rendered views of a calibration board seen through a known
// camera, for testing calibration against exact intrinsics.
//
// Contract: renderCalibrationViews() draws the board (calibration::drawTarget) on a plane and
// renders `views` images of it through `camera` (pinhole with radial-tangential distortion, or a
// Kannala-Brandt fisheye: each sample's ray is the lens's exact unprojection) from seeded random
// poses: the board 25-60% of the image wide, anywhere in the field of view (a fisheye's to 80°
// off axis), tilted up to 45° about both board axes and turned any way, always wholly in view and
// seen from its printed side. Pixels are the mean of supersample² rays, each reading the board
// bilinearly at the pyramid level of the view's scale; off the board the background is grey;
// Gaussian noise of noiseSigma grey levels is added. Everything is a function of the options and
// the seed. writeCalibrationViews() writes them as OUTDIR/images/view_NNN.png with truth.yaml (the
// camera, as `orbis calibrate` writes its result) and poses.txt (camera-from-board, one 3x4 row-major
// matrix per view). Given a right camera, the views are of a stereo rig: every pose keeps the whole
// board in view of both cameras, each view gets the right camera's image too (rendered the same
// way, with its own noise), and writeCalibrationViews writes OUTDIR/left/ and OUTDIR/right/ with
// truth_left.yaml, truth_right.yaml and truth.yaml (the rig's rectified stereo settings, as
// `orbis calibrate --right` writes them).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/calibration/calibrate.hpp"
#include "orbis/calibration/pattern.hpp"
#include "orbis/geometry/se3.hpp"

namespace orbis::synth {

// What renderCalibrationViews renders: a printed pattern seen by a camera from random poses.
struct CalibrationViewsOptions {
  // @{
  // The pattern and the camera (pinhole or fisheye).
  calibration::CalibrationPattern pattern;
  calibration::CalibratedCamera camera;
  // @}
  // @{
  // Views, seed, rays per pixel along each axis, and image noise (grey levels).
  int views = 30;
  std::uint64_t seed = 1;
  int supersample = 3;
  double noiseSigma = 0.0;
  // @}
  int pixelsPerSquare = 64;  // of the printed board, before its pyramid
  // Camera-from-board poses to render instead of random ones (then `views` is ignored).
  std::vector<SE3d> poses;
  // Every board parallel to the image plane (a degenerate set, for testing that calibration
  // refuses it): random poses keep only the turn about the optical axis.
  bool squareOn = false;
  // A stereo rig: the right camera, and where it is (x_right = rightFromLeft x_left).
  std::optional<calibration::CalibratedCamera> rightCamera;
  SE3d rightFromLeft;  // the rig's extrinsics, with rightCamera
};

// One rendered view.
struct RenderedCalibrationView {
  cv::Mat image;  // CV_8UC1
  cv::Mat right;  // CV_8UC1, stereo rigs only
  // The board's pose in the (left) camera.
  SE3d cameraFromBoard;
};

// Renders views of the pattern with exact poses (the calibration tests' ground truth).
std::vector<RenderedCalibrationView> renderCalibrationViews(const CalibrationViewsOptions& options);

// Returns the images' folder (a stereo rig's: the left camera's).
std::filesystem::path writeCalibrationViews(const std::filesystem::path& outDir,
                                            const std::vector<RenderedCalibrationView>& views,
                                            const calibration::CalibratedCamera& camera);
// Writes a stereo rig's views (left/, right/, truth_left.yaml, truth_right.yaml, truth.yaml,
// poses.txt of the left camera); returns the left images' folder.
std::filesystem::path writeStereoCalibrationViews(const std::filesystem::path& outDir,
                                                  const std::vector<RenderedCalibrationView>& views,
                                                  const CalibrationViewsOptions& options);

}  // namespace orbis::synth
