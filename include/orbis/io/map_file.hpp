// orbis/io/map_file.hpp — saving a map and loading it in a later run (paper §III-F reuse).
//
// Contract: a map file is little-endian binary:
//   header: magic "ORBISMAP", format version (kMapFileVersion), sensor kind, total file size,
//           vocabulary checksum, the camera (MapIntrinsics), keyframe and map-point counts,
//           and (version 2) whether the map's scale is metric (1) or arbitrary (0: a monocular
//           map, in the unit of its initialisation);
//   keyframes (good ones, by id): frame index, timestamp, pose, intrinsics, features (keypoints,
//           undistorted keypoints, descriptors, uRight, depth, close-depth threshold, scale
//           tables, grid bounds — the grid is rebuilt on load), BoW and feature vectors,
//           spanning-tree parent, loop edges, covisibility edges with weights;
//   map points (good ones, by id): position, reference keyframe, creating frame, descriptor,
//           visible/found counters, observations (keyframe, keypoint index);
//   atlas (version 3): the number of maps, per map its start frame and the map it was merged
//           into (-1: none), the active map, then per keyframe (in keyframe order) its map and
//           flags (1: its map's root, never culled; 2: the gauge BA keeps fixed);
//   trailer: bow::checksum64 of everything before it.
// Ids in the file are those of the saving map; loading creates keyframes and points afresh in
// the same order (ids are renumbered densely, order preserved). The mean viewing direction and
// the scale-invariance distances are recomputed from the observations (the same computation on
// the same data). readMapFile checks, in this order, size, magic, version, declared size,
// checksum, then the caller's expectations (sensor, vocabulary, camera), then every record: counts
// the remaining bytes cannot hold, indices out of range, non-finite poses and positions, graphs
// the running system could not have built (self edges, a cycle in the spanning tree, a keypoint
// held by two points, word or node ids beyond the caller's vocabulary). It throws orbis::Error
// naming the file and the defect — nothing is added to the map on failure. Version 1 files (no
// scale field) still load: their scale follows from the sensor, since monocular was the only
// sensor without metric scale when version 2 added the field. Version 1 and 2 files (no atlas
// section) load as one map, its first keyframe the root.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

#include "orbis/bow/vocabulary.hpp"
#include "orbis/camera/sensor_kind.hpp"
#include "orbis/map/map.hpp"

namespace orbis {

// The map file format's version, written in the header.
inline constexpr std::uint32_t kMapFileVersion = 3;

// What a map file's header records.
struct MapFileInfo {
  // The sensor that made the map.
  SensorKind sensor = SensorKind::Stereo;
  MapIntrinsics intrinsics;  // of the system that saved it (fx, fy, cx, cy, bf are checked)
  // Checksum of the vocabulary the map's bag-of-words vectors refer to.
  std::uint64_t vocabularyChecksum = 0;
  // @{
  // Keyframes and map points in the file.
  std::uint64_t keyFrames = 0, mapPoints = 0;
  // @}
  // @{
  // Not in the file: when non-zero, what readMapFile's caller's vocabulary holds. Every word and
  // node id of the keyframes' BoW and feature vectors must be below them (a corrupt id would
  // size the keyframe database's inverted index, or index the vocabulary, far out of bounds).
  std::uint64_t vocabularyWords = 0, vocabularyNodes = 0;
  // @}
  // False: the map's unit is arbitrary (a monocular map; Sensor::kMetricScale). Read back from
  // the file and checked against the caller's.
  bool metricScale = true;
  std::uint32_t version = 0;  // the file's format version (read back; writing uses kMapFileVersion)
};

// Identifies the vocabulary a map's BoW vectors belong to (checksum of its whole file block).
std::uint64_t vocabularyChecksum(const OrbVocabulary& vocabulary);

// Makes a whole map file's bytes (trailer included) agree with themselves, as writeMapFile leaves
// them: the header's declared total size and the trailer's checksum of everything before it.
// `bytes` must hold at least the size field and the trailer (24 bytes); nothing else is checked.
void sealMapFileBytes(std::span<char> bytes);

// Writes the good keyframes and points of `map`. Caller holds map.mutex(). Written to a
// temporary file renamed into place, so a crash never leaves half a map under `file`.
void writeMapFile(const std::filesystem::path& file, const Map& map, const MapFileInfo& info);

// Reads `file` into `map`, which must be empty; `expected` gives the sensor, vocabulary
// checksum and camera it must have been made with. Caller holds map.mutex(). Returns the
// file's header (counts as loaded).
MapFileInfo readMapFile(const std::filesystem::path& file, Map& map, const MapFileInfo& expected);

// The header of a map file, after the same checks as readMapFile up to (not including) the
// caller's expectations: what a reader that accepts any map (the viewer) passes as `expected`.
MapFileInfo readMapFileInfo(const std::filesystem::path& file);

}  // namespace orbis
