// orbis/calibration/calibration_output.hpp — what a calibration leaves behind.
//
// Contract: writeCalibrationSettings() writes an ORB-SLAM2-style settings YAML (%YAML:1.0,
// Camera.fx/fy/cx/cy, width, height, fps, RGB, ORBextractor.* at orbis's defaults) that
// Settings::load and so `orbis run --settings` take unchanged: a pinhole gets Camera.k1 k2 p1 p2
// k3, a fisheye Camera.type: "KannalaBrandt8" with Camera.k1..k4 (ORB-SLAM3's keys) and
// Camera.maxAngle, the widest angle the image sees. writeCalibrationReport() fills a folder with
// report.json (every number of the result, per view), coverage.png (every used corner drawn where
// it fell, one colour per view, outliers' corners as red crosses) and undistorted.png (`preview`,
// one of the calibration images, undistorted to a pinhole with OpenCV's remap; a fisheye wider
// than a pinhole can show keeps its central part). calibrationJson() is the one JSON object
// `orbis calibrate --json` prints: fx fy cx cy distortion (list) rms views_used model and the rest.
// Files that cannot be written throw orbis::Error naming them.
#pragma once

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "orbis/calibration/calibrate.hpp"

namespace orbis::calibration {

void writeCalibrationSettings(const std::filesystem::path& file, const CalibratedCamera& camera, double fps = 30.0);

// The pinhole an image of `camera` is undistorted to (the same focal length for a pinhole; for a
// fisheye, OpenCV's estimate that keeps only valid pixels), and the undistorted image.
cv::Mat undistortToPinhole(const CalibratedCamera& camera, const cv::Mat& image, PinholeCamera<double>* pinhole = nullptr);

void writeCalibrationReport(const std::filesystem::path& folder, const CalibrationResult& result,
                            const CalibrationPattern& pattern, const cv::Mat& preview);

std::string calibrationJson(const CalibrationResult& result, const CalibrationPattern& pattern,
                            const std::filesystem::path& settings);

}  // namespace orbis::calibration
