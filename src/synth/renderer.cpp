#include "orbis/synth/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <array>
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

// Nearest hit of the ray o + t d among the listed rectangles; returns t (depth when d has
// camera-frame z = 1, range when d is a unit ray) or infinity, and the shaded grey value through
// `value` when shade is set. n2 = |d|², which sets the ray's footprint for the mip level.
double traceRay(const Renderer::FrameRect* rects, const int* list, int count, const Eigen::Vector3d& o,
                const Eigen::Vector3d& d, double n2, bool shade, double lodBias, float& value) {
  double best = std::numeric_limits<double>::infinity();
  int hit = -1;
  double hu = 0.0, hv = 0.0;
  for (int k = 0; k < count; ++k) {
    const Renderer::FrameRect& fr = rects[list[k]];
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
    const Renderer::FrameRect& fr = rects[hit];
    // Ray spacing on the surface in texels, stretched by the obliquity (geometric mean of the
    // footprint's two axes): footprint = t·|d| / (f·ss·texel) / sqrt(cos θ).
    const double cosTheta = std::abs(d[fr.axis]) / std::sqrt(n2);
    const double footprint = best * std::sqrt(n2) * fr.lodScale / std::sqrt(std::max(cosTheta, 1e-6));
    const double lod = std::log2(std::max(footprint, 1e-9)) + lodBias;
    value = fr.texture->sample((hu - fr.lo0) * fr.invTexel, (hv - fr.lo1) * fr.invTexel, lod);
  }
  return best;
}

// The world corners of a scene rectangle.
std::array<Eigen::Vector3d, 4> rectCorners(const SceneRect& r) {
  const int u = (r.axis + 1) % 3, v = (r.axis + 2) % 3;
  std::array<Eigen::Vector3d, 4> corners;
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector3d p;
    p[r.axis] = r.offset;
    p[u] = (k == 1 || k == 2) ? r.hi[0] : r.lo[0];
    p[v] = (k >= 2) ? r.hi[1] : r.lo[1];
    corners[k] = p;
  }
  return corners;
}

}  // namespace

// Bins every front-facing rectangle into the tiles its projected bounds touch; boundsOf(corners
// in the camera frame, rectangle) gives those bounds, or empty ones for an unseen rectangle.
template <class BoundsOf>
void Renderer::binWith(const Scene& scene, int width, int height, double focal, const SE3d& cameraToWorld,
                       const BoundsOf& boundsOf) {
  const Eigen::Vector3d origin = cameraToWorld.translation();
  const SE3d worldToCamera = cameraToWorld.inverse();
  const int ss = std::max(1, options_.supersample);
  tilesX_ = (width + kTile - 1) / kTile;
  tilesY_ = (height + kTile - 1) / kTile;
  frameRects_.clear();
  std::vector<std::vector<int>> perTile(static_cast<std::size_t>(tilesX_ * tilesY_));
  for (const SceneRect& r : scene.rects()) {
    if ((origin[r.axis] - r.offset) * r.facing <= 0.0) continue;  // seen from behind
    const int u = (r.axis + 1) % 3, v = (r.axis + 2) % 3;
    std::array<Eigen::Vector3d, 4> corners = rectCorners(r);
    for (Eigen::Vector3d& c : corners) c = worldToCamera * c;
    const Bounds b = boundsOf(corners, r);
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

void Renderer::binRects(const Scene& scene, const PinholeCamera<double>& camera, const SE3d& cameraToWorld) {
  binWith(scene, camera.width, camera.height, std::sqrt(camera.fx * camera.fy), cameraToWorld,
          [&](const std::array<Eigen::Vector3d, 4>& corners, const SceneRect&) {
            return clippedBounds(corners.data(), 4, camera);
          });
}

// A rectangle's image through a fisheye is bounded by its edges' images (it subtends less than a
// hemisphere), unless it crosses the backward axis, where the lens's image wraps round: then it
// may cover any pixel. Edges are sampled densely; the few pixels an edge's image bulges out
// between samples are covered by the slack.
void Renderer::binRectsFisheye(const Scene& scene, const KannalaBrandtCamera<double>& camera,
                               const SE3d& cameraToWorld) {
  const Eigen::Vector3d backward = -cameraToWorld.rotationMatrix().col(2);
  const Eigen::Vector3d origin = cameraToWorld.translation();
  constexpr int kSamplesPerEdge = 48;
  constexpr double kSlack = 4.0;
  const Bounds everywhere{-kSlack, camera.width + kSlack, -kSlack, camera.height + kSlack};
  binWith(scene, camera.width, camera.height, std::sqrt(camera.fx * camera.fy), cameraToWorld,
          [&](const std::array<Eigen::Vector3d, 4>& corners, const SceneRect& r) {
            const double t = (r.offset - origin[r.axis]) / backward[r.axis];
            if (t > 0) {
              const Eigen::Vector3d hit = origin + t * backward;
              const int u = (r.axis + 1) % 3, v = (r.axis + 2) % 3;
              if (hit[u] >= r.lo[0] && hit[u] <= r.hi[0] && hit[v] >= r.lo[1] && hit[v] <= r.hi[1]) return everywhere;
            }
            Bounds b;
            for (int k = 0; k < 4; ++k) {
              for (int i = 0; i < kSamplesPerEdge; ++i) {
                const Eigen::Vector3d p = corners[k] + (corners[(k + 1) % 4] - corners[k]) * (double(i) / kSamplesPerEdge);
                if (!camera.inFront(p)) return everywhere;
                const Eigen::Vector2d px = camera.project(p);
                b.minU = std::min(b.minU, px.x() - kSlack);
                b.maxU = std::max(b.maxU, px.x() + kSlack);
                b.minV = std::min(b.minV, px.y() - kSlack);
                b.maxV = std::max(b.maxV, px.y() + kSlack);
              }
            }
            return b;
          });
}

void Renderer::prepareFisheyeRays(const KannalaBrandtCamera<double>& camera) {
  const int ss = std::max(1, options_.supersample);
  const std::size_t count = static_cast<std::size_t>(camera.width) * camera.height * ss * ss;
  const auto& c = fisheyeRaysOf_;
  if (fisheyeRays_.size() == count && c.fx == camera.fx && c.fy == camera.fy && c.cx == camera.cx &&
      c.cy == camera.cy && c.k1 == camera.k1 && c.k2 == camera.k2 && c.k3 == camera.k3 && c.k4 == camera.k4 &&
      c.maxAngle == camera.maxAngle && c.width == camera.width && c.height == camera.height)
    return;
  fisheyeRays_.resize(count);
  const double step = 1.0 / ss;
  const double minZ = std::cos(camera.maxAngle);
  std::size_t k = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x)
      for (int sy = 0; sy < ss; ++sy)
        for (int sx = 0; sx < ss; ++sx) {
          const Eigen::Vector2d px(x - 0.5 + (sx + 0.5) * step, y - 0.5 + (sy + 0.5) * step);
          const Eigen::Vector3d ray = camera.bearing(px);
          // Past the lens's field of view (or where the polynomial does not reach): no ray.
          const bool seen = ray.z() >= minZ && (camera.project(ray) - px).norm() < 1e-3;
          fisheyeRays_[k++] = seen ? ray : Eigen::Vector3d(0, 0, 2);
        }
  fisheyeRaysOf_ = camera;
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

  // Nearest hit among the tile's rectangles (traceRay below).
  const auto trace = [&](const int* list, int count, double xn, double yn, bool shade, float& value) {
    const Eigen::Vector3d d = R.col(0) * xn + R.col(1) * yn + R.col(2);
    return traceRay(rects, list, count, o, d, 1.0 + xn * xn + yn * yn, shade, lodBias, value);
  };

  const double step = 1.0 / ss;
  // The centre sample's depth, kept by shade for depthOf when the centre is one of the samples.
  double centreDepth = std::numeric_limits<double>::infinity();
  forEachPixel(
      rowBegin, rowEnd, camera.width, gray, depth,
      [&](int x, int y, const int* list, int count) {
        float sum = 0.0f;
        centreDepth = std::numeric_limits<double>::infinity();
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
        return sum * invSamples;
      },
      [&](int x, int y, const int* list, int count) {
        if (!centreIsSample) {
          float unused = 0.0f;
          centreDepth = trace(list, count, (x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy, false, unused);
        }
        return std::isfinite(centreDepth) ? static_cast<float>(centreDepth) : 0.0f;
      });
}

template <class Shade, class DepthOf>
void Renderer::forEachPixel(int rowBegin, int rowEnd, int width, cv::Mat& gray, cv::Mat* depth, const Shade& shade,
                            const DepthOf& depthOf) const {
  for (int y = rowBegin; y < rowEnd; ++y) {
    float* g = gray.ptr<float>(y);
    float* dp = depth ? depth->ptr<float>(y) : nullptr;
    const int* tileRow = tileBegin_.data() + (y / kTile) * tilesX_;
    for (int x = 0; x < width; ++x) {
      const int tile = x / kTile;
      const int* list = tileRects_.data() + tileRow[tile];
      const int count = tileRow[tile + 1] - tileRow[tile];
      g[x] = shade(x, y, list, count);
      if (dp) dp[x] = depthOf(x, y, list, count);
    }
  }
}

template <class RenderRows>
void Renderer::renderInThreads(int height, const RenderRows& rows) {
  const int threads = std::clamp(options_.threads, 1, std::max(1, height));
  if (threads == 1) {
    rows(0, height);
    return;
  }
  std::vector<std::thread> workers;
  for (int i = 0; i < threads; ++i) {
    const int begin = height * i / threads, end = height * (i + 1) / threads;
    workers.emplace_back([&rows, begin, end] { rows(begin, end); });
  }
  for (auto& w : workers) w.join();
}

void Renderer::render(const Scene& scene, const PinholeCamera<double>& camera, const SE3d& cameraToWorld,
                      cv::Mat& gray, cv::Mat* depth) {
  gray.create(camera.height, camera.width, CV_32FC1);
  if (depth) depth->create(camera.height, camera.width, CV_32FC1);
  binRects(scene, camera, cameraToWorld);
  renderInThreads(camera.height,
                  [&](int begin, int end) { renderRows(camera, cameraToWorld, begin, end, gray, depth); });
}

void Renderer::render(const Scene& scene, const KannalaBrandtCamera<double>& camera, const SE3d& cameraToWorld,
                      cv::Mat& gray, cv::Mat* depth) {
  gray.create(camera.height, camera.width, CV_32FC1);
  if (depth) depth->create(camera.height, camera.width, CV_32FC1);
  prepareFisheyeRays(camera);
  binRectsFisheye(scene, camera, cameraToWorld);
  renderInThreads(camera.height,
                  [&](int begin, int end) { renderRowsFisheye(camera, cameraToWorld, begin, end, gray, depth); });
}

void Renderer::renderRowsFisheye(const KannalaBrandtCamera<double>& camera, const SE3d& cameraToWorld, int rowBegin,
                                 int rowEnd, cv::Mat& gray, cv::Mat* depth) const {
  const Eigen::Matrix3d R = cameraToWorld.rotationMatrix();
  const Eigen::Vector3d o = cameraToWorld.translation();
  const int ss = std::max(1, options_.supersample);
  const std::size_t perPixel = static_cast<std::size_t>(ss * ss);
  const float invSamples = 1.0f / static_cast<float>(ss * ss);
  forEachPixel(
      rowBegin, rowEnd, camera.width, gray, depth,
      [&](int x, int y, const int* list, int count) {
        const Eigen::Vector3d* rays = fisheyeRays_.data() + (static_cast<std::size_t>(y) * camera.width + x) * perPixel;
        float sum = 0.0f;
        for (std::size_t k = 0; k < perPixel; ++k) {
          if (rays[k].z() > 1.5) continue;  // outside the lens's field of view: black
          float value = 0.0f;
          traceRay(frameRects_.data(), list, count, o, R * rays[k], 1.0, true, options_.lodBias, value);
          sum += value;
        }
        return sum * invSamples;
      },
      [&](int x, int y, const int* list, int count) {
        // Depth along the optical axis of the ray through the pixel centre.
        const Eigen::Vector3d centre = camera.bearing(Eigen::Vector2d(x, y));
        float unused = 0.0f;
        const double range = traceRay(frameRects_.data(), list, count, o, R * centre, 1.0, false, 0.0, unused);
        return std::isfinite(range) ? static_cast<float>(range * centre.z()) : 0.0f;
      });
}

}  // namespace orbis::synth
