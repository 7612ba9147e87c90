// orbis/calibration/calibrate.hpp — camera calibration from views of a known pattern.
//
// Contract: detectView() turns one grey image into a CalibrationView (the pattern's corners, or
// none, and how sharp the board is); detectInFolder() does so for every image of a folder, in
// name order (the frame source `orbis calibrate images` uses; video and live sources hand their
// frames to detectView). calibrate() then
//   1. keeps the views that show the pattern, are sharp enough (chessboard: OpenCV's edge-rise
//      width under maxEdgeWidth pixels) and are not near-duplicates of a kept view (mean corner
//      displacement under duplicateFraction of the image diagonal), and, past maxViews, a
//      well-spread subset (farthest-point sampling over where the board is, how big, how turned
//      and how tilted);
//   2. fits the model with OpenCV (pinhole: cv::calibrateCamera, k1 k2 p1 p2 k3; fisheye:
//      cv::fisheye::calibrate, Kannala-Brandt k1..k4, no skew) — docs/notes/2026-11-26-fisheye.md
//      says why OpenCV's solvers rather than orbis's LM;
//   3. names the views whose RMS error exceeds outlierFactor x the median (and 0.5 px) as
//      outliers and fits once more without them;
//   4. gives each parameter's standard deviation (the residual σ times the square root of the
//      diagonal of the inverse normal matrix with the board poses marginalised: OpenCV's
//      stdDeviationsIntrinsics for the pinhole, the same computed here from a numeric Jacobian
//      for the fisheye).
// Every input it cannot use throws orbis::Error naming `source` and saying what to do: no view
// shows the pattern, fewer than minViews usable views, views of different sizes, a fit that
// fails or leaves the focal length or principal point unobservable (a degenerate set: the board
// square-on to the camera in every view (depth across it varying under minDepthSpread), the board
// planes of all views within minTiltDegrees of each other, or σ of the focal length or principal
// point beyond the options' bounds).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "orbis/calibration/pattern.hpp"
#include "orbis/camera/distortion.hpp"
#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/geometry/se3.hpp"

namespace orbis::calibration {

// The lens model a calibration fits: pinhole with radial-tangential distortion, or Kannala–Brandt
// fisheye.
enum class LensModel { Pinhole, Fisheye };  // pinhole: radial-tangential distortion
// "pinhole" or "fisheye"; throws orbis::Error(source) otherwise.
LensModel parseLensModel(const std::string& name, const std::string& source = "argument --model");
// The model's name.
const char* toString(LensModel model);

// A calibrated camera: intrinsics and the lens model's distortion.
struct CalibratedCamera {
  // Pinhole or fisheye.
  LensModel model = LensModel::Pinhole;
  // @{
  // Image size, pixels.
  int width = 0, height = 0;
  // @}
  // @{
  // Focal lengths and principal point, pixels.
  double fx = 0, fy = 0, cx = 0, cy = 0;
  // @}
  std::vector<double> distortion;  // pinhole: k1 k2 p1 p2 k3; fisheye: k1 k2 k3 k4

  // The pinhole part.
  PinholeCamera<double> pinhole() const { return {fx, fy, cx, cy, width, height}; }
  // The radial-tangential distortion (pinhole model).
  RadTanDistortion<double> radTan() const;
  KannalaBrandtCamera<double> fisheye() const;  // maxAngle: fieldOfViewAngle()
  // The largest angle off axis any pixel of the image sees (radians; fisheye: within the
  // polynomial's increasing range).
  double fieldOfViewAngle() const;
  Eigen::Vector2d project(const Eigen::Vector3d& pc) const;  // through the lens
  // The unit ray of a pixel.
  Eigen::Vector3d bearing(const Eigen::Vector2d& px) const;
};

// One image of the pattern: its name, size and detected corners.
struct CalibrationView {
  // @{
  // File name, image size, and the corners found (none: no pattern).
  std::string name;
  cv::Size imageSize;
  std::optional<PatternDetection> detection;
  // @}
  double edgeWidth = 0;  // chessboard: mean black-to-white rise in pixels (smaller is sharper)
};

// Detects the pattern in a grey image.
CalibrationView detectView(const cv::Mat& gray, const std::string& name, const CalibrationPattern& pattern);
// Every image file (png, jpg, jpeg, bmp, tif, tiff, pgm, ppm) of `folder`, sorted by name.
// onImage(done, total) reports progress. Throws orbis::Error for a missing or image-less folder.
std::vector<CalibrationView> detectInFolder(const std::filesystem::path& folder, const CalibrationPattern& pattern,
                                            const std::function<void(std::size_t, std::size_t)>& onImage = {});

// What calibrate() accepts and how it selects views.
struct CalibrationOptions {
  // Pinhole or fisheye.
  LensModel model = LensModel::Pinhole;
  // @{
  // Fewest views to calibrate from, and most views used (a well-spread subset).
  int minViews = 6;
  int maxViews = 40;
  // @}
  double maxEdgeWidth = 4.0;        // pixels
  double duplicateFraction = 0.01;  // of the image diagonal
  // Views whose error exceeds this × the median are outliers.
  double outlierFactor = 3.0;
  // Refused as degenerate when σ(fx)/fx or σ(fy)/fy exceeds this, or σ(cx), σ(cy) exceed
  // maxPrincipalPointSigma of the image width.
  double maxRelativeFocalSigma = 0.02;
  // Largest σ(cx), σ(cy) as a share of the image width.
  double maxPrincipalPointSigma = 0.05;
  // Refused as degenerate when no two views' board planes differ in orientation by this much.
  double minTiltDegrees = 5.0;
  // Refused as degenerate when in no view the board's depth varies across it by this share of its
  // distance (a board square-on in every view: focal length and distance are interchangeable).
  double minDepthSpread = 0.03;
};

// What became of one input view.
struct ViewOutcome {
  // @{
  // Its name, and whether it was used.
  std::string name;
  bool used = false;
  // @}
  std::string rejected;  // why not used: "no pattern", "blurred", "duplicate of X", "not selected", "outlier"
  // Corners detected.
  int corners = 0;
  double rms = 0;        // pixels, for fitted views
  // @{
  // Whether it was an outlier, and its edge width (px).
  bool outlier = false;
  double edgeWidth = 0;
  // @}
};

// The result of a calibration.
struct CalibrationResult {
  // The calibrated camera.
  CalibratedCamera camera;
  std::vector<std::string> parameterNames;  // fx fy cx cy then the distortion's
  // @{
  // The parameters and their standard deviations.
  std::vector<double> parameters, standardDeviations;
  // @}
  double rms = 0;  // pixels, over every corner of the used views
  // Views used.
  int viewsUsed = 0;
  std::vector<ViewOutcome> views;  // one per input view, in input order
  std::vector<SE3d> cameraFromBoard;  // per used view, in the order views lists them
  // Names of the used views.
  std::vector<std::string> usedNames;
  std::vector<std::vector<cv::Point2f>> usedCorners;  // per used view: for the coverage picture
  // What the user should know (few views, poor coverage, ...).
  std::vector<std::string> warnings;
};

// The pose OpenCV's rotation vector and translation describe.
SE3d poseFromRotationVector(const cv::Vec3d& rvec, const cv::Vec3d& tvec);
// Pixels of `camera` undistorted to its normalised image plane (x/z, y/z).
std::vector<cv::Point2f> undistortToPlane(const CalibratedCamera& camera, const std::vector<cv::Point2f>& pixels);

// Calibrates from detected views (OpenCV's calibration for the chosen model), selecting views and
// rejecting blurred, duplicate and outlier ones; throws orbis::Error naming source when too few
// views or a degenerate set.
CalibrationResult calibrate(const std::vector<CalibrationView>& views, const CalibrationPattern& pattern,
                            const CalibrationOptions& options, const std::string& source);

}  // namespace orbis::calibration
