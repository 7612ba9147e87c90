#include "frame_preparation.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "orbis/util/error.hpp"

namespace orbis::run_detail {

namespace {

PinholeCamera<double>& pinholeOf(DatasetCamera& camera) {
  return std::visit(
      [](auto& c) -> PinholeCamera<double>& {
        if constexpr (std::is_same_v<std::decay_t<decltype(c)>, PinholeCamera<double>>) return c;
        else return c.pinhole;
      },
      camera);
}

// OpenCV's resize maps pixel centres: x' + 0.5 = s (x + 0.5).
void scaleIntrinsics(PinholeCamera<double>& p, double sx, double sy) {
  p.fx *= sx;
  p.fy *= sy;
  p.cx = (p.cx + 0.5) * sx - 0.5;
  p.cy = (p.cy + 0.5) * sy - 0.5;
}

}  // namespace

FrameScaling planScaling(DatasetCamera& camera, int inputWidth, int inputHeight, int resizeWidth,
                         const std::string& calibrationSource, bool adaptCalibrationSize, std::vector<std::string>& warnings) {
  FrameScaling plan;
  plan.inputWidth = inputWidth;
  plan.inputHeight = inputHeight;
  PinholeCamera<double>& pinhole = pinholeOf(camera);
  const int calibratedWidth = pinhole.width > 0 ? pinhole.width : inputWidth;
  const int calibratedHeight = pinhole.height > 0 ? pinhole.height : inputHeight;
  if (adaptCalibrationSize && (calibratedWidth != inputWidth || calibratedHeight != inputHeight)) {
    const double sx = static_cast<double>(inputWidth) / calibratedWidth, sy = static_cast<double>(inputHeight) / calibratedHeight;
    if (std::abs(sx - sy) > 0.01 * std::max(sx, sy))
      throw Error(calibrationSource, "Camera.width/height",
                  "the calibration is for " + std::to_string(calibratedWidth) + "x" + std::to_string(calibratedHeight) +
                      " images but the frames are " + std::to_string(inputWidth) + "x" + std::to_string(inputHeight) +
                      " (another aspect ratio: calibrate at this size)");
    warnings.push_back("the calibration (" + calibrationSource + ") is for " + std::to_string(calibratedWidth) + "x" +
                       std::to_string(calibratedHeight) + " images, the frames are " + std::to_string(inputWidth) + "x" +
                       std::to_string(inputHeight) + ": intrinsics scaled to the frames");
    scaleIntrinsics(pinhole, sx, sy);
    pinhole.width = inputWidth;
    pinhole.height = inputHeight;
  }
  plan.width = inputWidth;
  plan.height = inputHeight;
  if (resizeWidth > 0 && resizeWidth != inputWidth) {
    plan.imageScale = static_cast<double>(resizeWidth) / inputWidth;
    plan.width = resizeWidth;
    plan.height = static_cast<int>(std::lround(inputHeight * plan.imageScale));
    scaleIntrinsics(pinhole, static_cast<double>(plan.width) / inputWidth, static_cast<double>(plan.height) / inputHeight);
    pinhole.width = plan.width;
    pinhole.height = plan.height;
  }
  // Unscaled, the camera stays as calibrated (a width left 0 is still taken from the first image).
  return plan;
}

bool applyScaling(SourceFrame& frame, const FrameScaling& scaling) {
  if (frame.image.cols != scaling.inputWidth || frame.image.rows != scaling.inputHeight) return false;
  if (scaling.imageScale == 1.0) return true;
  const cv::Size size(scaling.width, scaling.height);
  // Area averaging when shrinking: no aliasing for the FAST detector to find corners in.
  const int interpolation = scaling.imageScale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR;
  cv::resize(frame.image, frame.image, size, 0, 0, interpolation);
  if (!frame.right.empty()) cv::resize(frame.right, frame.right, size, 0, 0, interpolation);
  if (!frame.depth.empty()) cv::resize(frame.depth, frame.depth, size, 0, 0, cv::INTER_NEAREST);
  return true;
}

}  // namespace orbis::run_detail
