// Stereo rig calibration; see orbis/calibration/stereo_calibrate.hpp.
#include "orbis/calibration/stereo_calibrate.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <optional>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>

#include "orbis/util/error.hpp"

namespace orbis::calibration {

namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// One pair's corners seen by both cameras, on the board and in each image.
struct CommonCorners {
  std::vector<cv::Point3f> board;
  std::vector<cv::Point2f> left, right;
};

CommonCorners commonCorners(const PatternDetection& l, const PatternDetection& r, const CalibrationPattern& pattern) {
  CommonCorners c;
  for (std::size_t i = 0; i < l.ids.size(); ++i) {
    const auto it = std::find(r.ids.begin(), r.ids.end(), l.ids[i]);
    if (it == r.ids.end()) continue;
    const Eigen::Vector3d p = pattern.objectPoint(l.ids[i]);
    c.board.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
    c.left.push_back(l.corners[i]);
    c.right.push_back(r.corners[static_cast<std::size_t>(it - r.ids.begin())]);
  }
  return c;
}

// Why a pair cannot serve the extrinsics, or "" when it can: both views must show the board
// and be kept (not blurred, not outliers) by their own camera's calibration.
std::string pairProblem(const CalibrationView& l, const CalibrationView& r, const ViewOutcome& lo, const ViewOutcome& ro) {
  if (!l.detection) return "no pattern in the left view";
  if (!r.detection) return "no pattern in the right view";
  for (const auto& [side, o] : {std::pair<const char*, const ViewOutcome&>{"left", lo}, {"right", ro}})
    if (o.rejected == "blurred" || o.outlier) return std::string(side) + ": " + o.rejected;
  return "";
}

cv::Matx33d cameraMatrix(const CalibratedCamera& c) { return {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1}; }

// A camera's pose of the board from its corners alone (PnP on undistorted rays).
SE3d boardPose(const CalibratedCamera& camera, const std::vector<cv::Point3f>& board, const std::vector<cv::Point2f>& image) {
  cv::Vec3d rvec, tvec;
  cv::solvePnP(board, undistortToPlane(camera, image), cv::Matx33d::eye(), cv::noArray(), rvec, tvec);
  return poseFromRotationVector(rvec, tvec);
}

// The rig moved by δ: rotation R·exp(δω), translation t + δt (so δt is t's own perturbation).
SE3d perturbRig(const SE3d& rig, const Vector6d& delta) {
  const Eigen::Vector3d w = delta.tail<3>();
  const Eigen::Matrix3d turn =
      w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() : Eigen::Matrix3d::Identity();
  return SE3d(rig.rotationMatrix() * turn, rig.translation() + delta.head<3>());
}

// A camera's projection with the lens built once (CalibratedCamera::project builds it per point).
struct Lens {
  explicit Lens(const CalibratedCamera& c) : camera(c) {
    if (c.model == LensModel::Fisheye) fisheye = c.fisheye();
  }
  Eigen::Vector2d project(const Eigen::Vector3d& p) const { return fisheye ? fisheye->project(p) : camera.project(p); }
  CalibratedCamera camera;
  std::optional<KannalaBrandtCamera<double>> fisheye;
};

// Reprojection errors (x, y per corner; left corners first, then right) of one pair.
Eigen::VectorXd pairResiduals(const Lens& l, const Lens& r, const SE3d& rig, const SE3d& leftFromBoard,
                              const CommonCorners& c) {
  const std::size_t n = c.board.size();
  Eigen::VectorXd e(4 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d pl = leftFromBoard * Eigen::Vector3d(c.board[i].x, c.board[i].y, c.board[i].z);
    const Eigen::Vector2d el = l.project(pl) - Eigen::Vector2d(c.left[i].x, c.left[i].y);
    const Eigen::Vector2d er = r.project(rig * pl) - Eigen::Vector2d(c.right[i].x, c.right[i].y);
    e.segment<2>(2 * static_cast<Eigen::Index>(i)) = el;
    e.segment<2>(2 * static_cast<Eigen::Index>(n + i)) = er;
  }
  return e;
}

// Numeric Jacobian of a residual function of a 6-vector perturbation at zero.
template <class F>
Eigen::MatrixXd numericJacobian(const F& residuals, Eigen::Index rows, double step) {
  Eigen::MatrixXd J(rows, 6);
  for (int k = 0; k < 6; ++k) {
    Vector6d plus = Vector6d::Zero(), minus = Vector6d::Zero();
    plus[k] = step;
    minus[k] = -step;
    J.col(k) = (residuals(plus) - residuals(minus)) / (2 * step);
  }
  return J;
}

// The board pose of a pair refined on both cameras' corners with the rig fixed (Gauss-Newton):
// the pose the extrinsics' fit would give it, so per-pair errors and σ match that fit.
SE3d refinePose(const Lens& l, const Lens& r, const SE3d& rig, SE3d pose, const CommonCorners& c) {
  for (int iteration = 0; iteration < 8; ++iteration) {
    const auto residuals = [&](const Vector6d& d) { return pairResiduals(l, r, rig, SE3d::exp(d) * pose, c); };
    const Eigen::MatrixXd J = numericJacobian(residuals, static_cast<Eigen::Index>(4 * c.board.size()), 1e-7);
    const Vector6d step = (J.transpose() * J).ldlt().solve(-J.transpose() * residuals(Vector6d::Zero()));
    pose = SE3d::exp(step) * pose;
    if (step.norm() < 1e-12) break;
  }
  return pose;
}

// The rig from the pairs' own board poses (each camera's calibration's, or PnP), robustly: the
// median translation, pairs far from it named inconsistent (`consistent`), the rotation the
// chordal mean of the rest; then Gauss-Newton over the rig and every consistent pair's board pose
// on both cameras' corners (Schur complement on the rig). For Kannala-Brandt pairs: OpenCV's
// fisheye::stereoCalibrate refuses boards seen far off axis ("abs_max < threshold"), which are
// exactly the views a fisheye needs.
SE3d fitRig(const Lens& l, const Lens& r, const std::vector<CommonCorners>& corners, std::vector<SE3d> poses,
            const std::vector<SE3d>& rightPoses, std::vector<bool>& consistent) {
  std::vector<SE3d> rigs;
  std::array<std::vector<double>, 3> components;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    rigs.push_back(rightPoses[k] * poses[k].inverse());
    for (int i = 0; i < 3; ++i) components[static_cast<std::size_t>(i)].push_back(rigs.back().translation()[i]);
  }
  Eigen::Vector3d median;
  for (int i = 0; i < 3; ++i) {
    std::vector<double>& v = components[static_cast<std::size_t>(i)];
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    median[i] = v[v.size() / 2];
  }
  Eigen::Matrix3d rotationSum = Eigen::Matrix3d::Zero();
  consistent.assign(corners.size(), false);
  for (std::size_t k = 0; k < corners.size(); ++k) {
    consistent[k] = (rigs[k].translation() - median).norm() < 0.1 * median.norm();
    if (consistent[k]) rotationSum += rigs[k].rotationMatrix();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotationSum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d rotation = svd.matrixU() * svd.matrixV().transpose();
  if (rotation.determinant() < 0) rotation = -rotation;
  SE3d rig(rotation, median);
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix<double, 6, 6> reduced = Eigen::Matrix<double, 6, 6>::Zero();
    Vector6d gradient = Vector6d::Zero();
    std::vector<Eigen::Matrix<double, 6, 6>> Cs(corners.size()), Bs(corners.size());
    std::vector<Vector6d> poseGradients(corners.size());
    for (std::size_t k = 0; k < corners.size(); ++k) {
      if (!consistent[k]) continue;
      const CommonCorners& c = corners[k];
      const Eigen::Index rows = static_cast<Eigen::Index>(4 * c.board.size());
      const Eigen::MatrixXd Jrig =
          numericJacobian([&](const Vector6d& d) { return pairResiduals(l, r, perturbRig(rig, d), poses[k], c); }, rows, 1e-7);
      const Eigen::MatrixXd Jpose =
          numericJacobian([&](const Vector6d& d) { return pairResiduals(l, r, rig, SE3d::exp(d) * poses[k], c); }, rows, 1e-7);
      const Eigen::VectorXd e = pairResiduals(l, r, rig, poses[k], c);
      Cs[k] = Jpose.transpose() * Jpose, Bs[k] = Jrig.transpose() * Jpose;
      poseGradients[k] = Jpose.transpose() * e;
      reduced += Jrig.transpose() * Jrig - Bs[k] * Cs[k].ldlt().solve(Bs[k].transpose());
      gradient += Jrig.transpose() * e - Bs[k] * Cs[k].ldlt().solve(poseGradients[k]);
    }
    const Vector6d rigStep = reduced.ldlt().solve(-gradient);
    rig = perturbRig(rig, rigStep);
    for (std::size_t k = 0; k < corners.size(); ++k)
      if (consistent[k]) poses[k] = SE3d::exp(Cs[k].ldlt().solve(-poseGradients[k] - Bs[k].transpose() * rigStep)) * poses[k];
    if (rigStep.norm() < 1e-10) break;
  }
  return rig;
}

// The sum of squared reprojection errors of the pairs under a rig, each board pose refined.
double rigError(const Lens& l, const Lens& r, const SE3d& rig, const std::vector<CommonCorners>& corners) {
  double squared = 0;
  for (const CommonCorners& c : corners)
    squared += pairResiduals(l, r, rig, refinePose(l, r, rig, boardPose(l.camera, c.board, c.left), c), c).squaredNorm();
  return squared;
}

// The pose of view `name` in a camera's calibration, or PnP when the calibration did not fit it.
SE3d viewPose(const CalibrationResult& r, const std::string& name, const CalibratedCamera& camera,
              const std::vector<cv::Point3f>& board, const std::vector<cv::Point2f>& image) {
  const auto it = std::find(r.usedNames.begin(), r.usedNames.end(), name);
  if (it != r.usedNames.end()) return r.cameraFromBoard[static_cast<std::size_t>(it - r.usedNames.begin())];
  return boardPose(camera, board, image);
}

CameraCalibration rectificationInput(const CalibratedCamera& c, const SE3d& cameraFromLeft) {
  CameraCalibration out;
  out.intrinsics = c.pinhole();
  if (c.model == LensModel::Fisheye) out.fisheye = std::array<double, 4>{c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3]};
  else out.distortion = c.radTan();
  out.bodyFromCamera = cameraFromLeft.inverse().matrix();
  return out;
}

}  // namespace

StereoRectification rectifyRig(const CalibratedCamera& left, const CalibratedCamera& right, const SE3d& rightFromLeft) {
  const StereoRectification rectified = rectifyStereo(rectificationInput(left, SE3d()), rectificationInput(right, rightFromLeft));
  if (left.model != LensModel::Fisheye) return rectified;
  // fisheye::stereoRectify places the principal point unstably for lenses near 180 degrees (a
  // calibrated 180-degree rig came out at cx = -53 of 640 where its truth gives 320): the
  // rectified pair looks straight ahead instead, principal point at the image centre.
  RectificationBlock l = rectified.left, r = rectified.right;
  for (RectificationBlock* b : {&l, &r}) {
    b->P(0, 2) = 0.5 * (left.width - 1);
    b->P(1, 2) = 0.5 * (left.height - 1);
  }
  return rectificationFromBlocks(l, r, "stereo calibration");
}

StereoCalibrationResult calibrateStereo(const std::vector<CalibrationView>& left, const std::vector<CalibrationView>& right,
                                        const CalibrationPattern& pattern, const CalibrationOptions& options,
                                        const std::string& source) {
  if (left.size() != right.size())
    throw Error(source, "", "the left camera gave " + std::to_string(left.size()) + " views but the right " +
                                std::to_string(right.size()) +
                                ": a stereo rig is calibrated from pairs taken at the same moment; give both cameras' "
                                "images of each moment (same count, same order)");
  for (std::size_t i = 0; i < left.size(); ++i)
    if (left[i].detection && right[i].detection && left[i].imageSize != right[i].imageSize)
      throw Error(source, "", "pair " + left[i].name + " / " + right[i].name + " has a " +
                                  std::to_string(left[i].imageSize.width) + "x" + std::to_string(left[i].imageSize.height) +
                                  " left and a " + std::to_string(right[i].imageSize.width) + "x" +
                                  std::to_string(right[i].imageSize.height) +
                                  " right image: both cameras of a rig must run at one resolution");
  StereoCalibrationResult result;
  result.left = calibrate(left, pattern, options, source + " (left camera)");
  result.right = calibrate(right, pattern, options, source + " (right camera)");
  const CalibratedCamera& lc = result.left.camera;
  const CalibratedCamera& rc = result.right.camera;

  // Pairs both cameras kept.
  std::vector<CommonCorners> corners;
  std::vector<std::size_t> used;
  result.pairs.resize(left.size());
  for (std::size_t i = 0; i < left.size(); ++i) {
    StereoPairOutcome& o = result.pairs[i];
    o.name = left[i].name;
    o.rejected = pairProblem(left[i], right[i], result.left.views[i], result.right.views[i]);
    if (!o.rejected.empty()) continue;
    CommonCorners c = commonCorners(*left[i].detection, *right[i].detection, pattern);
    if (c.board.size() < 6) {
      o.rejected = "fewer than 6 corners seen by both cameras";
      continue;
    }
    corners.push_back(std::move(c));
    used.push_back(i);
  }
  if (static_cast<int>(used.size()) < options.minViews)
    throw Error(source, "", std::to_string(used.size()) + " pairs show the board sharply in both cameras; at least " +
                                std::to_string(options.minViews) +
                                " are needed for the extrinsics: take more pairs with the whole board in view of both "
                                "cameras, tilted by 20-45 degrees in several directions");

  // Extrinsics with the intrinsics fixed: orbis's fitRig (see there), and for pinholes also
  // OpenCV's stereoCalibrate, kept when it explains the corners at least as well (on 8 small
  // rendered pairs it converged to a rig 5x too short, 15 px RMS: docs/notes/2026-11-26-fisheye.md).
  const Lens leftLens(lc), rightLens(rc);
  std::vector<SE3d> leftPoses, rightPoses;
  for (std::size_t k = 0; k < used.size(); ++k) {
    leftPoses.push_back(viewPose(result.left, left[used[k]].name, lc, corners[k].board, corners[k].left));
    rightPoses.push_back(viewPose(result.right, right[used[k]].name, rc, corners[k].board, corners[k].right));
  }
  std::vector<bool> consistent;
  result.rightFromLeft = fitRig(leftLens, rightLens, corners, leftPoses, rightPoses, consistent);
  std::vector<CommonCorners> kept;
  std::vector<std::size_t> keptPairs;
  for (std::size_t k = 0; k < used.size(); ++k) {
    if (consistent[k]) {
      kept.push_back(std::move(corners[k]));
      keptPairs.push_back(used[k]);
    } else {
      result.pairs[used[k]].rejected = "the two views disagree on the rig (not taken at the same moment?)";
    }
  }
  corners = std::move(kept);
  used = std::move(keptPairs);
  if (used.size() < 3)
    throw Error(source, "", "only " + std::to_string(used.size()) + " pairs agree on where the right camera is: check "
                                "that --right names the right camera's views of the same moments, in the same order");
  if (options.model == LensModel::Pinhole && static_cast<int>(used.size()) >= options.minViews) {
    const cv::Size size(lc.width, lc.height);
    std::vector<std::vector<cv::Point3f>> object;
    std::vector<std::vector<cv::Point2f>> l, r;
    for (const CommonCorners& c : corners) object.push_back(c.board), l.push_back(c.left), r.push_back(c.right);
    cv::Mat K1(cameraMatrix(lc)), K2(cameraMatrix(rc)), D1(lc.distortion), D2(rc.distortion), R, T, E, F;
    const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, DBL_EPSILON);
    try {
      cv::stereoCalibrate(object, l, r, K1, D1, K2, D2, size, R, T, E, F, cv::CALIB_FIX_INTRINSIC, criteria);
      Eigen::Matrix3d rotation;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) rotation(i, j) = R.at<double>(i, j);
      const SE3d opencv(Eigen::Quaterniond(rotation).normalized().toRotationMatrix(),
                        Eigen::Vector3d(T.at<double>(0), T.at<double>(1), T.at<double>(2)));
      if (rigError(leftLens, rightLens, opencv, corners) <= rigError(leftLens, rightLens, result.rightFromLeft, corners))
        result.rightFromLeft = opencv;
    } catch (const cv::Exception&) {
      // orbis's fit stands.
    }
  }
  const Eigen::Matrix3d rotation = result.rightFromLeft.rotationMatrix();
  const Eigen::Vector3d translation = result.rightFromLeft.translation();
  result.baseline = translation.norm();
  const Eigen::Vector3d rightCentre = -(rotation.transpose() * translation);  // in the left camera
  if (!(rightCentre.x() > 0.5 * result.baseline))
    throw Error(source, "", "the right camera sits at (" + std::to_string(rightCentre.x()) + ", " +
                                std::to_string(rightCentre.y()) + ", " + std::to_string(rightCentre.z()) +
                                ") m from the left one, not to its right: swap the two streams (PATH is the left "
                                "camera, --right the right one; side-by-side frames have the left camera's image first)");

  // Per-pair errors and the baseline's σ: board poses refined on both cameras, then the normal
  // matrix of the rig's 6 parameters with the poses marginalised (Schur complement).
  Eigen::Matrix<double, 6, 6> reduced = Eigen::Matrix<double, 6, 6>::Zero();
  double squared = 0;
  std::size_t observations = 0;
  for (std::size_t k = 0; k < used.size(); ++k) {
    const CommonCorners& c = corners[k];
    const SE3d pose = refinePose(leftLens, rightLens, result.rightFromLeft, boardPose(lc, c.board, c.left), c);
    const Eigen::Index rows = static_cast<Eigen::Index>(4 * c.board.size());
    const Eigen::MatrixXd Jrig = numericJacobian(
        [&](const Vector6d& d) { return pairResiduals(leftLens, rightLens, perturbRig(result.rightFromLeft, d), pose, c); }, rows, 1e-7);
    const Eigen::MatrixXd Jpose = numericJacobian(
        [&](const Vector6d& d) { return pairResiduals(leftLens, rightLens, result.rightFromLeft, SE3d::exp(d) * pose, c); }, rows, 1e-7);
    const Eigen::Matrix<double, 6, 6> C = Jpose.transpose() * Jpose, B = Jrig.transpose() * Jpose;
    reduced += Jrig.transpose() * Jrig - B * C.ldlt().solve(B.transpose());
    const Eigen::VectorXd e = pairResiduals(leftLens, rightLens, result.rightFromLeft, pose, c);
    const Eigen::Index half = rows / 2;
    StereoPairOutcome& o = result.pairs[used[k]];
    o.used = true;
    o.rmsLeft = std::sqrt(e.head(half).squaredNorm() / static_cast<double>(c.board.size()));
    o.rmsRight = std::sqrt(e.tail(half).squaredNorm() / static_cast<double>(c.board.size()));
    squared += e.squaredNorm();
    observations += static_cast<std::size_t>(rows);
  }
  result.pairsUsed = static_cast<int>(used.size());
  result.rms = std::sqrt(squared / static_cast<double>(observations / 2));
  const double dof = static_cast<double>(observations) - 6.0 - 6.0 * static_cast<double>(used.size());
  const Eigen::Matrix3d translationCovariance =
      (reduced.inverse() * (squared / std::max(dof, 1.0))).topLeftCorner<3, 3>();
  const Eigen::Vector3d direction = translation.normalized();
  result.baselineSigma = std::sqrt(std::max(direction.dot(translationCovariance * direction), 0.0));

  result.rectification = rectifyRig(lc, rc, result.rightFromLeft);
  for (const std::string& w : result.left.warnings) result.warnings.push_back("left camera: " + w);
  for (const std::string& w : result.right.warnings) result.warnings.push_back("right camera: " + w);
  return result;
}

}  // namespace orbis::calibration
