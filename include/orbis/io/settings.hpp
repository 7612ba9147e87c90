// orbis/io/settings.hpp — ORB-SLAM2 settings files (OpenCV-dialect YAML, read with yaml-cpp).
//
// Contract: Settings::load() reads an ORB-SLAM2 settings file unchanged (it starts with
// %YAML:1.0): Camera.fx/fy/cx/cy/k1/k2/p1/p2[/k3/width/height/fps/RGB/bf], ThDepth,
// DepthMapFactor, ORBextractor.*, and the optional LEFT./RIGHT. rectification blocks
// (K, D, R, P, width, height) of its EuRoC file. orbis adds two optional keys: Sensor (mono |
// stereo | rgbd, read by parseSensorKind), System.seed and, as ORB-SLAM3 does, Camera.newWidth. ORB-SLAM3's Camera.type picks the lens:
// PinHole (the default) or KannalaBrandt8, an equidistant fisheye (KannalaBrandtCamera) whose
// fx, fy, cx, cy, k1..k4 are read from Camera.* or, in ORB-SLAM3's File.version 1.0 layout, from
// Camera1.*; Camera.maxAngle (orbis, degrees, optional) bounds the angles off axis it is trusted
// at. A monocular KannalaBrandt8 camera runs as the MonocularFisheye sensor (keypoints through
// the lens model, images untouched); a stereo or RGB-D one is refused with what to do instead
// (rectify the pair on load: docs/guide/fisheye.md). The sensor is chosen once here, in
// this order: the argument of load(), the Sensor key, else inferred as ORB-SLAM2's files imply
// (no Camera.bf: mono; Camera.bf and DepthMapFactor: rgbd; Camera.bf only: stereo). The camera
// is then one alternative of a std::variant; code past this boundary dispatches once with
// std::visit and runs on the concrete, compile-time camera type.
// settingsKeys() lists every key load() reads (and load() reads no other), so tools that check
// keys — `orbis settings-keys`, orbis.settings_keys() in Python, orbis.sweep's study files — share
// one list with the reader. Keys a file has beyond it (ORB-SLAM2's Viewer.*) are ignored.
// Every missing or malformed key (wrong type, non-positive focal length, ...) throws
// orbis::Error naming the file and the key; an unreadable file names the file (and the line).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <variant>

#include "orbis/camera/distortion.hpp"
#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/rectification.hpp"
#include "orbis/camera/sensor_kind.hpp"
#include "orbis/camera/stereo.hpp"
#include "orbis/features/orb_params.hpp"

namespace orbis {

// SensorKind, its names and their parser: orbis/camera/sensor_kind.hpp (shared with the dataset
// readers and the command line).

// The camera a settings file describes, by sensor: the one std::variant; code past it runs on the
// concrete type.
using CameraVariant =
    std::variant<PinholeCamera<double>, RectifiedStereoCamera<double>, RgbdCamera<double>, KannalaBrandtCamera<double>>;

// ORB-SLAM2's LEFT./RIGHT. rectification blocks of a stereo settings file.
struct StereoRectificationBlocks {
  // @{
  // The left and right camera's block.
  RectificationBlock left, right;
  // @}

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

// An ORB-SLAM2 settings file, read: the sensor, its camera and the extractor's parameters
// (docs/guide/settings.md lists every key).
struct Settings {
  // The file read.
  std::filesystem::path source;
  // The sensor chosen (argument, Sensor key, or inferred).
  SensorKind sensor = SensorKind::Monocular;
  // PinholeCamera for mono (KannalaBrandtCamera for a KannalaBrandt8 mono camera),
  // RectifiedStereoCamera for stereo, RgbdCamera for rgbd; stereo and
  // RGB-D carry baseline = Camera.bf / Camera.fx and closeDepth = ThDepth * baseline.
  CameraVariant camera;
  RadTanDistortion<double> distortion;  // of the input images (Camera.k1..k3); zero if rectified or fisheye
  // The ORBextractor.* parameters.
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

  // Reads file, choosing the sensor from its Sensor key or its keys; throws orbis::Error naming the
  // file and key.
  static Settings load(const std::filesystem::path& file);
  // Reads file as the given sensor.
  static Settings load(const std::filesystem::path& file, SensorKind sensor);

  // Remap tables from the LEFT./RIGHT. blocks; throws orbis::Error when the file has none.
  StereoRectification stereoRectification() const;

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

// A settings key load() reads: its name, its kind of value ("number", "whole number", "text" or
// "matrix") and what it sets, in a few words.
struct SettingsKey {
  // @{
  // The key, its kind of value, and what it sets.
  std::string_view name;
  std::string_view type;
  std::string_view meaning;
  // @}
};

// Every key load() reads, in the order of ORB-SLAM2's files.
std::span<const SettingsKey> settingsKeys();

}  // namespace orbis
