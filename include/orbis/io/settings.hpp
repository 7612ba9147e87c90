// orbis/io/settings.hpp — ORB-SLAM2 settings files (OpenCV-dialect YAML, read with yaml-cpp).
//
// Contract: Settings::load() reads an ORB-SLAM2 settings file unchanged (it starts with
// %YAML:1.0): Camera.fx/fy/cx/cy/k1/k2/p1/p2[/k3/width/height/fps/RGB/bf], ThDepth,
// DepthMapFactor, ORBextractor.*, and the optional LEFT./RIGHT. rectification blocks
// (K, D, R, P, width, height) of its EuRoC file. orbis adds two optional keys: Sensor (mono |
// stereo | rgbd, read by parseSensorKind), System.seed and, as ORB-SLAM3 does, Camera.newWidth. The sensor is chosen once here, in
// this order: the argument of load(), the Sensor key, else inferred as ORB-SLAM2's files imply
// (no Camera.bf: mono; Camera.bf and DepthMapFactor: rgbd; Camera.bf only: stereo). The camera
// is then one alternative of a std::variant; code past this boundary dispatches once with
// std::visit and runs on the concrete, compile-time camera type.
// Every missing or malformed key (wrong type, non-positive focal length, ...) throws
// orbis::Error naming the file and the key; an unreadable file names the file (and the line).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <variant>

#include "orbis/camera/distortion.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/rectification.hpp"
#include "orbis/camera/sensor_kind.hpp"
#include "orbis/camera/stereo.hpp"
#include "orbis/features/orb_params.hpp"

namespace orbis {

// SensorKind, its names and their parser: orbis/camera/sensor_kind.hpp (shared with the dataset
// readers and the command line).

using CameraVariant = std::variant<PinholeCamera<double>, RectifiedStereoCamera<double>, RgbdCamera<double>>;

struct StereoRectificationBlocks {
  RectificationBlock left, right;

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

struct Settings {
  std::filesystem::path source;
  SensorKind sensor = SensorKind::Monocular;
  // PinholeCamera for mono, RectifiedStereoCamera for stereo, RgbdCamera for rgbd; stereo and
  // RGB-D carry baseline = Camera.bf / Camera.fx and closeDepth = ThDepth * baseline.
  CameraVariant camera;
  RadTanDistortion<double> distortion;  // of the input images (Camera.k1..k3); zero if rectified
  OrbParams orb;
  double fps = 30.0;           // Camera.fps (0 or absent: 30, as ORB-SLAM2)
  bool rgbOrder = true;        // Camera.RGB: colour images arrive as RGB (1) or BGR (0)
  double thDepth = 40.0;       // ThDepth: close/far threshold in baselines
  double depthMapFactor = 1.0; // DepthMapFactor: raw depth / factor = metres (rgbd only)
  // DepthDisparitySigma (orbis only): σ of the depth sensor's virtual disparity, px (rgbd only)
  double depthDisparitySigma = RgbdCamera<double>::kDefaultDisparitySigma;
  std::optional<StereoRectificationBlocks> rectification;  // LEFT./RIGHT. blocks, if present
  std::uint32_t seed = 0;      // System.seed: seeds every random choice of the system
  int newWidth = 0;            // Camera.newWidth (as ORB-SLAM3): images and intrinsics scaled to it first; 0: no

  static Settings load(const std::filesystem::path& file);
  static Settings load(const std::filesystem::path& file, SensorKind sensor);

  // Remap tables from the LEFT./RIGHT. blocks; throws orbis::Error when the file has none.
  StereoRectification stereoRectification() const;

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

}  // namespace orbis
