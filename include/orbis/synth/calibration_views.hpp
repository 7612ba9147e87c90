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
// matrix per view).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/calibration/calibrate.hpp"
#include "orbis/calibration/pattern.hpp"
#include "orbis/geometry/se3.hpp"

namespace orbis::synth {

struct CalibrationViewsOptions {
  calibration::CalibrationPattern pattern;
  calibration::CalibratedCamera camera;
  int views = 30;
  std::uint64_t seed = 1;
  int supersample = 3;
  double noiseSigma = 0.0;
  int pixelsPerSquare = 64;  // of the printed board, before its pyramid
  // Camera-from-board poses to render instead of random ones (then `views` is ignored).
  std::vector<SE3d> poses;
};

struct RenderedCalibrationView {
  cv::Mat image;  // CV_8UC1
  SE3d cameraFromBoard;
};

std::vector<RenderedCalibrationView> renderCalibrationViews(const CalibrationViewsOptions& options);

// Returns the images' folder.
std::filesystem::path writeCalibrationViews(const std::filesystem::path& outDir,
                                            const std::vector<RenderedCalibrationView>& views,
                                            const calibration::CalibratedCamera& camera);

}  // namespace orbis::synth
