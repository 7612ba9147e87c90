// orbis/synth/scene.hpp — a textured 3-D scene of axis-aligned rectangles (a room with boxes).
//
// Contract: a Scene is a list of one-sided, axis-aligned, textured rectangles in world
// coordinates (metres). Rectangle r lies in the plane x[axis] = offset, spans [lo, hi] on the
// two other axes (u = axis+1 mod 3, v = axis+2 mod 3), and is seen only from the side its
// `facing` sign points to. Texture coordinate (s, t) in level-0 texels maps to the world point
// with x[u] = lo[0] + s * texelSize and x[v] = lo[1] + t * texelSize (pointAt()), so a test
// can paint a feature into a texture and know exactly where it is in 3-D.
// makeRoomScene() builds the standard sequence scene from a seed: a closed room (walls, floor,
// ceiling, facing inwards) with boxes standing on the floor at several distances from its
// centre, every face carrying its own corner-rich texture. World frame: z up, room centred on
// the z axis; the camera path of loop_trajectory.hpp stays inside the free space.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "orbis/synth/texture.hpp"

namespace orbis::synth {

// An axis-aligned textured rectangle.
struct SceneRect {
  int axis = 2;                 // 0, 1, 2: the plane's normal axis
  double offset = 0.0;          // the plane: x[axis] = offset
  int facing = 1;               // +1: visible from x[axis] > offset; -1: from below
  std::array<double, 2> lo{};   // bounds on axes (axis+1)%3 and (axis+2)%3
  // Upper bounds on the two in-plane axes.
  std::array<double, 2> hi{};
  int texture = 0;              // index into Scene::textures()
  double texelSize = 0.006;     // metres per level-0 texel
};

// Where a ray hits the scene.
struct SceneHit {
  double distance = 0.0;        // ray parameter t: hit = origin + t * direction
  // Index of the rectangle hit.
  int rect = -1;
  Eigen::Vector2d texel;        // level-0 texture coordinates of the hit
};

// A scene of textured rectangles.
class Scene {
 public:
  // Adds a texture; returns its index.
  int addTexture(Texture texture);
  // Returns the rectangle's index. Throws std::invalid_argument for a bad axis, facing,
  // texture index or an empty extent (programming errors, not outside input).
  int addRect(const SceneRect& rect);
  // Five faces (no bottom) of the box [min, max], facing outwards, each with its own texture
  // from makeCornerTexture(seed + face).
  void addBox(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double texelSize, std::uint64_t seed);

  // @{
  // The rectangles, a texture, and the number of textures.
  const std::vector<SceneRect>& rects() const { return rects_; }
  const Texture& texture(int i) const { return textures_[static_cast<std::size_t>(i)]; }
  std::size_t textureCount() const { return textures_.size(); }
  // @}

  // World point of rectangle `rect` at level-0 texture coordinates (s, t).
  Eigen::Vector3d pointAt(int rect, double s, double t) const;
  // Nearest front-facing hit with t > tMin (a reference implementation for checks; the
  // renderer has its own culled, tiled loop).
  std::optional<SceneHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                    double tMin = 1e-6) const;

 private:
  std::vector<SceneRect> rects_;
  std::vector<Texture> textures_;
};

// The rendered room: its extent, boxes and optional central block.
struct RoomParams {
  Eigen::Vector3d min{-5.0, -4.0, 0.0};  // room interior, metres
  // Upper corner of the room interior, metres.
  Eigen::Vector3d max{5.0, 4.0, 3.0};
  double texelSize = 0.006;              // metres per texel on every face
  int boxes = 8;                         // boxes around the centre, at several depths
  double freeRadiusX = 2.9;              // no box intrudes into this ellipse around the centre
  double freeRadiusY = 2.3;              // (the camera path of LoopTrajectoryParams lies inside it)
  // Half extents of a block standing floor to ceiling at the room's centre, inside the free
  // ellipse (zero: none). The camera path then runs round it as a corridor loop: the block hides
  // the far side of the room, so a place leaves the view until the camera comes back to it.
  Eigen::Vector2d pillarHalf{0.0, 0.0};
};

// Builds the room, every texture drawn from seed.
Scene makeRoomScene(const RoomParams& params, std::uint64_t seed);

}  // namespace orbis::synth
