// Camera calibration from pattern views; see orbis/calibration/calibrate.hpp.
#include "orbis/calibration/calibrate.hpp"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/util/error.hpp"

namespace orbis::calibration {

namespace fs = std::filesystem;

LensModel parseLensModel(const std::string& name, const std::string& source) {
  if (name == "pinhole") return LensModel::Pinhole;
  if (name == "fisheye") return LensModel::Fisheye;
  throw Error(source, "", "expected pinhole (radial-tangential) or fisheye (Kannala-Brandt), not '" + name + "'");
}

const char* toString(LensModel model) { return model == LensModel::Pinhole ? "pinhole" : "fisheye"; }

RadTanDistortion<double> CalibratedCamera::radTan() const {
  if (model != LensModel::Pinhole || distortion.size() < 4) return {};
  return {distortion[0], distortion[1], distortion[2], distortion[3], distortion.size() > 4 ? distortion[4] : 0.0};
}

KannalaBrandtCamera<double> CalibratedCamera::fisheye() const {
  KannalaBrandtCamera<double> c;
  c.fx = fx, c.fy = fy, c.cx = cx, c.cy = cy, c.width = width, c.height = height;
  if (model == LensModel::Fisheye && distortion.size() == 4)
    c.k1 = distortion[0], c.k2 = distortion[1], c.k3 = distortion[2], c.k4 = distortion[3];
  c.maxAngle = M_PI;
  // The polynomial must increase up to the angles used; stop where it no longer does.
  for (double theta = 0.01; theta < M_PI; theta += 0.01) {
    if (c.distortAngleDerivative(theta) <= 0) {
      c.maxAngle = theta - 0.01;
      break;
    }
  }
  return c;
}

Eigen::Vector3d CalibratedCamera::bearing(const Eigen::Vector2d& px) const {
  if (model == LensModel::Fisheye) return fisheye().bearing(px);
  const PinholeCamera<double> k = pinhole();
  return radTan().undistort(k.pixelToNormalized(px)).homogeneous().normalized();
}

double CalibratedCamera::fieldOfViewAngle() const {
  double widest = 0;
  const KannalaBrandtCamera<double> lens = fisheye();
  for (int k = 0; k <= 64; ++k) {
    const double a = k / 64.0;
    for (const Eigen::Vector2d& px : {Eigen::Vector2d(a * width, 0), Eigen::Vector2d(a * width, height),
                                     Eigen::Vector2d(0, a * height), Eigen::Vector2d(width, a * height)}) {
      const Eigen::Vector3d ray = bearing(px);
      widest = std::max(widest, std::atan2(ray.head<2>().norm(), ray.z()));
    }
  }
  return model == LensModel::Fisheye ? std::min(widest, lens.maxAngle) : widest;
}

Eigen::Vector2d CalibratedCamera::project(const Eigen::Vector3d& pc) const {
  if (model == LensModel::Fisheye) return fisheye().project(pc);
  const PinholeCamera<double> k = pinhole();
  return k.normalizedToPixel(radTan().distort(pc.hnormalized()));
}

// --- detection --------------------------------------------------------------------------------

CalibrationView detectView(const cv::Mat& gray, const std::string& name, const CalibrationPattern& pattern) {
  CalibrationView view;
  view.name = name;
  view.imageSize = gray.size();
  view.detection = detectPattern(gray, pattern);
  if (view.detection && pattern.kind == PatternKind::Chessboard) {
    view.edgeWidth = cv::estimateChessboardSharpness(gray, cv::Size(pattern.cols, pattern.rows), view.detection->corners)[0];
  }
  return view;
}

std::vector<CalibrationView> detectInFolder(const fs::path& folder, const CalibrationPattern& pattern,
                                            const std::function<void(std::size_t, std::size_t)>& onImage) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw fileError(folder.string(), "not a folder of images");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" ||
                                    ext == ".tiff" || ext == ".pgm" || ext == ".ppm"))
      files.push_back(entry.path());
  }
  if (files.empty())
    throw fileError(folder.string(), "holds no image (png, jpg, jpeg, bmp, tif, tiff, pgm, ppm) to calibrate from");
  std::sort(files.begin(), files.end());
  std::vector<CalibrationView> views;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const cv::Mat gray = cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE);
    if (gray.empty()) {
      CalibrationView unreadable;
      unreadable.name = files[i].filename().string() + " (unreadable)";
      views.push_back(unreadable);
    } else {
      views.push_back(detectView(gray, files[i].filename().string(), pattern));
    }
    if (onImage) onImage(i + 1, files.size());
  }
  return views;
}

namespace {

std::vector<cv::Point3f> objectPoints(const PatternDetection& d, const CalibrationPattern& pattern) {
  std::vector<cv::Point3f> points;
  for (int id : d.ids) {
    const Eigen::Vector3d p = pattern.objectPoint(id);
    points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
  }
  return points;
}

// Where the board's outer corners appear (through the view's homography): the view's footprint,
// for duplicate tests and for choosing a spread of views.
std::array<cv::Point2d, 4> footprint(const PatternDetection& d, const CalibrationPattern& pattern) {
  std::vector<cv::Point2f> plane;
  for (int id : d.ids) {
    const Eigen::Vector3d p = pattern.objectPoint(id);
    plane.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  const cv::Mat H = cv::findHomography(plane, d.corners);
  const Eigen::Vector2d size = pattern.boardSize();
  std::array<cv::Point2d, 4> out{};
  const std::array<cv::Point2d, 4> outer{cv::Point2d(0, 0), cv::Point2d(size.x(), 0), cv::Point2d(size.x(), size.y()),
                                         cv::Point2d(0, size.y())};
  for (int k = 0; k < 4; ++k) {
    if (H.empty()) {
      out[k] = d.corners.front();
      continue;
    }
    const cv::Mat p = H * (cv::Mat_<double>(3, 1) << outer[k].x, outer[k].y, 1.0);
    out[k] = cv::Point2d(p.at<double>(0) / p.at<double>(2), p.at<double>(1) / p.at<double>(2));
  }
  return out;
}

// Where the board is, how big, how turned in the image and how tilted: the space a well-spread
// set of views covers.
Eigen::Matrix<double, 7, 1> poseDescriptor(const std::array<cv::Point2d, 4>& f, const cv::Size& size) {
  const double diagonal = std::hypot(size.width, size.height);
  const cv::Point2d centre = (f[0] + f[1] + f[2] + f[3]) * 0.25;
  const auto length = [](const cv::Point2d& a, const cv::Point2d& b) { return std::max(std::hypot(a.x - b.x, a.y - b.y), 1e-6); };
  const double top = length(f[0], f[1]), bottom = length(f[3], f[2]), left = length(f[0], f[3]), right = length(f[1], f[2]);
  const double angle = std::atan2(f[1].y - f[0].y, f[1].x - f[0].x);
  Eigen::Matrix<double, 7, 1> d;
  d << centre.x / size.width, centre.y / size.height, std::sqrt(top * left) / diagonal, 0.25 * std::cos(angle),
      0.25 * std::sin(angle), std::log(top / bottom), std::log(left / right);
  return d;
}

double meanDistance(const std::array<cv::Point2d, 4>& a, const std::array<cv::Point2d, 4>& b) {
  double sum = 0;
  for (int k = 0; k < 4; ++k) sum += std::hypot(a[k].x - b[k].x, a[k].y - b[k].y);
  return sum / 4;
}

struct Fit {
  CalibratedCamera camera;
  std::vector<double> sigmas;
  std::vector<cv::Vec3d> rvecs, tvecs;
  std::vector<double> viewRms;
  double rms = 0;
};

std::vector<cv::Point2d> projectView(const CalibratedCamera& c, const std::vector<cv::Point3f>& object,
                                     const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
  std::vector<cv::Point2d> out;
  const cv::Matx33d K(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  std::vector<cv::Point3d> object64(object.begin(), object.end());
  if (c.model == LensModel::Fisheye) {
    cv::fisheye::projectPoints(object64, out, rvec, tvec, K, cv::Vec4d(c.distortion[0], c.distortion[1],
                                                                       c.distortion[2], c.distortion[3]));
  } else {
    cv::projectPoints(object64, rvec, tvec, K, c.distortion, out);
  }
  return out;
}

void measureViews(Fit& fit, const std::vector<std::vector<cv::Point3f>>& object,
                  const std::vector<std::vector<cv::Point2f>>& image) {
  double total = 0;
  std::size_t count = 0;
  fit.viewRms.clear();
  for (std::size_t v = 0; v < object.size(); ++v) {
    const std::vector<cv::Point2d> projected = projectView(fit.camera, object[v], fit.rvecs[v], fit.tvecs[v]);
    double sum = 0;
    for (std::size_t i = 0; i < projected.size(); ++i) {
      const double dx = projected[i].x - image[v][i].x, dy = projected[i].y - image[v][i].y;
      sum += dx * dx + dy * dy;
    }
    fit.viewRms.push_back(std::sqrt(sum / static_cast<double>(projected.size())));
    total += sum;
    count += projected.size();
  }
  fit.rms = std::sqrt(total / static_cast<double>(count));
}

// σ of the intrinsics: residual σ times sqrt(diag((A - Σ B C⁻¹ Bᵀ)⁻¹)) with a numeric Jacobian
// (intrinsics A, board poses C, both B), the board poses marginalised as OpenCV does for the pinhole.
std::vector<double> fisheyeSigmas(const Fit& fit, const std::vector<std::vector<cv::Point3f>>& object,
                                  const std::vector<std::vector<cv::Point2f>>& image) {
  constexpr int kIntrinsics = 8;
  using Matrix8 = Eigen::Matrix<double, kIntrinsics, kIntrinsics>;
  Matrix8 reduced = Matrix8::Zero();
  double squared = 0;
  std::size_t observations = 0;
  const auto intrinsicsOf = [](const CalibratedCamera& c) {
    Eigen::Matrix<double, kIntrinsics, 1> p;
    p << c.fx, c.fy, c.cx, c.cy, c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3];
    return p;
  };
  const auto cameraOf = [&](const Eigen::Matrix<double, kIntrinsics, 1>& p) {
    CalibratedCamera c = fit.camera;
    c.fx = p[0], c.fy = p[1], c.cx = p[2], c.cy = p[3];
    c.distortion = {p[4], p[5], p[6], p[7]};
    return c;
  };
  const Eigen::Matrix<double, kIntrinsics, 1> p0 = intrinsicsOf(fit.camera);
  for (std::size_t v = 0; v < object.size(); ++v) {
    const int rows = 2 * static_cast<int>(object[v].size());
    const auto residuals = [&](const CalibratedCamera& c, const cv::Vec3d& r, const cv::Vec3d& t) {
      const std::vector<cv::Point2d> projected = projectView(c, object[v], r, t);
      Eigen::VectorXd e(rows);
      for (std::size_t i = 0; i < projected.size(); ++i) {
        e[2 * i] = projected[i].x - image[v][i].x;
        e[2 * i + 1] = projected[i].y - image[v][i].y;
      }
      return e;
    };
    Eigen::MatrixXd J(rows, kIntrinsics), E(rows, 6);
    for (int k = 0; k < kIntrinsics; ++k) {
      const double h = 1e-6 * std::max(1.0, std::abs(p0[k]));
      Eigen::Matrix<double, kIntrinsics, 1> plus = p0, minus = p0;
      plus[k] += h;
      minus[k] -= h;
      J.col(k) = (residuals(cameraOf(plus), fit.rvecs[v], fit.tvecs[v]) -
                  residuals(cameraOf(minus), fit.rvecs[v], fit.tvecs[v])) / (2 * h);
    }
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-7;
      cv::Vec3d rPlus = fit.rvecs[v], rMinus = fit.rvecs[v], tPlus = fit.tvecs[v], tMinus = fit.tvecs[v];
      if (k < 3) rPlus[k] += h, rMinus[k] -= h;
      else tPlus[k - 3] += h, tMinus[k - 3] -= h;
      E.col(k) = (residuals(fit.camera, rPlus, tPlus) - residuals(fit.camera, rMinus, tMinus)) / (2 * h);
    }
    const Eigen::Matrix<double, 6, 6> C = E.transpose() * E;
    const Eigen::Matrix<double, kIntrinsics, 6> B = J.transpose() * E;
    reduced += J.transpose() * J - B * C.ldlt().solve(B.transpose());
    squared += residuals(fit.camera, fit.rvecs[v], fit.tvecs[v]).squaredNorm();
    observations += static_cast<std::size_t>(rows);
  }
  const double dof = static_cast<double>(observations) - kIntrinsics - 6.0 * static_cast<double>(object.size());
  const double variance = squared / std::max(dof, 1.0);
  const Matrix8 covariance = reduced.inverse() * variance;
  std::vector<double> sigmas;
  for (int k = 0; k < kIntrinsics; ++k) sigmas.push_back(std::sqrt(std::max(covariance(k, k), 0.0)));
  return sigmas;
}

Fit fitModel(LensModel model, const std::vector<std::vector<cv::Point3f>>& object,
             const std::vector<std::vector<cv::Point2f>>& image, const cv::Size& size, const std::string& source) {
  Fit fit;
  fit.camera.model = model;
  fit.camera.width = size.width;
  fit.camera.height = size.height;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, DBL_EPSILON);
  try {
    if (model == LensModel::Pinhole) {
      cv::Mat K, D, stdIntrinsics, stdExtrinsics, perView;
      std::vector<cv::Mat> rvecs, tvecs;
      cv::calibrateCamera(object, image, size, K, D, rvecs, tvecs, stdIntrinsics, stdExtrinsics, perView, 0, criteria);
      fit.camera.fx = K.at<double>(0, 0), fit.camera.fy = K.at<double>(1, 1);
      fit.camera.cx = K.at<double>(0, 2), fit.camera.cy = K.at<double>(1, 2);
      for (int k = 0; k < 5; ++k) fit.camera.distortion.push_back(D.at<double>(k));
      for (int k = 0; k < 9; ++k) fit.sigmas.push_back(stdIntrinsics.at<double>(k));
      for (std::size_t v = 0; v < rvecs.size(); ++v) {
        fit.rvecs.emplace_back(rvecs[v].at<double>(0), rvecs[v].at<double>(1), rvecs[v].at<double>(2));
        fit.tvecs.emplace_back(tvecs[v].at<double>(0), tvecs[v].at<double>(1), tvecs[v].at<double>(2));
      }
    } else {
      cv::Matx33d K;
      cv::Vec4d D;
      std::vector<cv::Vec3d> rvecs, tvecs;
      std::vector<std::vector<cv::Point3d>> object64;
      std::vector<std::vector<cv::Point2d>> image64;
      for (std::size_t v = 0; v < object.size(); ++v) {
        object64.emplace_back(object[v].begin(), object[v].end());
        image64.emplace_back(image[v].begin(), image[v].end());
      }
      cv::fisheye::calibrate(object64, image64, size, K, D, rvecs, tvecs,
                             cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW, criteria);
      fit.camera.fx = K(0, 0), fit.camera.fy = K(1, 1), fit.camera.cx = K(0, 2), fit.camera.cy = K(1, 2);
      fit.camera.distortion = {D[0], D[1], D[2], D[3]};
      fit.rvecs = rvecs;
      fit.tvecs = tvecs;
    }
  } catch (const cv::Exception& e) {
    throw Error(source, "",
                std::string("the calibration did not converge (OpenCV: ") + e.err +
                    "): the views are probably degenerate or the pattern size is wrong; check --pattern (inner "
                    "corners for a chessboard), show the board tilted by 20-45 degrees in several directions and "
                    "in every part of the image");
  }
  if (!(fit.camera.fx > 0 && fit.camera.fy > 0) || !std::isfinite(fit.camera.fx) || !std::isfinite(fit.camera.cx))
    throw Error(source, "", "the calibration diverged (non-positive focal length): the views are degenerate; show "
                            "the board tilted in several directions and in every part of the image");
  measureViews(fit, object, image);
  if (model == LensModel::Fisheye) fit.sigmas = fisheyeSigmas(fit, object, image);
  return fit;
}

// How much the board's depth varies across a view, relative to its mean depth, from the
// homography of the board plane onto the undistorted image plane: its third row is
// (r13, r23, tz) up to scale whatever the focal length, so this needs no trust in the fitted
// intrinsics. Zero for a board square-on to the camera: then focal length and distance trade
// off exactly and the set is degenerate (Zhang's method needs foreshortened boards).
double depthSpread(const CalibratedCamera& camera, const std::vector<cv::Point3f>& object,
                   const std::vector<cv::Point2f>& image) {
  const std::vector<cv::Point2f> normalised = undistortToPlane(camera, image);
  std::vector<cv::Point2f> plane;
  for (const cv::Point3f& p : object) plane.emplace_back(p.x, p.y);
  const cv::Mat H = cv::findHomography(plane, normalised);
  if (H.empty()) return 0;
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest, sum = 0;
  for (const cv::Point3f& p : object) {
    const double w = H.at<double>(2, 0) * p.x + H.at<double>(2, 1) * p.y + H.at<double>(2, 2);
    lowest = std::min(lowest, w), highest = std::max(highest, w), sum += w;
  }
  const double mean = sum / static_cast<double>(object.size());
  return std::abs(mean) > 0 ? (highest - lowest) / std::abs(mean) : 0;
}

}  // namespace

SE3d poseFromRotationVector(const cv::Vec3d& rvec, const cv::Vec3d& tvec) {
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = R(i, j);
  return SE3d(r, Eigen::Vector3d(tvec[0], tvec[1], tvec[2]));
}

std::vector<cv::Point2f> undistortToPlane(const CalibratedCamera& camera, const std::vector<cv::Point2f>& pixels) {
  const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  std::vector<cv::Point2f> normalised;
  if (camera.model == LensModel::Fisheye)
    cv::fisheye::undistortPoints(pixels, normalised, K, cv::Vec4d(camera.distortion[0], camera.distortion[1],
                                                                  camera.distortion[2], camera.distortion[3]));
  else
    cv::undistortPoints(pixels, normalised, K, camera.distortion);
  return normalised;
}

CalibrationResult calibrate(const std::vector<CalibrationView>& views, const CalibrationPattern& pattern,
                            const CalibrationOptions& options, const std::string& source) {
  CalibrationResult result;
  result.views.resize(views.size());
  // 1. Usable views: the pattern found, sharp, not a near-duplicate of one kept earlier.
  std::vector<std::size_t> kept;
  std::vector<std::array<cv::Point2d, 4>> footprints(views.size());
  std::optional<cv::Size> size;
  std::size_t found = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const CalibrationView& view = views[i];
    ViewOutcome& outcome = result.views[i];
    outcome.name = view.name;
    outcome.edgeWidth = view.edgeWidth;
    if (!view.detection) {
      outcome.rejected = "no pattern";
      continue;
    }
    ++found;
    outcome.corners = static_cast<int>(view.detection->corners.size());
    if (size && *size != view.imageSize)
      throw Error(source, "", "image " + view.name + " is " + std::to_string(view.imageSize.width) + "x" +
                                  std::to_string(view.imageSize.height) + " but earlier ones are " +
                                  std::to_string(size->width) + "x" + std::to_string(size->height) +
                                  ": calibrate one camera at one resolution at a time");
    size = view.imageSize;
    if (view.edgeWidth > options.maxEdgeWidth) {
      outcome.rejected = "blurred";
      continue;
    }
    footprints[i] = footprint(*view.detection, pattern);
    const double diagonal = std::hypot(view.imageSize.width, view.imageSize.height);
    const auto same = std::find_if(kept.begin(), kept.end(), [&](std::size_t k) {
      return meanDistance(footprints[k], footprints[i]) < options.duplicateFraction * diagonal;
    });
    if (same != kept.end()) {
      outcome.rejected = "duplicate of " + views[*same].name;
      continue;
    }
    kept.push_back(i);
  }
  if (found == 0)
    throw Error(source, "", "no image shows the pattern " + pattern.describe() +
                                ": check the pattern's size (a chessboard counts inner corners, e.g. 9x6 for 10x7 "
                                "squares) and that the whole board is in view, lit evenly and in focus");
  const auto tooFew = [&](std::size_t usable, const std::string& why) {
    return Error(source, "", std::to_string(usable) + " usable view" + (usable == 1 ? "" : "s") + " (" +
                                 std::to_string(found) + " of " + std::to_string(views.size()) +
                                 " images show the pattern" + why + "); at least " +
                                 std::to_string(options.minViews) +
                                 " are needed: take more views, the board tilted by 20-45 degrees in several "
                                 "directions and covering every part of the image, corners included");
  };
  if (static_cast<int>(kept.size()) < options.minViews) {
    const auto count = [&](const std::string& prefix) {
      return std::count_if(result.views.begin(), result.views.end(),
                           [&](const ViewOutcome& o) { return o.rejected.rfind(prefix, 0) == 0; });
    };
    throw tooFew(kept.size(), ", " + std::to_string(count("blurred")) + " blurred, " +
                                  std::to_string(count("duplicate")) + " duplicates");
  }
  // 2. Past maxViews, a spread: farthest-point sampling from the view with the most corners.
  std::vector<std::size_t> selected;
  if (static_cast<int>(kept.size()) <= options.maxViews) {
    selected = kept;
  } else {
    std::vector<Eigen::Matrix<double, 7, 1>> descriptors;
    for (std::size_t k : kept) descriptors.push_back(poseDescriptor(footprints[k], *size));
    std::vector<double> nearest(kept.size(), std::numeric_limits<double>::infinity());
    std::size_t next = static_cast<std::size_t>(
        std::max_element(kept.begin(), kept.end(),
                         [&](std::size_t a, std::size_t b) { return result.views[a].corners < result.views[b].corners; }) -
        kept.begin());
    std::vector<bool> taken(kept.size(), false);
    for (int n = 0; n < options.maxViews; ++n) {
      taken[next] = true;
      selected.push_back(kept[next]);
      for (std::size_t j = 0; j < kept.size(); ++j)
        nearest[j] = std::min(nearest[j], (descriptors[j] - descriptors[next]).norm());
      double farthest = -1;
      for (std::size_t j = 0; j < kept.size(); ++j)
        if (!taken[j] && nearest[j] > farthest) farthest = nearest[j], next = j;
    }
    std::sort(selected.begin(), selected.end());
    for (std::size_t k : kept)
      if (!std::binary_search(selected.begin(), selected.end(), k)) result.views[k].rejected = "not selected (similar to a chosen view)";
  }
  // 3. Fit; name the outliers and fit again without them.
  const auto gather = [&](const std::vector<std::size_t>& chosen, std::vector<std::vector<cv::Point3f>>& object,
                          std::vector<std::vector<cv::Point2f>>& image) {
    object.clear();
    image.clear();
    for (std::size_t i : chosen) {
      object.push_back(objectPoints(*views[i].detection, pattern));
      image.push_back(views[i].detection->corners);
    }
  };
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  gather(selected, object, image);
  Fit fit = fitModel(options.model, object, image, *size, source);
  std::vector<double> sorted = fit.viewRms;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double limit = std::max(options.outlierFactor * sorted[sorted.size() / 2], 0.5);
  std::vector<std::size_t> inliers;
  for (std::size_t k = 0; k < selected.size(); ++k) {
    if (fit.viewRms[k] > limit) {
      ViewOutcome& o = result.views[selected[k]];
      o.outlier = true;
      o.rms = fit.viewRms[k];
      o.rejected = "outlier";
    } else {
      inliers.push_back(selected[k]);
    }
  }
  if (inliers.size() != selected.size()) {
    if (static_cast<int>(inliers.size()) < options.minViews) throw tooFew(inliers.size(), " but the rest are outliers");
    gather(inliers, object, image);
    fit = fitModel(options.model, object, image, *size, source);
    selected = inliers;
  }
  // 4. A set that does not pin the focal length or principal point down is degenerate: the board
  // square-on in every view (focal length and distance trade off; OpenCV's σ need not show it,
  // docs/notes/2026-11-26-fisheye.md), all boards parallel (Zhang's method needs planes in
  // different orientations), or the uncertainty says so.
  double widestSpread = 0;
  for (std::size_t v = 0; v < object.size(); ++v)
    widestSpread = std::max(widestSpread, depthSpread(fit.camera, object[v], image[v]));
  if (widestSpread < options.minDepthSpread) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "the views do not determine the camera (a degenerate set): the board is square-on to the camera "
                  "in every view (its near and far corners differ in distance by at most %.1f%%), so the focal "
                  "length cannot be told from the distance. Tilt the board by 20-45 degrees in several directions "
                  "(left, right, up, down), at several distances and in every part of the image",
                  100 * widestSpread);
    throw Error(source, "", text);
  }
  double widestTurn = 0;
  for (std::size_t a = 0; a < fit.rvecs.size(); ++a)
    for (std::size_t b = a + 1; b < fit.rvecs.size(); ++b) {
      const Eigen::Vector3d na = poseFromRotationVector(fit.rvecs[a], fit.tvecs[a]).rotationMatrix().col(2);
      const Eigen::Vector3d nb = poseFromRotationVector(fit.rvecs[b], fit.tvecs[b]).rotationMatrix().col(2);
      widestTurn = std::max(widestTurn, std::acos(std::clamp(na.dot(nb), -1.0, 1.0)));
    }
  if (widestTurn < options.minTiltDegrees * M_PI / 180.0) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "the views do not determine the camera (a degenerate set): the board's orientation varies by "
                  "%.1f degrees over all views. Show it tilted by 20-45 degrees about both axes, at several "
                  "distances and in every part of the image",
                  widestTurn * 180.0 / M_PI);
    throw Error(source, "", text);
  }
  const double width = static_cast<double>(size->width);
  if (fit.sigmas[0] > options.maxRelativeFocalSigma * fit.camera.fx ||
      fit.sigmas[1] > options.maxRelativeFocalSigma * fit.camera.fy ||
      fit.sigmas[2] > options.maxPrincipalPointSigma * width || fit.sigmas[3] > options.maxPrincipalPointSigma * width ||
      !std::isfinite(fit.sigmas[0]) || !std::isfinite(fit.sigmas[2])) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "the views do not determine the camera (a degenerate set): fx = %.1f +- %.1f, cx = %.1f +- %.1f "
                  "pixels. Show the board tilted by 20-45 degrees about both axes, at several distances and in "
                  "every part of the image",
                  fit.camera.fx, fit.sigmas[0], fit.camera.cx, fit.sigmas[2]);
    throw Error(source, "", text);
  }

  result.camera = fit.camera;
  result.parameterNames = {"fx", "fy", "cx", "cy"};
  for (const char* name : options.model == LensModel::Pinhole ? std::vector<const char*>{"k1", "k2", "p1", "p2", "k3"}
                                                             : std::vector<const char*>{"k1", "k2", "k3", "k4"})
    result.parameterNames.push_back(name);
  result.parameters = {fit.camera.fx, fit.camera.fy, fit.camera.cx, fit.camera.cy};
  result.parameters.insert(result.parameters.end(), fit.camera.distortion.begin(), fit.camera.distortion.end());
  result.standardDeviations = fit.sigmas;
  result.rms = fit.rms;
  result.viewsUsed = static_cast<int>(selected.size());
  for (std::size_t k = 0; k < selected.size(); ++k) {
    ViewOutcome& o = result.views[selected[k]];
    o.used = true;
    o.rms = fit.viewRms[k];
    result.cameraFromBoard.push_back(poseFromRotationVector(fit.rvecs[k], fit.tvecs[k]));
    result.usedNames.push_back(views[selected[k]].name);
    result.usedCorners.push_back(views[selected[k]].detection->corners);
  }
  for (const ViewOutcome& o : result.views)
    if (o.outlier) result.warnings.push_back("view " + o.name + " is an outlier (" + std::to_string(o.rms) + " px RMS) and was left out");
  return result;
}

}  // namespace orbis::calibration
