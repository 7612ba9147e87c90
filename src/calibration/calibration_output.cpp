// Settings, report and JSON of a calibration; see orbis/calibration/calibration_output.hpp.
#include "orbis/calibration/calibration_output.hpp"

#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/calibration/stereo_calibrate.hpp"
#include "orbis/features/orb_params.hpp"
#include "orbis/util/image_file.hpp"
#include "orbis/util/atomic_file.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"

namespace orbis::calibration {

namespace fs = std::filesystem;

namespace {

std::string real(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.10g", v);
  std::string s = text;
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

void writeText(const fs::path& file, const std::string& text) {
  if (file.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    if (ec) throw fileError(file.parent_path().string(), "cannot create folder: " + ec.message());
  }
  writeFileAtomically(file, std::span<const char>(text.data(), text.size()));
}

// The settings' common tail: frame rate, colour order and ORB-SLAM2's extractor at orbis's defaults.
std::string frameRateAndExtractor(double fps) {
  const OrbParams orb;
  std::string y = "Camera.fps: " + real(fps) + "\n# Colour order of the images (0: BGR, 1: RGB).\nCamera.RGB: 1\n\n";
  y += "ORBextractor.nFeatures: " + std::to_string(orb.features) + "\n";
  y += "ORBextractor.scaleFactor: " + real(std::round(orb.scaleFactor * 1e6) / 1e6) + "\n";
  y += "ORBextractor.nLevels: " + std::to_string(orb.levels) + "\nORBextractor.iniThFAST: " +
       std::to_string(orb.iniThFast) + "\nORBextractor.minThFAST: " + std::to_string(orb.minThFast) + "\n";
  return y;
}

cv::Mat cameraMatrix(const CalibratedCamera& c) { return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1); }

}  // namespace

void writeCalibrationSettings(const fs::path& file, const CalibratedCamera& c, double fps) {
  std::string y = "%YAML:1.0\n# Written by orbis calibrate: ORB-SLAM2 settings keys";
  y += c.model == LensModel::Fisheye ? " (ORB-SLAM3's for the fisheye).\n" : ".\n";
  y += "Sensor: \"mono\"\n\n";
  if (c.model == LensModel::Fisheye) y += "# Kannala-Brandt equidistant fisheye.\nCamera.type: \"KannalaBrandt8\"\n";
  y += "Camera.fx: " + real(c.fx) + "\nCamera.fy: " + real(c.fy) + "\nCamera.cx: " + real(c.cx) + "\nCamera.cy: " +
       real(c.cy) + "\n\n";
  if (c.model == LensModel::Fisheye) {
    y += "Camera.k1: " + real(c.distortion[0]) + "\nCamera.k2: " + real(c.distortion[1]) + "\nCamera.k3: " +
         real(c.distortion[2]) + "\nCamera.k4: " + real(c.distortion[3]) + "\n";
    y += "# The widest angle off axis the image sees, degrees (the polynomial is trusted up to it).\n";
    y += "Camera.maxAngle: " + real(std::floor(c.fieldOfViewAngle() * 180.0 / M_PI * 100.0) / 100.0) + "\n\n";
  } else {
    y += "Camera.k1: " + real(c.distortion[0]) + "\nCamera.k2: " + real(c.distortion[1]) + "\nCamera.p1: " +
         real(c.distortion[2]) + "\nCamera.p2: " + real(c.distortion[3]) + "\nCamera.k3: " + real(c.distortion[4]) +
         "\n\n";
  }
  y += "Camera.width: " + std::to_string(c.width) + "\nCamera.height: " + std::to_string(c.height) + "\n\n";
  y += frameRateAndExtractor(fps);
  writeText(file, y);
}

cv::Mat undistortToPinhole(const CalibratedCamera& c, const cv::Mat& image, PinholeCamera<double>* pinhole) {
  const cv::Size size(c.width, c.height);
  cv::Mat K = cameraMatrix(c), newK, mapX, mapY;
  if (c.model == LensModel::Fisheye) {
    const cv::Vec4d D(c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3]);
    cv::fisheye::estimateNewCameraMatrixForUndistortRectify(K, D, size, cv::Mat::eye(3, 3, CV_64F), newK, 0.0, size, 1.0);
    cv::fisheye::initUndistortRectifyMap(K, D, cv::Mat::eye(3, 3, CV_64F), newK, size, CV_32FC1, mapX, mapY);
  } else {
    newK = cv::getOptimalNewCameraMatrix(K, c.distortion, size, 0.0, size);
    cv::initUndistortRectifyMap(K, c.distortion, cv::Mat(), newK, size, CV_32FC1, mapX, mapY);
  }
  if (pinhole)
    *pinhole = {newK.at<double>(0, 0), newK.at<double>(1, 1), newK.at<double>(0, 2), newK.at<double>(1, 2), c.width,
                c.height};
  cv::Mat out;
  if (!image.empty()) cv::remap(image, out, mapX, mapY, cv::INTER_LINEAR);
  return out;
}

namespace {

// The keys of one camera's calibration, into an open JSON object.
void writeCameraFields(JsonWriter& w, const CalibrationResult& r, const CalibrationPattern& pattern,
                       const fs::path& settings) {
  const CalibratedCamera& c = r.camera;
  w.field("model", toString(c.model))
      .field("pattern", pattern.describe())
      .field("width", c.width)
      .field("height", c.height)
      .field("fx", c.fx)
      .field("fy", c.fy)
      .field("cx", c.cx)
      .field("cy", c.cy);
  w.key("distortion").beginArray();
  for (double d : c.distortion) w.value(d);
  w.endArray();
  w.key("parameters").beginObject();
  for (std::size_t k = 0; k < r.parameterNames.size(); ++k)
    w.key(r.parameterNames[k]).beginObject().field("value", r.parameters[k]).field("std", r.standardDeviations[k]).endObject();
  w.endObject();
  w.field("rms", r.rms).field("views_used", r.viewsUsed).field("views_total", r.views.size());
  if (c.model == LensModel::Fisheye) w.field("field_of_view_deg", 2.0 * c.fieldOfViewAngle() * 180.0 / M_PI);
  w.field("settings", settings.string());
  w.key("views").beginArray();
  for (const ViewOutcome& v : r.views) {
    w.beginObject().field("name", v.name).field("used", v.used).field("corners", v.corners);
    if (v.used || v.outlier) w.field("rms", v.rms);
    if (v.edgeWidth > 0) w.field("edge_width_px", v.edgeWidth);
    if (!v.rejected.empty()) w.field("rejected", v.rejected);
    w.endObject();
  }
  w.endArray();
  w.key("outliers").beginArray();
  for (const ViewOutcome& v : r.views)
    if (v.outlier) w.value(v.name);
  w.endArray();
  w.key("warnings").beginArray();
  for (const std::string& s : r.warnings) w.value(s);
  w.endArray();
}

}  // namespace

std::string calibrationJson(const CalibrationResult& r, const CalibrationPattern& pattern, const fs::path& settings) {
  JsonWriter w;
  w.beginObject();
  writeCameraFields(w, r, pattern, settings);
  w.endObject();
  return w.str();
}

void writeCalibrationReport(const fs::path& folder, const CalibrationResult& r, const CalibrationPattern& pattern,
                            const cv::Mat& preview) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw fileError(folder.string(), "cannot create the report folder: " + ec.message());
  writeText(folder / "report.json", calibrationJson(r, pattern, "") + "\n");
  const CalibratedCamera& c = r.camera;
  // Coverage: where the corners fell. Bare areas are where the distortion is extrapolated.
  cv::Mat coverage(c.height, c.width, CV_8UC3, cv::Scalar(32, 32, 32));
  for (std::size_t v = 0; v < r.usedCorners.size(); ++v) {
    cv::Mat hue(1, 1, CV_8UC3, cv::Scalar(static_cast<int>(v * 37 % 180), 200, 255)), bgr;
    cv::cvtColor(hue, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b colour = bgr.at<cv::Vec3b>(0, 0);
    for (const cv::Point2f& p : r.usedCorners[v]) cv::circle(coverage, p, 3, cv::Scalar(colour[0], colour[1], colour[2]), cv::FILLED);
  }
  char caption[200];
  std::snprintf(caption, sizeof caption, "%s: %d views, RMS %.3f px", toString(c.model), r.viewsUsed, r.rms);
  cv::putText(coverage, caption, cv::Point(10, 24), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  writeImageFile(folder / "coverage.png", coverage);
  if (!preview.empty()) writeImageFile(folder / "undistorted.png", undistortToPinhole(c, preview));
}

// --- stereo -------------------------------------------------------------------------------------

namespace {

// An OpenCV-style matrix entry of a settings file.
std::string yamlMatrix(const std::string& key, const Eigen::MatrixXd& m) {
  std::string y = key + ": !!opencv-matrix\n   rows: " + std::to_string(m.rows()) + "\n   cols: " +
                  std::to_string(m.cols()) + "\n   dt: d\n   data: [";
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) y += (r + c > 0 ? ", " : "") + real(m(r, c));
  return y + "]\n";
}

std::string rectificationBlock(const std::string& prefix, const RectificationBlock& b) {
  std::string y = prefix + "height: " + std::to_string(b.height) + "\n" + prefix + "width: " + std::to_string(b.width) + "\n";
  if (b.fisheye) {
    y += "# Kannala-Brandt equidistant fisheye: D holds k1 k2 k3 k4.\n" + prefix + "type: \"KannalaBrandt8\"\n";
    y += yamlMatrix(prefix + "D", Eigen::RowVector4d((*b.fisheye)[0], (*b.fisheye)[1], (*b.fisheye)[2], (*b.fisheye)[3]));
  } else {
    Eigen::Matrix<double, 1, 5> d;
    d << b.D.k1, b.D.k2, b.D.p1, b.D.p2, b.D.k3;
    y += yamlMatrix(prefix + "D", d);
  }
  return y + yamlMatrix(prefix + "K", b.K) + yamlMatrix(prefix + "R", b.R) + yamlMatrix(prefix + "P", b.P) + "\n";
}

}  // namespace

void writeStereoCalibrationSettings(const fs::path& file, const StereoCalibrationResult& r, double fps) {
  const PinholeCamera<double>& k = r.rectification.camera.pinhole;
  std::string y = "%YAML:1.0\n# Written by orbis calibrate: ORB-SLAM2's rectified stereo settings. Camera.* is the\n"
                  "# rectified pinhole both images share; LEFT./RIGHT. rectify raw frames to it on load.\n";
  y += "Sensor: \"stereo\"\n\n";
  y += "Camera.fx: " + real(k.fx) + "\nCamera.fy: " + real(k.fy) + "\nCamera.cx: " + real(k.cx) + "\nCamera.cy: " +
       real(k.cy) + "\n\nCamera.k1: 0.0\nCamera.k2: 0.0\nCamera.p1: 0.0\nCamera.p2: 0.0\n\n";
  y += "Camera.width: " + std::to_string(k.width) + "\nCamera.height: " + std::to_string(k.height) + "\n\n";
  y += "# Baseline (" + real(r.rectification.camera.baseline) + " m) times fx.\nCamera.bf: " +
       real(r.rectification.camera.baseline * k.fx) + "\n# Close/far depth threshold, in baselines.\nThDepth: 40.0\n\n";
  y += frameRateAndExtractor(fps) + "\n";
  y += rectificationBlock("LEFT.", r.rectification.left) + rectificationBlock("RIGHT.", r.rectification.right);
  writeText(file, y);
}

std::string stereoCalibrationJson(const StereoCalibrationResult& r, const CalibrationPattern& pattern,
                                  const fs::path& settings) {
  JsonWriter w;
  w.beginObject();
  writeCameraFields(w, r.left, pattern, settings);
  w.key("right").beginObject();
  writeCameraFields(w, r.right, pattern, settings);
  w.endObject();
  w.field("baseline", r.baseline).field("baseline_std", r.baselineSigma).field("stereo_rms", r.rms);
  w.field("pairs_used", r.pairsUsed);
  const Eigen::AngleAxisd turn(r.rightFromLeft.rotationMatrix());
  w.key("rotation_deg").beginArray();
  for (int i = 0; i < 3; ++i) w.value(turn.axis()[i] * turn.angle() * 180.0 / M_PI);
  w.endArray();
  w.key("translation").beginArray();
  for (int i = 0; i < 3; ++i) w.value(r.rightFromLeft.translation()[i]);
  w.endArray();
  const PinholeCamera<double>& k = r.rectification.camera.pinhole;
  w.key("rectified").beginObject().field("fx", k.fx).field("fy", k.fy).field("cx", k.cx).field("cy", k.cy)
      .field("bf", k.fx * r.rectification.camera.baseline).field("width", k.width).field("height", k.height).endObject();
  w.key("pairs").beginArray();
  for (const StereoPairOutcome& p : r.pairs) {
    w.beginObject().field("name", p.name).field("used", p.used);
    if (p.used) w.field("rms_left", p.rmsLeft).field("rms_right", p.rmsRight);
    if (!p.rejected.empty()) w.field("rejected", p.rejected);
    w.endObject();
  }
  w.endArray();
  w.key("stereo_warnings").beginArray();
  for (const std::string& s : r.warnings) w.value(s);
  w.endArray();
  w.endObject();
  return w.str();
}

void writeStereoCalibrationReport(const fs::path& folder, const StereoCalibrationResult& r,
                                  const CalibrationPattern& pattern, const cv::Mat& leftPreview,
                                  const cv::Mat& rightPreview) {
  writeCalibrationReport(folder / "left", r.left, pattern, leftPreview);
  writeCalibrationReport(folder / "right", r.right, pattern, rightPreview);
  writeText(folder / "report.json", stereoCalibrationJson(r, pattern, "") + "\n");
  if (leftPreview.empty() || rightPreview.empty()) return;
  const StereoRectification::Images rectified = r.rectification.rectify(leftPreview, rightPreview);
  cv::Mat pair;
  cv::hconcat(rectified.left, rectified.right, pair);
  if (pair.channels() == 1) cv::cvtColor(pair, pair, cv::COLOR_GRAY2BGR);
  // Rows every 32 pixels: a point of the scene lies on the same row in both halves.
  for (int y = 16; y < pair.rows; y += 32)
    cv::line(pair, cv::Point(0, y), cv::Point(pair.cols - 1, y), cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
  writeImageFile(folder / "rectified.png", pair);
}

}  // namespace orbis::calibration
