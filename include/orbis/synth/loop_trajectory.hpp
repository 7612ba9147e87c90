// orbis/synth/loop_trajectory.hpp — the smooth closed camera path of the synthetic sequences.
//
// Contract: loopPose(params, phase) is the camera-to-world pose (T_wc; camera z forward,
// x right, y down; world z up) at `phase`, periodic with period 1: phase 0 and phase 1 are the
// same pose, so a sequence sampling [0, 1) ends one step before its start (a closed loop).
// The camera centre runs counter-clockwise around an ellipse about `centre` at a height that
// oscillates gently; it looks along the direction of travel turned outwards by yawOffset (so
// it sees the walls and the boxes in front of them, with sideways parallax), with small pitch
// and roll oscillations. Every term is a trigonometric polynomial of the phase: the path is
// infinitely smooth (C-infinity), with no jump at phase 0.
// Two degenerate motions test what monocular initialisation must refuse: PureRotation stays at
// the path's phase-0 position and turns one full yaw circle per period (no parallax); Static
// holds the phase-0 pose.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "orbis/geometry/se3.hpp"

namespace orbis::synth {

// How the rendered camera moves: along the loop, rotating in place, or not at all.
enum class PathMotion { Loop, PureRotation, Static };

// The camera path of a rendered sequence: an ellipse at a height, with gentle height, yaw, pitch
// and roll waves.
struct LoopTrajectoryParams {
  // Loop, pure rotation or static.
  PathMotion motion = PathMotion::Loop;
  // The ellipse's centre on the floor, metres.
  Eigen::Vector2d centre{0.0, 0.0};
  // @{
  // The ellipse's half axes.
  double radiusX = 2.0, radiusY = 1.5;   // metres
  // @}
  double height = 1.4;                   // metres above z = 0
  // Height wave amplitude, metres.
  double heightAmplitude = 0.15;
  double yawOffset = 0.6;                // radians, turned outwards from the direction of travel
  double yawAmplitude = 0.08;            // radians
  // @{
  // Pitch and roll wave amplitudes, radians.
  double pitchAmplitude = 0.08;
  double rollAmplitude = 0.05;
  // @}
};

// The left camera's pose (world from camera) at phase in [0, 1) of the loop.
inline SE3d loopPose(const LoopTrajectoryParams& p, double phase) {
  // Along the loop the whole pose moves with the phase; the degenerate motions freeze it at 0.
  const double a = p.motion == PathMotion::Loop ? 2.0 * M_PI * phase : 0.0;
  const double turn = p.motion == PathMotion::PureRotation ? 2.0 * M_PI * phase : 0.0;
  const Eigen::Vector3d position(p.centre.x() + p.radiusX * std::cos(a), p.centre.y() + p.radiusY * std::sin(a),
                                 p.height + p.heightAmplitude * std::sin(2.0 * a + 1.3));
  // Direction of travel of a counter-clockwise ellipse; the outside lies to its right.
  const double heading = std::atan2(p.radiusY * std::cos(a), -p.radiusX * std::sin(a));
  const double yaw = heading - p.yawOffset + p.yawAmplitude * std::sin(4.0 * a) + turn;
  const double pitch = p.pitchAmplitude * std::sin(3.0 * a);
  const double roll = p.rollAmplitude * std::sin(2.0 * a + 0.7);
  // Camera axes at zero yaw, pitch and roll: looking along world +x, right = -y, down = -z.
  Eigen::Matrix3d base;
  base << 0.0, 0.0, 1.0,  //
      -1.0, 0.0, 0.0,     //
      0.0, -1.0, 0.0;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * base *
                                   Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                                   Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return SE3d(rotation, position);
}

}  // namespace orbis::synth
