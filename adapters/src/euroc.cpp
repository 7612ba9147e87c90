// EuRoC MAV reader: mav0/cam0 and mav0/cam1 (data.csv in nanoseconds + sensor.yaml), stereo
// pairs matched by timestamp, rectified on load; ground truth from
// state_groundtruth_estimate0/data.csv, turned from body poses into left-camera poses.
#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "dataset_common.hpp"
#include "orbis/camera/euroc_calibration.hpp"
#include "orbis/camera/rectification.hpp"
#include "orbis/util/error.hpp"

namespace orbis {
namespace {

using namespace adapters_detail;
namespace fs = std::filesystem;

SE3d toPose(const Eigen::Matrix4d& m) {
  return SE3d(Eigen::Matrix3d(m.topLeftCorner<3, 3>()), Eigen::Vector3d(m.topRightCorner<3, 1>()));
}

class EurocReader final : public DatasetReader {
 public:
  EurocReader(const fs::path& root, const DatasetOptions& options)
      : root_(root), options_(options), sensor_(options.sensor.value_or(SensorKind::Stereo)) {
    if (sensor_ == SensorKind::Rgbd)
      throw Error(root.string(), "", "EuRoC has no depth maps (use stereo or mono)");
    const fs::path mav = fs::exists(root / "mav0") ? root / "mav0" : root;
    requireExists(mav / "cam0", "the EuRoC cam0 folder");
    left_ = readImageList(mav / "cam0" / "data.csv", mav / "cam0" / "data", TimeUnit::Nanoseconds,
                          !options.tolerateBadFrames, warnings_);
    leftSensor_ = readEurocCalibration(mav / "cam0" / "sensor.yaml");
    if (sensor_ == SensorKind::Stereo) {
      std::vector<ListedImage> right =
          readImageList(mav / "cam1" / "data.csv", mav / "cam1" / "data", TimeUnit::Nanoseconds, false, warnings_);
      right_ = PairedImages(left_, std::move(right), options.maxStereoDt, "cam1 image");
      rightSensor_ = readEurocCalibration(mav / "cam1" / "sensor.yaml");
      if (options.strict) right_.requireAll(left_);
    }
    if (options.rectify) prepareRectification();

    // The ground truth as published (data.csv, 17 columns) or converted to TUM form, by evo
    // (data.tum) or by hand into data.csv: both carry body poses.
    fs::path gtFile = mav / "state_groundtruth_estimate0" / "data.csv";
    if (!fs::exists(gtFile)) gtFile.replace_extension(".tum");
    if (fs::exists(gtFile)) {
      // Body poses T_WB to left-camera poses T_WC = T_WB T_BS, then to the rectified left
      // camera: rectification rotates the camera by R1 (x_rect = R1 x_cam).
      const SE3d cameraFromRectified(rectifiedRotation_.transpose(), Eigen::Vector3d::Zero());
      groundTruth_ = readTrajectory(gtFile, detectTrajectoryFormat(gtFile), {}, &warnings_);
      const SE3d bodyFromCamera = toPose(leftSensor_.bodyFromCamera);
      for (StampedPose& sp : groundTruth_) sp.pose = sp.pose * bodyFromCamera * cameraFromRectified;
    }
  }

  DatasetKind kind() const override { return DatasetKind::Euroc; }
  SensorKind sensor() const override { return sensor_; }
  std::size_t size() const override { return left_.size(); }
  double timestamp(std::size_t index) const override { return left_.at(index).t; }
  const Trajectory& groundTruth() const override { return groundTruth_; }
  const fs::path& root() const override { return root_; }

  DatasetCamera camera() const override {
    if (!options_.rectify) {
      if (leftSensor_.fisheye)
        throw Error(root_.string(), "", "an unrectified fisheye has no pinhole camera: give its Kannala-Brandt "
                                        "settings (Camera.type: KannalaBrandt8) or open it with rectify = true");
      if (sensor_ == SensorKind::Monocular) return leftSensor_.intrinsics;
      throw Error(root_.string(), "",
                  "unrectified EuRoC stereo has no RectifiedStereoCamera; "
                  "open it with rectify = true");
    }
    if (sensor_ == SensorKind::Monocular) return rectifiedPinhole_;
    return RectifiedStereoCamera<double>(rectifiedPinhole_, baseline_);
  }

  RadTanDistortion<double> distortion() const override {
    return options_.rectify ? RadTanDistortion<double>{} : leftSensor_.distortion;
  }

  DatasetFrame frame(std::size_t index) const override {
    const ListedImage& left = left_.at(index);
    DatasetFrame frame;
    frame.index = index;
    frame.timestamp = left.t;
    frame.left = rectify(loadImage(left, cv::IMREAD_UNCHANGED), leftMapX_, leftMapY_);
    const ListedImage* right =
        sensor_ == SensorKind::Stereo ? right_.find(left_, index, frame.warnings, false) : nullptr;
    if (right) frame.right = rectify(loadImage(*right, cv::IMREAD_UNCHANGED), rightMapX_, rightMapY_);
    return frame;
  }

 private:
  // Stereo: OpenCV's rectification (camera module, fisheye pairs included); monocular: plain
  // undistortion with the same intrinsics (a fisheye: to the pinhole OpenCV estimates for it).
  void prepareRectification() {
    if (sensor_ == SensorKind::Monocular) {
      const PinholeCamera<double>& k = leftSensor_.intrinsics;
      const RadTanDistortion<double>& d = leftSensor_.distortion;
      cv::Mat cameraMatrix, coefficients = (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
      cv::eigen2cv(k.K(), cameraMatrix);
      if (const auto& fisheye = leftSensor_.fisheye) {
        // A fisheye is undistorted to the pinhole OpenCV picks for it (balance 0: valid pixels only).
        const cv::Mat kb = (cv::Mat_<double>(1, 4) << (*fisheye)[0], (*fisheye)[1], (*fisheye)[2], (*fisheye)[3]);
        const cv::Size size(k.width, k.height);
        cv::Mat newK;
        cv::fisheye::estimateNewCameraMatrixForUndistortRectify(cameraMatrix, kb, size, cv::Mat::eye(3, 3, CV_64F), newK,
                                                                0.0, size, 1.0);
        cv::fisheye::initUndistortRectifyMap(cameraMatrix, kb, cv::Mat::eye(3, 3, CV_64F), newK, size, CV_32FC1,
                                             leftMapX_, leftMapY_);
        rectifiedPinhole_ = {newK.at<double>(0, 0), newK.at<double>(1, 1), newK.at<double>(0, 2),
                             newK.at<double>(1, 2), k.width, k.height};
        return;
      }
      cv::initUndistortRectifyMap(cameraMatrix, coefficients, cv::Mat(), cameraMatrix,
                                  cv::Size(k.width, k.height), CV_32FC1, leftMapX_, leftMapY_);
      rectifiedPinhole_ = k;
      return;
    }
    const StereoRectification rectification = rectifyStereo(leftSensor_, rightSensor_);
    leftMapX_ = rectification.leftMapX;
    leftMapY_ = rectification.leftMapY;
    rightMapX_ = rectification.rightMapX;
    rightMapY_ = rectification.rightMapY;
    rectifiedPinhole_ = rectification.camera.pinhole;
    baseline_ = rectification.camera.baseline;
    rectifiedRotation_ = rectification.left.R;
  }

  cv::Mat rectify(const cv::Mat& image, const cv::Mat& mapX, const cv::Mat& mapY) const {
    if (mapX.empty()) return image;
    cv::Mat out;
    cv::remap(image, out, mapX, mapY, cv::INTER_LINEAR);
    return out;
  }

  fs::path root_;
  DatasetOptions options_;
  SensorKind sensor_;
  std::vector<ListedImage> left_;
  PairedImages right_;
  CameraCalibration leftSensor_, rightSensor_;
  cv::Mat leftMapX_, leftMapY_, rightMapX_, rightMapY_;
  PinholeCamera<double> rectifiedPinhole_;
  Eigen::Matrix3d rectifiedRotation_ = Eigen::Matrix3d::Identity();
  double baseline_ = 0.0;
  Trajectory groundTruth_;
};

}  // namespace

std::unique_ptr<DatasetReader> openEuroc(const std::filesystem::path& root, const DatasetOptions& options) {
  return std::make_unique<EurocReader>(root, options);
}

}  // namespace orbis
