#include "orbis/synth/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

namespace orbis::synth {

namespace {

constexpr int kTile = 16;
constexpr double kNearClip = 1e-3;

struct Bounds {
  double minU = std::numeric_limits<double>::infinity(), maxU = -std::numeric_limits<double>::infinity();
  double minV = minU, maxV = maxU;
  bool empty() const { return !(minU <= maxU); }
};

// Projected bounds of a convex polygon (camera frame) after clipping it to z >= kNearClip.
Bounds clippedBounds(const Eigen::Vector3d* corners, int n, const PinholeCamera<double>& camera) {
  Bounds b;
  const auto add = [&](const Eigen::Vector3d& p) {
    const double u = camera.fx * p.x() / p.z() + camera.cx, v = camera.fy * p.y() / p.z() + camera.cy;
    b.minU = std::min(b.minU, u);
    b.maxU = std::max(b.maxU, u);
    b.minV = std::min(b.minV, v);
    b.maxV = std::max(b.maxV, v);
  };
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = corners[i];
    const Eigen::Vector3d& c = corners[(i + 1) % n];
    const bool aIn = a.z() >= kNearClip, cIn = c.z() >= kNearClip;
    if (aIn) add(a);
    if (aIn != cIn) add(a + (c - a) * ((kNearClip - a.z()) / (c.z() - a.z())));
  }
  return b;
}

}  // namespace

void Renderer::binRects(const Scene& scene, const PinholeCamera<double>& camera, const SE3d& cameraToWorld) {
  const Eigen::Vector3d origin = cameraToWorld.translation();
  const SE3d worldToCamera = cameraToWorld.inverse();
  const int ss = std::max(1, options_.supersample);
  const double focal = std::sqrt(camera.fx * camera.fy);
  tilesX_ = (camera.width + kTile - 1) / kTile;
  tilesY_ = (camera.height + kTile - 1) / kTile;
  frameRects_.clear();
  std::vector<std::vector<int>> perTile(static_cast<std::size_t>(tilesX_ * tilesY_));
  for (const SceneRect& r : scene.rects()) {
    if ((origin[r.axis] - r.offset) * r.facing <= 0.0) continue;  // seen from behind
    const int u = (r.axis + 1) % 3, v = (r.axis + 2) % 3;
    Eigen::Vector3d corners[4];
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector3d p;
      p[r.axis] = r.offset;
      p[u] = (k == 1 || k == 2) ? r.hi[0] : r.lo[0];
      p[v] = (k >= 2) ? r.hi[1] : r.lo[1];
      corners[k] = worldToCamera * p;
    }
    const Bounds b = clippedBounds(corners, 4, camera);
    if (b.empty()) continue;
    // Pixel i spans [i - 0.5, i + 0.5]; one pixel of slack covers rounding.
    const int tx0 = std::max(0, static_cast<int>(std::floor((b.minU - 1.5) / kTile)));
    const int tx1 = std::min(tilesX_ - 1, static_cast<int>(std::floor(std::min(b.maxU + 1.5, 1e9) / kTile)));
    const int ty0 = std::max(0, static_cast<int>(std::floor((b.minV - 1.5) / kTile)));
    const int ty1 = std::min(tilesY_ - 1, static_cast<int>(std::floor(std::min(b.maxV + 1.5, 1e9) / kTile)));
    if (tx0 > tx1 || ty0 > ty1) continue;
    const int index = static_cast<int>(frameRects_.size());
    frameRects_.push_back({r.axis, u, v, r.offset, r.lo[0], r.lo[1], r.hi[0], r.hi[1], 1.0 / r.texelSize,
                           1.0 / (focal * ss * r.texelSize), &scene.texture(r.texture)});
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) perTile[static_cast<std::size_t>(ty * tilesX_ + tx)].push_back(index);
  }
  tileBegin_.assign(1, 0);
  tileRects_.clear();
  for (const auto& list : perTile) {
    tileRects_.insert(tileRects_.end(), list.begin(), list.end());
    tileBegin_.push_back(static_cast<int>(tileRects_.size()));
  }
}

void Renderer::renderRows(const PinholeCamera<double>& camera, const SE3d& cameraToWorld, int rowBegin,
                          int rowEnd, cv::Mat& gray, cv::Mat* depth) const {
  const Eigen::Matrix3d R = cameraToWorld.rotationMatrix();
  const Eigen::Vector3d o = cameraToWorld.translation();
  const int ss = std::max(1, options_.supersample);
  const bool centreIsSample = ss % 2 == 1;
  const float invSamples = 1.0f / static_cast<float>(ss * ss);
  const double lodBias = options_.lodBias;
  const FrameRect* rects = frameRects_.data();

  // Nearest hit among the tile's rectangles; returns depth (t, since the camera-frame ray has
  // z = 1) or infinity, and the shaded grey value through `value` when shade is set.
  const auto trace = [&](const int* list, int count, double xn, double yn, bool shade, float& value) {
    const Eigen::Vector3d d = R.col(0) * xn + R.col(1) * yn + R.col(2);
    double best = std::numeric_limits<double>::infinity();
    int hit = -1;
    double hu = 0.0, hv = 0.0;
    for (int k = 0; k < count; ++k) {
      const FrameRect& fr = rects[list[k]];
      const double t = (fr.offset - o[fr.axis]) / d[fr.axis];
      if (!(t > 0.0 && t < best)) continue;
      const double pu = o[fr.u] + t * d[fr.u];
      if (pu < fr.lo0 || pu > fr.hi0) continue;
      const double pv = o[fr.v] + t * d[fr.v];
      if (pv < fr.lo1 || pv > fr.hi1) continue;
      best = t;
      hit = list[k];
      hu = pu;
      hv = pv;
    }
    if (hit < 0) {
      value = 0.0f;
      return best;
    }
    if (shade) {
      const FrameRect& fr = rects[hit];
      const double n2 = 1.0 + xn * xn + yn * yn;
      // Ray spacing on the surface in texels, stretched by the obliquity (geometric mean of the
      // footprint's two axes): footprint = t·|d| / (f·ss·texel) / sqrt(cos θ).
      const double cosTheta = std::abs(d[fr.axis]) / std::sqrt(n2);
      const double footprint = best * std::sqrt(n2) * fr.lodScale / std::sqrt(std::max(cosTheta, 1e-6));
      const double lod = std::log2(std::max(footprint, 1e-9)) + lodBias;
      value = fr.texture->sample((hu - fr.lo0) * fr.invTexel, (hv - fr.lo1) * fr.invTexel, lod);
    }
    return best;
  };

  const double step = 1.0 / ss;
  for (int y = rowBegin; y < rowEnd; ++y) {
    float* g = gray.ptr<float>(y);
    float* dp = depth ? depth->ptr<float>(y) : nullptr;
    const int* tileRow = tileBegin_.data() + (y / kTile) * tilesX_;
    for (int x = 0; x < camera.width; ++x) {
      const int tile = x / kTile;
      const int* list = tileRects_.data() + tileRow[tile];
      const int count = tileRow[tile + 1] - tileRow[tile];
      float sum = 0.0f;
      double centreDepth = std::numeric_limits<double>::infinity();
      for (int sy = 0; sy < ss; ++sy) {
        const double v = y - 0.5 + (sy + 0.5) * step;
        const double yn = (v - camera.cy) / camera.fy;
        for (int sx = 0; sx < ss; ++sx) {
          const double u = x - 0.5 + (sx + 0.5) * step;
          float value = 0.0f;
          const double t = trace(list, count, (u - camera.cx) / camera.fx, yn, true, value);
          sum += value;
          if (centreIsSample && sx == ss / 2 && sy == ss / 2) centreDepth = t;
        }
      }
      g[x] = sum * invSamples;
      if (dp) {
        if (!centreIsSample) {
          float unused = 0.0f;
          centreDepth = trace(list, count, (x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy, false, unused);
        }
        dp[x] = std::isfinite(centreDepth) ? static_cast<float>(centreDepth) : 0.0f;
      }
    }
  }
}

void Renderer::render(const Scene& scene, const PinholeCamera<double>& camera, const SE3d& cameraToWorld,
                      cv::Mat& gray, cv::Mat* depth) {
  gray.create(camera.height, camera.width, CV_32FC1);
  if (depth) depth->create(camera.height, camera.width, CV_32FC1);
  binRects(scene, camera, cameraToWorld);
  const int threads = std::clamp(options_.threads, 1, std::max(1, camera.height));
  if (threads == 1) {
    renderRows(camera, cameraToWorld, 0, camera.height, gray, depth);
    return;
  }
  std::vector<std::thread> workers;
  for (int i = 0; i < threads; ++i) {
    const int begin = camera.height * i / threads, end = camera.height * (i + 1) / threads;
    workers.emplace_back([&, begin, end] { renderRows(camera, cameraToWorld, begin, end, gray, depth); });
  }
  for (auto& w : workers) w.join();
}

}  // namespace orbis::synth
