#include "orbis/synth/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "orbis/synth/rng.hpp"

namespace orbis::synth {

namespace {

int textureTexels(double extent, double texelSize) {
  return std::max(2, static_cast<int>(std::ceil(extent / texelSize - 1e-9)));
}

// Distance from point p to the axis-aligned 2-D box [lo, hi] (0 inside).
double distanceToBox(const Eigen::Vector2d& p, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  const Eigen::Vector2d d = (lo - p).cwiseMax(p - hi).cwiseMax(Eigen::Vector2d::Zero());
  return d.norm();
}

}  // namespace

int Scene::addTexture(Texture texture) {
  textures_.push_back(std::move(texture));
  return static_cast<int>(textures_.size()) - 1;
}

int Scene::addRect(const SceneRect& rect) {
  if (rect.axis < 0 || rect.axis > 2) throw std::invalid_argument("SceneRect: axis must be 0, 1 or 2");
  if (rect.facing != 1 && rect.facing != -1) throw std::invalid_argument("SceneRect: facing must be +1 or -1");
  if (rect.texture < 0 || static_cast<std::size_t>(rect.texture) >= textures_.size())
    throw std::invalid_argument("SceneRect: texture index out of range");
  if (!(rect.hi[0] > rect.lo[0] && rect.hi[1] > rect.lo[1] && rect.texelSize > 0.0))
    throw std::invalid_argument("SceneRect: empty extent or non-positive texel size");
  rects_.push_back(rect);
  return static_cast<int>(rects_.size()) - 1;
}

void Scene::addBox(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double texelSize,
                   std::uint64_t seed) {
  int face = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int facing : {-1, 1}) {
      if (axis == 2 && facing == -1) continue;  // the bottom stands on the floor, never seen
      SceneRect r;
      r.axis = axis;
      r.facing = facing;
      r.offset = facing > 0 ? max[axis] : min[axis];
      r.lo = {min[u], min[v]};
      r.hi = {max[u], max[v]};
      r.texelSize = texelSize;
      const int w = textureTexels(max[u] - min[u], texelSize), h = textureTexels(max[v] - min[v], texelSize);
      r.texture = addTexture(Texture(makeCornerTexture(w, h, mixSeed(seed, static_cast<std::uint64_t>(face)))));
      addRect(r);
      ++face;
    }
  }
}

Eigen::Vector3d Scene::pointAt(int rect, double s, double t) const {
  const SceneRect& r = rects_.at(static_cast<std::size_t>(rect));
  Eigen::Vector3d p;
  p[r.axis] = r.offset;
  p[(r.axis + 1) % 3] = r.lo[0] + s * r.texelSize;
  p[(r.axis + 2) % 3] = r.lo[1] + t * r.texelSize;
  return p;
}

std::optional<SceneHit> Scene::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                         double tMin) const {
  SceneHit best;
  best.distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rects_.size(); ++i) {
    const SceneRect& r = rects_[i];
    const int a = r.axis, u = (a + 1) % 3, v = (a + 2) % 3;
    if ((origin[a] - r.offset) * r.facing <= 0.0 || direction[a] * r.facing >= 0.0) continue;
    const double t = (r.offset - origin[a]) / direction[a];
    if (t <= tMin || t >= best.distance) continue;
    const double hu = origin[u] + t * direction[u], hv = origin[v] + t * direction[v];
    if (hu < r.lo[0] || hu > r.hi[0] || hv < r.lo[1] || hv > r.hi[1]) continue;
    best.distance = t;
    best.rect = static_cast<int>(i);
    best.texel = {(hu - r.lo[0]) / r.texelSize, (hv - r.lo[1]) / r.texelSize};
  }
  if (best.rect < 0) return std::nullopt;
  return best;
}

Scene makeRoomScene(const RoomParams& params, std::uint64_t seed) {
  Scene scene;
  const Eigen::Vector3d& lo = params.min;
  const Eigen::Vector3d& hi = params.max;
  // Walls, floor and ceiling face inwards: the -facing plane sits at max, the +facing at min.
  int face = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int facing : {1, -1}) {
      SceneRect r;
      r.axis = axis;
      r.facing = facing;
      r.offset = facing > 0 ? lo[axis] : hi[axis];
      // A hair of overlap at the room's edges, so no ray slips between two walls.
      r.lo = {lo[u] - 1e-6, lo[v] - 1e-6};
      r.hi = {hi[u] + 1e-6, hi[v] + 1e-6};
      r.texelSize = params.texelSize;
      const int w = textureTexels(hi[u] - lo[u], params.texelSize), h = textureTexels(hi[v] - lo[v], params.texelSize);
      r.texture = scene.addTexture(Texture(makeCornerTexture(w, h, mixSeed(seed, 1000 + static_cast<std::uint64_t>(face)))));
      scene.addRect(r);
      ++face;
    }
  }

  // Boxes on a ring around the free ellipse, pushed outwards by a random amount so they stand
  // at different distances from the camera path.
  SynthRng rng(mixSeed(seed, 7));
  const Eigen::Vector2d centre = 0.5 * (lo.head<2>() + hi.head<2>());
  const double margin = 0.15, step = 0.05;
  const auto clearsEllipse = [&](const Eigen::Vector2d& c, const Eigen::Vector2d& half) {
    for (int i = 0; i < 180; ++i) {
      const double a = 2.0 * M_PI * i / 180.0;
      const Eigen::Vector2d e = centre + Eigen::Vector2d(params.freeRadiusX * std::cos(a), params.freeRadiusY * std::sin(a));
      if (distanceToBox(e, c - half, c + half) < 0.1) return false;
    }
    // The whole box must lie outside the ellipse, not just away from its rim.
    const Eigen::Vector2d q = (c - centre).cwiseQuotient(Eigen::Vector2d(params.freeRadiusX, params.freeRadiusY));
    return q.norm() > 1.0;
  };
  for (int k = 0; k < params.boxes; ++k) {
    const double angle = 2.0 * M_PI * (k + rng.uniform(-0.25, 0.25)) / params.boxes;
    Eigen::Vector2d half(rng.uniform(0.2, 0.5), rng.uniform(0.2, 0.5));
    const double height = rng.uniform(0.4, 2.2);
    const double push = rng.uniform(0.0, 1.0);  // fraction of the space left towards the wall
    const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d onEllipse = centre + Eigen::Vector2d(params.freeRadiusX * dir.x(), params.freeRadiusY * dir.y());
    for (int attempt = 0; attempt < 4; ++attempt, half *= 0.75) {
      const Eigen::Vector2d roomLo = lo.head<2>() + half + Eigen::Vector2d::Constant(margin);
      const Eigen::Vector2d roomHi = hi.head<2>() - half - Eigen::Vector2d::Constant(margin);
      const auto fits = [&](const Eigen::Vector2d& c) {
        return (c.array() >= roomLo.array()).all() && (c.array() <= roomHi.array()).all();
      };
      Eigen::Vector2d c = onEllipse;
      while (fits(c) && !clearsEllipse(c, half)) c += step * dir;
      if (!fits(c)) continue;
      double freeSpace = 0.0;
      while (fits(c + (freeSpace + step) * dir)) freeSpace += step;
      c += (push * freeSpace) * dir;
      scene.addBox(Eigen::Vector3d(c.x() - half.x(), c.y() - half.y(), lo.z()),
                   Eigen::Vector3d(c.x() + half.x(), c.y() + half.y(), lo.z() + height),
                   params.texelSize, mixSeed(seed, 2000 + static_cast<std::uint64_t>(k)));
      break;
    }
  }
  if (params.pillarHalf.x() > 0.0 && params.pillarHalf.y() > 0.0) {
    // A hair below the ceiling, so its top and the ceiling never share a plane.
    const Eigen::Vector2d& half = params.pillarHalf;
    scene.addBox(Eigen::Vector3d(centre.x() - half.x(), centre.y() - half.y(), lo.z()),
                 Eigen::Vector3d(centre.x() + half.x(), centre.y() + half.y(), hi.z() - 1e-3), params.texelSize,
                 mixSeed(seed, 3000));
  }
  return scene;
}

}  // namespace orbis::synth
