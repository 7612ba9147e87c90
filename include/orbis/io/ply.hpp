// orbis/io/ply.hpp — writes point clouds as binary little-endian PLY (x, y, z float; optional rgb).
//
// Contract: writePly throws orbis::Error naming the path when the file cannot be written;
// colours, when given, must have one entry per point. readPly reads back the points of such a
// file (binary little-endian, float x, y, z first); another layout is an orbis::Error.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include <Eigen/Core>

namespace orbis {

// Writes points (and per-point colours, when given) as binary PLY.
void writePly(const std::filesystem::path& path, const std::vector<Eigen::Vector3f>& points,
              const std::vector<std::array<std::uint8_t, 3>>& colours = {});

// Reads the vertices of a PLY file (ASCII or binary little-endian); throws orbis::Error naming the
// file.
std::vector<Eigen::Vector3f> readPly(const std::filesystem::path& path);

}  // namespace orbis
