// The renderer against geometry computed independently of it: bright squares painted into the
// textures must appear where the ground-truth poses project them, stereo pairs must show the
// disparity bf/Z, and every depth pixel must lie on a surface of the scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "orbis/synth/loop_trajectory.hpp"
#include "orbis/synth/renderer.hpp"
#include "orbis/synth/scene.hpp"

namespace orbis::synth {
namespace {

constexpr double kTexel = 0.01;     // metres
constexpr int kSquare = 5;          // texels per square side
constexpr int kSpacing = 50;        // texels between square origins
constexpr float kDark = 20.0f, kBright = 230.0f;

struct Marker {
  int rect;
  double s, t;  // texture coordinates of the square's centre
};

// The default room, every face dark with bright squares on a regular grid.
Scene markerRoom(std::vector<Marker>& markers) {
  const RoomParams room;
  Scene scene;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int facing : {1, -1}) {
      const int w = static_cast<int>(std::lround((room.max[u] - room.min[u]) / kTexel));
      const int h = static_cast<int>(std::lround((room.max[v] - room.min[v]) / kTexel));
      cv::Mat image(h, w, CV_32FC1, cv::Scalar(kDark));
      SceneRect r;
      r.axis = axis;
      r.facing = facing;
      r.offset = facing > 0 ? room.min[axis] : room.max[axis];
      r.lo = {room.min[u], room.min[v]};
      r.hi = {room.max[u], room.max[v]};
      r.texelSize = kTexel;
      const int index = static_cast<int>(scene.rects().size());
      for (int y = kSpacing / 2; y + kSquare < h - kSpacing / 2; y += kSpacing)
        for (int x = kSpacing / 2; x + kSquare < w - kSpacing / 2; x += kSpacing) {
          image(cv::Rect(x, y, kSquare, kSquare)).setTo(kBright);
          markers.push_back({index, x + 0.5 * kSquare, y + 0.5 * kSquare});
        }
      r.texture = scene.addTexture(Texture(image));
      scene.addRect(r);
    }
  }
  return scene;
}

PinholeCamera<double> vga() { return PinholeCamera<double>{500.0, 500.0, 320.0, 240.0, 640, 480}; }

// Image-area centroid of a square of the scene as the camera projects it: the exact target for
// an intensity centroid (perspective moves it slightly off the projected centre).
Eigen::Vector2d projectedAreaCentroid(const Scene& scene, const Marker& m, const PinholeCamera<double>& cam,
                                      const SE3d& worldToCamera) {
  constexpr int n = 40;
  const double h = static_cast<double>(kSquare) / n;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double area = 0.0;
  const auto project = [&](double s, double t) { return cam.project(worldToCamera * scene.pointAt(m.rect, s, t)); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double s = m.s - 0.5 * kSquare + (i + 0.5) * h, t = m.t - 0.5 * kSquare + (j + 0.5) * h;
      const Eigen::Vector2d c = project(s, t);
      const Eigen::Vector2d ds = project(s + 0.5 * h, t) - project(s - 0.5 * h, t);
      const Eigen::Vector2d dt = project(s, t + 0.5 * h) - project(s, t - 0.5 * h);
      const double a = std::abs(ds.x() * dt.y() - ds.y() * dt.x());
      sum += a * c;
      area += a;
    }
  return sum / area;
}

struct Found {
  Eigen::Vector2d expected, measured;
  double depth;
};

// Intensity centroids of every marker fully inside the image and seen unoccluded.
std::vector<Found> measureMarkers(const Scene& scene, const std::vector<Marker>& markers,
                                  const PinholeCamera<double>& cam, const SE3d& cameraToWorld, const cv::Mat& gray) {
  const SE3d worldToCamera = cameraToWorld.inverse();
  std::vector<Found> found;
  for (const Marker& m : markers) {
    const Eigen::Vector3d pw = scene.pointAt(m.rect, m.s, m.t);
    const Eigen::Vector3d pc = worldToCamera * pw;
    if (pc.z() < 0.5) continue;
    const auto hit = scene.intersect(cameraToWorld.translation(), pw - cameraToWorld.translation());
    if (!hit || hit->rect != m.rect) continue;
    const Eigen::Vector2d centre = cam.project(pc);
    const double radius = cam.fx * kSquare * kTexel / pc.z() + 4.0;  // generous: the square tilts
    const int x0 = static_cast<int>(std::floor(centre.x() - radius)), x1 = static_cast<int>(std::ceil(centre.x() + radius));
    const int y0 = static_cast<int>(std::floor(centre.y() - radius)), y1 = static_cast<int>(std::ceil(centre.y() + radius));
    if (x0 < 0 || y0 < 0 || x1 >= cam.width || y1 >= cam.height) continue;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double mass = 0.0;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double w = gray.at<float>(y, x) - kDark;
        sum += w * Eigen::Vector2d(x, y);
        mass += w;
      }
    if (mass <= 0.0) continue;
    found.push_back({projectedAreaCentroid(scene, m, cam, worldToCamera), sum / mass, pc.z()});
  }
  return found;
}

TEST(SynthRender, PaintedSquaresAppearWhereGroundTruthProjectsThem) {
  std::vector<Marker> markers;
  const Scene scene = markerRoom(markers);
  const PinholeCamera<double> cam = vga();
  Renderer renderer;
  cv::Mat gray;
  const LoopTrajectoryParams path;
  std::size_t total = 0;
  for (double phase : {0.0, 0.13, 0.37, 0.61, 0.88}) {
    const SE3d pose = loopPose(path, phase);
    renderer.render(scene, cam, pose, gray);
    const std::vector<Found> found = measureMarkers(scene, markers, cam, pose, gray);
    ASSERT_GT(found.size(), 20u) << "phase " << phase;
    double worst = 0.0, sum = 0.0;
    for (const Found& f : found) {
      const double e = (f.measured - f.expected).norm();
      worst = std::max(worst, e);
      sum += e;
    }
    std::printf("phase %.2f: %zu squares, centroid vs projection: mean %.4f px, max %.4f px\n", phase,
                found.size(), sum / found.size(), worst);
    EXPECT_LT(worst, 0.1) << "phase " << phase << ", " << found.size() << " squares";
    EXPECT_LT(sum / found.size(), 0.03) << "phase " << phase;
    total += found.size();
  }
  EXPECT_GT(total, 200u);
}

TEST(SynthRender, StereoDisparityOfSquaresIsBfOverDepth) {
  std::vector<Marker> markers;
  const Scene scene = markerRoom(markers);
  const PinholeCamera<double> cam = vga();
  const double baseline = 0.12;
  Renderer renderer;
  cv::Mat left, right;
  const LoopTrajectoryParams path;
  for (double phase : {0.05, 0.5}) {
    const SE3d leftPose = loopPose(path, phase);
    const SE3d rightPose = leftPose * SE3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(baseline, 0.0, 0.0));
    renderer.render(scene, cam, leftPose, left);
    renderer.render(scene, cam, rightPose, right);
    const std::vector<Found> inLeft = measureMarkers(scene, markers, cam, leftPose, left);
    const std::vector<Found> inRight = measureMarkers(scene, markers, cam, rightPose, right);
    std::size_t pairs = 0;
    double worst = 0.0;
    for (const Found& l : inLeft)
      for (const Found& r : inRight) {
        // The same square: same row, and to the left in the right image by about bf/Z.
        const double expectedDisparity = cam.fx * baseline / l.depth;
        if (std::abs(l.expected.y() - r.expected.y()) > 1.0 ||
            std::abs(l.expected.x() - r.expected.x() - expectedDisparity) > 2.0)
          continue;
        EXPECT_NEAR(l.measured.x() - r.measured.x(), expectedDisparity, 0.1);
        worst = std::max(worst, std::abs(l.measured.x() - r.measured.x() - expectedDisparity));
        EXPECT_NEAR(l.measured.y(), r.measured.y(), 0.1);
        ++pairs;
      }
    std::printf("phase %.2f: %zu square pairs, |disparity - bf/Z| max %.4f px\n", phase, pairs, worst);
    EXPECT_GT(pairs, 20u) << "phase " << phase;
  }
}

TEST(SynthRender, DepthPixelsLieOnTheSceneSurfaces) {
  const Scene scene = makeRoomScene(RoomParams{}, 3);
  const PinholeCamera<double> cam{200.0, 200.0, 80.0, 60.0, 160, 120};
  Renderer renderer;
  cv::Mat gray, depth;
  const LoopTrajectoryParams path;
  for (double phase : {0.0, 0.3, 0.7}) {
    const SE3d pose = loopPose(path, phase);
    renderer.render(scene, cam, pose, gray, &depth);
    int checked = 0;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        const double z = depth.at<float>(y, x);
        ASSERT_GT(z, 0.3) << "closed room: every pixel sees a surface";
        const Eigen::Vector3d pw = pose * cam.unproject(Eigen::Vector2d(x, y), z);
        // Distance to the nearest rectangle (plane distance where inside its bounds).
        double nearest = 1e9;
        for (const SceneRect& r : scene.rects()) {
          const int u = (r.axis + 1) % 3, v = (r.axis + 2) % 3;
          const double du = std::max({r.lo[0] - pw[u], pw[u] - r.hi[0], 0.0});
          const double dv = std::max({r.lo[1] - pw[v], pw[v] - r.hi[1], 0.0});
          nearest = std::min(nearest, std::sqrt(du * du + dv * dv + std::pow(pw[r.axis] - r.offset, 2)));
        }
        // float storage: a few parts in 1e7 of the depth.
        EXPECT_LT(nearest, 2e-6 * z + 1e-6) << "pixel " << x << "," << y;
        ++checked;
      }
    EXPECT_EQ(checked, cam.width * cam.height);
  }
}

TEST(SynthRender, ThreadedRenderIsIdentical) {
  const Scene scene = makeRoomScene(RoomParams{}, 5);
  const PinholeCamera<double> cam{250.0, 250.0, 160.0, 120.0, 320, 240};
  const SE3d pose = loopPose(LoopTrajectoryParams{}, 0.2);
  cv::Mat a, b, da, db;
  Renderer(RenderOptions{2, 0.0, 1}).render(scene, cam, pose, a, &da);
  Renderer(RenderOptions{2, 0.0, 3}).render(scene, cam, pose, b, &db);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(da, db, cv::NORM_INF), 0.0);
}

TEST(SynthTexture, MipLevelsAreAlignedWithLevelZero) {
  // A linear ramp survives 2x2 box averaging unchanged, but only if every level's texel centres
  // sit where level 0 says: a half-texel drift would show as an offset growing with the level.
  const auto ramp = [](double x, double y) { return 2.0 * x + 3.0 * y; };
  cv::Mat image(128, 128, CV_32FC1);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) image.at<float>(y, x) = static_cast<float>(ramp(x + 0.5, y + 0.5));
  const Texture tex(image);
  ASSERT_GE(tex.levelCount(), 5);
  for (double lod : {0.0, 1.0, 2.0, 2.5, 3.0, 4.0})
    for (const auto& [x, y] : {std::pair{40.0, 50.0}, std::pair{63.3, 71.9}, std::pair{80.25, 44.0}})
      EXPECT_NEAR(tex.sample(x, y, lod), ramp(x, y), 1e-3) << "lod " << lod << " at " << x << "," << y;
  // Level-0 bilinear sampling returns texel values at texel centres and blends between them.
  cv::Mat square(64, 64, CV_32FC1, cv::Scalar(0.0));
  square(cv::Rect(21, 37, 6, 4)).setTo(100.0f);
  const Texture sq(square);
  EXPECT_FLOAT_EQ(sq.sample(21.5, 37.5, 0.0), 100.0f);
  EXPECT_FLOAT_EQ(sq.sample(20.5, 37.5, 0.0), 0.0f);
  EXPECT_FLOAT_EQ(sq.sample(21.0, 37.5, 0.0), 50.0f);
}

}  // namespace
}  // namespace orbis::synth
