// orbis/io/overview.hpp — a top view of a SLAM run: map points, keyframes, trajectory, ground truth.
//
// Contract: writeOverview draws, on the two world axes along which the trajectory and ground
// truth extend most (equal scale on both, so shapes are true), the map points (grey), the
// estimated trajectory (blue), the keyframe centres (green) and the ground truth (red), all
// already expressed in one world frame (the caller aligns them), and writes a PNG. The view is
// fitted to the trajectories with a margin; map points outside it are clipped, not rescaled.
// Throws orbis::Error naming the file on a failed write.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "orbis/io/trajectory.hpp"

namespace orbis {

// What the top-view overview picture draws.
struct OverviewScene {
  // Drawn at the top.
  std::string title;
  // Map points, drawn as dots.
  std::vector<Eigen::Vector3f> mapPoints;
  // Every tracked frame's pose.
  Trajectory estimate;
  // The keyframes, drawn as small frusta.
  Trajectory keyFrames;
  Trajectory groundTruth;  // may be empty
};

// Writes the overview (PNG) of size × size pixels, viewed from above the two axes of largest
// extent.
void writeOverview(const std::filesystem::path& file, const OverviewScene& scene, int size = 900);

}  // namespace orbis
