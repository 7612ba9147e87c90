#include "orbis/io/overview.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "orbis/util/image_file.hpp"

namespace orbis {

namespace {

struct View {
  int axisX = 0, axisY = 2;
  double minX = 0, minY = 0, scale = 1;
  int originX = 0, originY = 0, height = 0;
  cv::Point map(const Eigen::Vector3d& p) const {
    return {originX + static_cast<int>(std::lround((p[axisX] - minX) * scale)),
            height - originY - static_cast<int>(std::lround((p[axisY] - minY) * scale))};
  }
};

}  // namespace

void writeOverview(const std::filesystem::path& file, const OverviewScene& scene, int size) {
  // The view fits the trajectories (estimate and ground truth): map points are context.
  std::vector<Eigen::Vector3d> fit;
  for (const auto* t : {&scene.estimate, &scene.groundTruth, &scene.keyFrames})
    for (const StampedPose& s : *t) fit.push_back(s.pose.translation());
  // Map points widen the view to their 10th–90th percentile box: far walls and stray points would
  // otherwise shrink the place the camera moved through to a corner.
  if (scene.mapPoints.size() >= 10) {
    Eigen::Vector3d plo, phi;
    for (int a = 0; a < 3; ++a) {
      std::vector<float> v;
      v.reserve(scene.mapPoints.size());
      for (const auto& p : scene.mapPoints) v.push_back(p[a]);
      std::sort(v.begin(), v.end());
      plo[a] = v[v.size() * 10 / 100];
      phi[a] = v[v.size() * 90 / 100];
    }
    fit.push_back(plo);
    fit.push_back(phi);
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : fit) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (fit.empty()) lo = hi = Eigen::Vector3d::Zero();
  const Eigen::Vector3d extent = hi - lo;
  std::array<int, 3> axes{0, 1, 2};
  std::sort(axes.begin(), axes.end(), [&](int a, int b) { return extent[a] > extent[b]; });
  View view;
  view.axisX = std::min(axes[0], axes[1]);
  view.axisY = std::max(axes[0], axes[1]);
  // A small margin (5% of the larger extent, which is at least 0.5 m).
  const double span = std::max({extent[view.axisX], extent[view.axisY], 0.5});
  const double margin = 0.05 * span;
  view.minX = lo[view.axisX] - margin;
  view.minY = lo[view.axisY] - margin;
  const int titleHeight = 40;
  const int plot = size - 20;
  view.scale = plot / (span + 2 * margin);
  view.originX = 10 + static_cast<int>((plot - (extent[view.axisX] + 2 * margin) * view.scale) / 2);
  view.originY = 10 + static_cast<int>((plot - (extent[view.axisY] + 2 * margin) * view.scale) / 2);
  view.height = size;

  cv::Mat img(size + titleHeight, size, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat canvas = img(cv::Rect(0, titleHeight, size, size));
  const cv::Rect bounds(0, 0, size, size);
  for (const auto& p : scene.mapPoints) {
    const cv::Point q = view.map(p.cast<double>());
    if (bounds.contains(q)) canvas.at<cv::Vec3b>(q) = cv::Vec3b(150, 150, 150);
  }
  auto polyline = [&](const Trajectory& t, const cv::Scalar& colour, int thickness) {
    for (std::size_t i = 1; i < t.size(); ++i)
      cv::line(canvas, view.map(t[i - 1].pose.translation()), view.map(t[i].pose.translation()), colour, thickness,
               cv::LINE_AA);
  };
  polyline(scene.groundTruth, cv::Scalar(40, 40, 220), 2);
  polyline(scene.estimate, cv::Scalar(200, 90, 20), 2);
  for (const StampedPose& k : scene.keyFrames) {
    const cv::Point c = view.map(k.pose.translation());
    cv::circle(canvas, c, 4, cv::Scalar(40, 160, 40), 1, cv::LINE_AA);
    // Viewing direction: the camera's optical axis projected on the view.
    const Eigen::Vector3d tip = k.pose * Eigen::Vector3d(0, 0, 0.08 * span);
    cv::line(canvas, c, view.map(tip), cv::Scalar(40, 160, 40), 1, cv::LINE_AA);
  }
  const char* axisNames = "xyz";
  const std::string axes2 = std::string("top view: ") + axisNames[view.axisX] + " right, " + axisNames[view.axisY] +
                            " up   grey: map points  blue: estimate  green: keyframes  red: ground truth";
  cv::putText(img, scene.title, cv::Point(10, 18), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, axes2, cv::Point(10, 35), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
  // Scale bar: the largest power-of-ten-ish length under a fifth of the view.
  double bar = std::pow(10.0, std::floor(std::log10(span / 2)));
  if (bar * 5 < span) bar *= 2;
  const int barPx = static_cast<int>(bar * view.scale);
  cv::line(canvas, cv::Point(20, size - 20), cv::Point(20 + barPx, size - 20), cv::Scalar(0, 0, 0), 2);
  char label[32];
  std::snprintf(label, sizeof label, "%g m", bar);
  cv::putText(canvas, label, cv::Point(20, size - 28), cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  writeImageFile(file, img);
}

}  // namespace orbis
