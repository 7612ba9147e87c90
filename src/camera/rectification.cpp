// Stereo rectification with OpenCV; see orbis/camera/rectification.hpp.
#include "orbis/camera/rectification.hpp"

#include <cmath>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace {

cv::Mat toCv(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

cv::Mat coefficients(const RadTanDistortion<double>& d) {
  return (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
}

cv::Mat fisheyeCoefficients(const std::array<double, 4>& k) { return (cv::Mat_<double>(1, 4) << k[0], k[1], k[2], k[3]); }

KannalaBrandtCamera<double> fisheyeOf(const Eigen::Matrix3d& K, const std::array<double, 4>& k) {
  KannalaBrandtCamera<double> lens;
  lens.fx = K(0, 0), lens.fy = K(1, 1), lens.cx = K(0, 2), lens.cy = K(1, 2);
  lens.k1 = k[0], lens.k2 = k[1], lens.k3 = k[2], lens.k4 = k[3];
  return lens;
}

void buildMaps(const RectificationBlock& block, cv::Mat& mapX, cv::Mat& mapY) {
  if (block.fisheye) {
    cv::fisheye::initUndistortRectifyMap(toCv(block.K), fisheyeCoefficients(*block.fisheye), toCv(block.R),
                                         toCv(block.P.leftCols<3>()), cv::Size(block.width, block.height), CV_32FC1,
                                         mapX, mapY);
    return;
  }
  cv::initUndistortRectifyMap(toCv(block.K), coefficients(block.D), toCv(block.R),
                              toCv(block.P.leftCols<3>()), cv::Size(block.width, block.height), CV_32FC1, mapX,
                              mapY);
}

Eigen::Vector2d rectifyPixel(const RectificationBlock& block, const Eigen::Vector2d& raw) {
  const PinholeCamera<double> intrinsics{block.K(0, 0), block.K(1, 1), block.K(0, 2), block.K(1, 2),
                                         block.width, block.height};
  const Eigen::Vector3d rawRay = block.fisheye ? fisheyeOf(block.K, *block.fisheye).bearing(raw)
                                               : block.D.undistort(intrinsics.pixelToNormalized(raw)).homogeneous();
  const Eigen::Vector3d ray = block.P.leftCols<3>() * (block.R * rawRay);
  return ray.hnormalized();
}

bool near(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(a)); }

}  // namespace

StereoRectification::Images StereoRectification::rectify(const cv::Mat& rawLeft, const cv::Mat& rawRight) const {
  Images out;
  cv::remap(rawLeft, out.left, leftMapX, leftMapY, cv::INTER_LINEAR);
  cv::remap(rawRight, out.right, rightMapX, rightMapY, cv::INTER_LINEAR);
  return out;
}

Eigen::Vector2d StereoRectification::rectifyLeftPixel(const Eigen::Vector2d& raw) const {
  return rectifyPixel(left, raw);
}

Eigen::Vector2d StereoRectification::rectifyRightPixel(const Eigen::Vector2d& raw) const {
  return rectifyPixel(right, raw);
}

StereoRectification rectificationFromBlocks(const RectificationBlock& left, const RectificationBlock& right,
                                            const std::string& source) {
  if (left.width <= 0 || left.height <= 0 || left.width != right.width || left.height != right.height) {
    throw Error(source, "", "left and right images must have the same positive width and height");
  }
  const auto& P1 = left.P;
  const auto& P2 = right.P;
  if (!(P1(0, 0) > 0 && P1(1, 1) > 0)) throw Error(source, "", "rectified focal lengths must be positive");
  if (!near(P1(0, 0), P2(0, 0)) || !near(P1(1, 1), P2(1, 1)) || !near(P1(0, 2), P2(0, 2)) ||
      !near(P1(1, 2), P2(1, 2))) {
    throw Error(source, "", "left and right rectified projections (P) must share fx, fy, cx, cy");
  }
  if (P1.col(3).norm() > 1e-9 * P1(0, 0) || std::abs(P2(1, 3)) > 1e-9 * P1(0, 0)) {
    throw Error(source, "", "expected a horizontal pair with the left camera at the origin (P1 = K[I|0])");
  }
  const double baseline = -P2(0, 3) / P2(0, 0);
  if (!(baseline > 0)) throw Error(source, "", "the right camera must lie to the right of the left (P2[0,3] < 0)");

  StereoRectification r;
  r.left = left;
  r.right = right;
  const PinholeCamera<double> rectified{P1(0, 0), P1(1, 1), P1(0, 2), P1(1, 2), left.width, left.height};
  r.camera = RectifiedStereoCamera<double>(rectified, baseline);
  buildMaps(left, r.leftMapX, r.leftMapY);
  buildMaps(right, r.rightMapX, r.rightMapY);
  return r;
}

StereoRectification rectifyStereo(const CameraCalibration& left, const CameraCalibration& right) {
  const std::string source = "stereo calibration";
  const PinholeCamera<double>& kl = left.intrinsics;
  const PinholeCamera<double>& kr = right.intrinsics;
  if (kl.width <= 0 || kl.height <= 0 || kl.width != kr.width || kl.height != kr.height) {
    throw Error(source, "", "left and right cameras must have the same positive resolution");
  }
  // x_right = R x_left + T: right-from-body composed with body-from-left.
  const Eigen::Matrix3d rotationBodyRight = right.bodyFromCamera.topLeftCorner<3, 3>();
  const Eigen::Matrix3d rotation = rotationBodyRight.transpose() * left.bodyFromCamera.topLeftCorner<3, 3>();
  const Eigen::Vector3d translation =
      rotationBodyRight.transpose() * (left.bodyFromCamera.topRightCorner<3, 1>() - right.bodyFromCamera.topRightCorner<3, 1>());

  const cv::Size size(kl.width, kl.height);
  cv::Mat R1, R2, P1, P2, Q;
  if (left.fisheye.has_value() != right.fisheye.has_value())
    throw Error(source, "", "one camera of the pair is a fisheye and the other is not: calibrate both with one model");
  if (left.fisheye) {
    cv::fisheye::stereoRectify(toCv(kl.K()), fisheyeCoefficients(*left.fisheye), toCv(kr.K()),
                               fisheyeCoefficients(*right.fisheye), size, toCv(rotation), toCv(translation), R1, R2, P1,
                               P2, Q, cv::CALIB_ZERO_DISPARITY, size, 0.0, 1.0);
  } else {
    cv::stereoRectify(toCv(kl.K()), coefficients(left.distortion), toCv(kr.K()), coefficients(right.distortion), size,
                      toCv(rotation), toCv(translation), R1, R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, 0.0, size);
  }

  RectificationBlock l, r;
  l.K = kl.K();
  r.K = kr.K();
  l.D = left.distortion;
  r.D = right.distortion;
  l.fisheye = left.fisheye;
  r.fisheye = right.fisheye;
  cv::cv2eigen(R1, l.R);
  cv::cv2eigen(R2, r.R);
  cv::cv2eigen(P1, l.P);
  cv::cv2eigen(P2, r.P);
  l.width = r.width = kl.width;
  l.height = r.height = kl.height;
  return rectificationFromBlocks(l, r, source);
}

}  // namespace orbis
