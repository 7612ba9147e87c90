// orbis/camera/euroc_calibration.hpp — reader for EuRoC MAV camera calibration (sensor.yaml).
//
// Contract: readEurocCalibration() reads one camera's sensor.yaml (mav0/cam0/sensor.yaml):
// intrinsics [fu, fv, cu, cv], distortion_coefficients [k1, k2, p1, p2(, k3)], resolution
// [width, height] and T_BS (4x4, body from sensor, row-major in `data`). It accepts camera_model
// pinhole with distortion_model radial-tangential, or equidistant (Kalibr's and TUM-VI's
// Kannala-Brandt fisheye: four coefficients k1..k4 into CameraCalibration::fisheye); anything
// missing or malformed
// throws orbis::Error naming the file and the key.
#pragma once

#include <filesystem>

#include "orbis/camera/rectification.hpp"

namespace orbis {

// Reads one camera of an EuRoC sequence from its sensor.yaml as ASL publishes it (intrinsics,
// radial-tangential distortion, T_BS); throws orbis::Error naming the file and key.
CameraCalibration readEurocCalibration(const std::filesystem::path& sensorYaml);

}  // namespace orbis
