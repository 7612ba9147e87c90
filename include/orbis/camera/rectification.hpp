// orbis/camera/rectification.hpp — rectification of a calibrated stereo pair.
//
// Contract: rectifyStereo() takes the calibration of two cameras (intrinsics, radial-tangential
// distortion, extrinsics relative to a common body frame, as EuRoC publishes them) and returns
// the RectifiedStereoCamera both rectified images share plus OpenCV remap tables; rectify()
// applies them to a pair. rectificationFromBlocks() does the same from ORB-SLAM2's LEFT./RIGHT.
// settings blocks (K, D, R, P, width, height), which already hold the rectification.
// After rectification a scene point has the same row in both images and uR = uL - bf/Z.
// Inconsistent input (different resolutions, a vertical or reversed pair) throws orbis::Error;
// the source of the calibration is named by the caller (settings file, sensor.yaml).
// A camera may instead carry a Kannala–Brandt fisheye lens (CameraCalibration::fisheye, k1..k4,
// Kalibr's "equidistant"): a pair of them is rectified with OpenCV's fisheye functions to a
// pinhole pair (balance 0: only valid pixels, the field of view a pinhole can hold).
#pragma once

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "orbis/camera/distortion.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/stereo.hpp"

namespace orbis {

// One physical camera as calibrated: pixels are distorted, the pose is relative to the body.
struct CameraCalibration {
  PinholeCamera<double> intrinsics;  // width/height are the image resolution
  // The lens of the raw images.
  RadTanDistortion<double> distortion;
  std::optional<std::array<double, 4>> fisheye;  // Kannala-Brandt k1..k4, replacing `distortion`
  Eigen::Matrix4d bodyFromCamera = Eigen::Matrix4d::Identity();  // EuRoC T_BS

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

// OpenCV's rectification of one camera of a pair, as ORB-SLAM2's LEFT./RIGHT. blocks hold it:
// a rectified pixel p comes from the raw pixel distort(K, D, R^T P_3x3^-1 p).
struct RectificationBlock {
  // The raw camera's matrix.
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  // The raw camera's distortion.
  RadTanDistortion<double> D;
  std::optional<std::array<double, 4>> fisheye;  // Kannala-Brandt k1..k4 instead of D
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // rectified camera from raw camera
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();  // rectified projection
  // @{
  // The image size.
  int width = 0, height = 0;
  // @}

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

// A calibrated stereo pair rectified into a RectifiedStereoCamera, with the remap tables that turn
// raw images into rectified ones.
struct StereoRectification {
  RectifiedStereoCamera<double> camera;  // of the rectified images; closeDepth = 40 baselines
  // @{
  // The left and right camera's rectification.
  RectificationBlock left, right;        // what the remap tables were built from
  // @}
  // @{
  // Remap tables (CV_32FC1): for each rectified pixel, the raw pixel it comes from.
  cv::Mat leftMapX, leftMapY, rightMapX, rightMapY;  // CV_32FC1, rectified pixel -> raw pixel
  // @}

  // A rectified image pair.
  struct Images {
    // @{
    // The rectified left and right images.
    cv::Mat left, right;
    // @}
  };
  // Bilinear remap of a raw pair (any type cv::remap takes) into the rectified pair.
  Images rectify(const cv::Mat& rawLeft, const cv::Mat& rawRight) const;

  // Where a raw (distorted) left/right pixel lands in the rectified image.
  Eigen::Vector2d rectifyLeftPixel(const Eigen::Vector2d& raw) const;
  // Where a raw (distorted) right pixel lands in the rectified right image.
  Eigen::Vector2d rectifyRightPixel(const Eigen::Vector2d& raw) const;

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

// cv::stereoRectify with zero disparity at infinity and alpha = 0 (only valid pixels kept).
StereoRectification rectifyStereo(const CameraCalibration& left, const CameraCalibration& right);

// `source` names where the blocks came from, for error messages.
StereoRectification rectificationFromBlocks(const RectificationBlock& left, const RectificationBlock& right,
                                            const std::string& source = "stereo rectification");

}  // namespace orbis
