// Rendered calibration-board views; see orbis/synth/calibration_views.hpp.
#include "orbis/synth/calibration_views.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/calibration/calibration_output.hpp"
#include "orbis/calibration/stereo_calibrate.hpp"
#include "orbis/util/image_file.hpp"
#include "orbis/synth/rng.hpp"
#include "orbis/util/error.hpp"

namespace orbis::synth {

namespace fs = std::filesystem;
using calibration::CalibratedCamera;
using calibration::LensModel;

namespace {

constexpr double kBackground = 128.0;

// Bilinear read of an 8-bit image at continuous pixel coordinates (pixel centres on integers);
// outside it, the background.
double sampleBilinear(const cv::Mat& image, double x, double y) {
  if (x < -0.5 || y < -0.5 || x > image.cols - 0.5 || y > image.rows - 0.5) return kBackground;
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, image.cols - 1);
  const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, image.rows - 1);
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const double ax = std::clamp(x - x0, 0.0, 1.0), ay = std::clamp(y - y0, 0.0, 1.0);
  const auto at = [&](int yy, int xx) { return static_cast<double>(image.at<std::uint8_t>(yy, xx)); };
  return (1 - ay) * ((1 - ax) * at(y0, x0) + ax * at(y0, x1)) + ay * ((1 - ax) * at(y1, x0) + ax * at(y1, x1));
}

// The rotation taking the camera's z axis onto `direction` by the shortest turn.
Eigen::Matrix3d alignZ(const Eigen::Vector3d& direction) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), direction).toRotationMatrix();
}

bool wholeBoardInView(const CalibratedCamera& camera, const calibration::CalibrationPattern& pattern, const SE3d& pose) {
  const Eigen::Vector2d size = pattern.boardSize();
  constexpr double kMargin = 10.0;
  const KannalaBrandtCamera<double> lens = camera.fisheye();
  // Samples along the board's outline (distortion bends its edges).
  for (int k = 0; k <= 40; ++k) {
    const double a = k / 40.0;
    for (const Eigen::Vector3d& b : {Eigen::Vector3d(a * size.x(), 0, 0), Eigen::Vector3d(a * size.x(), size.y(), 0),
                                     Eigen::Vector3d(0, a * size.y(), 0), Eigen::Vector3d(size.x(), a * size.y(), 0)}) {
      const Eigen::Vector3d pc = pose * b;
      if (camera.model == LensModel::Fisheye ? !lens.inFieldOfView(pc) : pc.z() < 0.05) return false;
      const Eigen::Vector2d px = camera.project(pc);
      if (!(px.x() >= kMargin && px.y() >= kMargin && px.x() < camera.width - kMargin &&
            px.y() < camera.height - kMargin))
        return false;
      // A pinhole's distortion polynomial folds back far outside the image: the ray must agree.
      if ((camera.bearing(px) - pc.normalized()).norm() > 1e-6) return false;
    }
  }
  return true;
}

SE3d randomPose(const CalibratedCamera& camera, const calibration::CalibrationPattern& pattern, SynthRng& rng,
                const CalibrationViewsOptions& o) {
  const Eigen::Vector2d size = pattern.boardSize();
  const double halfField = camera.fieldOfViewAngle();
  const double maxOffAxis = camera.model == LensModel::Fisheye ? std::min(80.0 * M_PI / 180.0, 0.9 * halfField)
                                                               : 0.85 * halfField;
  for (int attempt = 0; attempt < 20000; ++attempt) {
    const double offAxis = maxOffAxis * std::sqrt(rng.uniform());  // even over the image's area
    const double azimuth = rng.uniform(-M_PI, M_PI);
    const Eigen::Vector3d direction(std::sin(offAxis) * std::cos(azimuth), std::sin(offAxis) * std::sin(azimuth),
                                    std::cos(offAxis));
    const double fraction = rng.uniform(0.25, 0.6);
    const double distance = camera.fx * size.x() / (fraction * camera.width);
    const double tiltX = rng.uniform(-45.0, 45.0) * M_PI / 180.0, tiltY = rng.uniform(-45.0, 45.0) * M_PI / 180.0;
    const double roll = rng.uniform(-M_PI, M_PI);
    const Eigen::Matrix3d R = o.squareOn ? Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix()
                                         : Eigen::Matrix3d(alignZ(direction) *
                                                           Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                                           Eigen::AngleAxisd(tiltX, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                                                           Eigen::AngleAxisd(tiltY, Eigen::Vector3d::UnitY()).toRotationMatrix());
    const Eigen::Vector3d centre(0.5 * size.x(), 0.5 * size.y(), 0.0);
    const SE3d pose(R, distance * direction - R * centre);
    // Seen from its printed side, not too obliquely.
    if (R.col(2).dot(direction) < std::cos(65.0 * M_PI / 180.0)) continue;
    if (wholeBoardInView(camera, pattern, pose) &&
        (!o.rightCamera || wholeBoardInView(*o.rightCamera, pattern, o.rightFromLeft * pose)))
      return pose;
  }
  throw Error("calibration views", "", "no pose keeps the whole board in view: the board is too large for the camera");
}

cv::Mat renderView(const CalibratedCamera& camera, const std::vector<cv::Mat>& pyramid, double metresPerTexel0,
                   const SE3d& cameraFromBoard, int supersample) {
  const Eigen::Matrix3d R = cameraFromBoard.rotationMatrix();
  const Eigen::Vector3d t = cameraFromBoard.translation();
  const Eigen::Vector3d normal = R.col(2);
  // One pyramid level for the view: texels per sample spacing at the board's distance.
  const double samplesPerMetre = camera.fx * supersample / t.norm();
  const double texelsPerSample = 1.0 / (metresPerTexel0 * samplesPerMetre);
  const int level = std::clamp(static_cast<int>(std::floor(std::log2(std::max(texelsPerSample, 1.0)))), 0,
                               static_cast<int>(pyramid.size()) - 1);
  const cv::Mat& texture = pyramid[static_cast<std::size_t>(level)];
  const double scale = std::ldexp(1.0, level);
  const double step = 1.0 / supersample;
  cv::Mat out(camera.height, camera.width, CV_32FC1);
  for (int y = 0; y < camera.height; ++y) {
    float* row = out.ptr<float>(y);
    for (int x = 0; x < camera.width; ++x) {
      double sum = 0;
      for (int sy = 0; sy < supersample; ++sy)
        for (int sx = 0; sx < supersample; ++sx) {
          const Eigen::Vector3d d = camera.bearing(Eigen::Vector2d(x - 0.5 + (sx + 0.5) * step, y - 0.5 + (sy + 0.5) * step));
          const double denominator = normal.dot(d);
          const double s = std::abs(denominator) > 1e-12 ? normal.dot(t) / denominator : -1.0;
          if (!(s > 0)) {
            sum += kBackground;
            continue;
          }
          const Eigen::Vector3d q = R.transpose() * (s * d - t);  // metres on the board
          // Texel centres sit on integers: a level-L texel spans 2^L level-0 texels.
          sum += sampleBilinear(texture, q.x() / (metresPerTexel0 * scale) - 0.5, q.y() / (metresPerTexel0 * scale) - 0.5);
        }
      row[x] = static_cast<float>(sum / (supersample * supersample));
    }
  }
  return out;
}

// The rendered intensities with Gaussian noise, rounded to 8 bits.
cv::Mat withNoise(const cv::Mat& grey, double sigma, SynthRng& rng) {
  cv::Mat image(grey.size(), CV_8UC1);
  for (int y = 0; y < grey.rows; ++y)
    for (int x = 0; x < grey.cols; ++x) {
      const double v = grey.at<float>(y, x) + (sigma > 0 ? sigma * rng.normal() : 0.0);
      image.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
    }
  return image;
}

// view_NNN.png of each view's left (or only) or right image into `folder`.
void writeViewImages(const fs::path& folder, const std::vector<RenderedCalibrationView>& views, bool right) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw fileError(folder.string(), "cannot create folder: " + ec.message());
  for (std::size_t i = 0; i < views.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "view_%03zu.png", i);
    writeImageFile(folder / name, right ? views[i].right : views[i].image);
  }
}

// poses.txt: camera-from-board of each view, one 3x4 row-major matrix per line.
void writePoses(const fs::path& file, const std::vector<RenderedCalibrationView>& views) {
  std::string poses;
  for (const RenderedCalibrationView& view : views) {
    const Eigen::Matrix<double, 3, 4> m = view.cameraFromBoard.matrix3x4();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        char value[40];
        std::snprintf(value, sizeof value, "%.12g%c", m(r, c), r == 2 && c == 3 ? '\n' : ' ');
        poses += value;
      }
  }
  FILE* f = std::fopen(file.string().c_str(), "w");
  if (!f || std::fputs(poses.c_str(), f) < 0 || std::fclose(f) != 0) throw fileError(file.string(), "cannot write");
}

}  // namespace

std::vector<RenderedCalibrationView> renderCalibrationViews(const CalibrationViewsOptions& o) {
  const calibration::CalibrationPattern& pattern = o.pattern;
  const cv::Mat target = calibration::drawTarget(pattern, o.pixelsPerSquare);
  std::vector<cv::Mat> pyramid{target};
  while (pyramid.back().cols > 64 && pyramid.size() < 8) {
    cv::Mat next;
    cv::pyrDown(pyramid.back(), next);
    pyramid.push_back(next);
  }
  // The target has a one-square margin: board point (0, 0) is the target's texel edge at
  // pixelsPerSquare; shift the board frame so the texture lookup sees target coordinates.
  const double metresPerTexel = pattern.square / o.pixelsPerSquare;
  const SE3d boardFromTarget(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-pattern.square, -pattern.square, 0));
  std::vector<RenderedCalibrationView> views;
  const int count = o.poses.empty() ? o.views : static_cast<int>(o.poses.size());
  for (int i = 0; i < count; ++i) {
    SynthRng rng(mixSeed(o.seed, static_cast<std::uint64_t>(i) + 1, 77));
    RenderedCalibrationView view;
    view.cameraFromBoard = o.poses.empty() ? randomPose(o.camera, pattern, rng, o)
                                           : o.poses[static_cast<std::size_t>(i)];
    view.image = withNoise(renderView(o.camera, pyramid, metresPerTexel, view.cameraFromBoard * boardFromTarget, o.supersample),
                           o.noiseSigma, rng);
    if (o.rightCamera) {
      SynthRng rightRng(mixSeed(o.seed, static_cast<std::uint64_t>(i) + 1, 78));
      view.right = withNoise(renderView(*o.rightCamera, pyramid, metresPerTexel,
                                        o.rightFromLeft * view.cameraFromBoard * boardFromTarget, o.supersample),
                             o.noiseSigma, rightRng);
    }
    views.push_back(std::move(view));
  }
  return views;
}

fs::path writeCalibrationViews(const fs::path& outDir, const std::vector<RenderedCalibrationView>& views,
                               const CalibratedCamera& camera) {
  writeViewImages(outDir / "images", views, false);
  calibration::writeCalibrationSettings(outDir / "truth.yaml", camera);
  writePoses(outDir / "poses.txt", views);
  return outDir / "images";
}

fs::path writeStereoCalibrationViews(const fs::path& outDir, const std::vector<RenderedCalibrationView>& views,
                                     const CalibrationViewsOptions& options) {
  if (!options.rightCamera) throw Error(outDir.string(), "", "stereo calibration views need a right camera");
  writeViewImages(outDir / "left", views, false);
  writeViewImages(outDir / "right", views, true);
  calibration::writeCalibrationSettings(outDir / "truth_left.yaml", options.camera);
  calibration::writeCalibrationSettings(outDir / "truth_right.yaml", *options.rightCamera);
  calibration::StereoCalibrationResult rig;
  rig.rightFromLeft = options.rightFromLeft;
  rig.baseline = options.rightFromLeft.translation().norm();
  rig.rectification = calibration::rectifyRig(options.camera, *options.rightCamera, options.rightFromLeft);
  calibration::writeStereoCalibrationSettings(outDir / "truth.yaml", rig);
  writePoses(outDir / "poses.txt", views);
  return outDir / "left";
}

}  // namespace orbis::synth
