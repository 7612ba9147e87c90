// KITTI raw drive reader: a synced and rectified drive (2011_09_26_drive_0001_sync) with
// image_00/data and image_01/data (grey, rectified, 10-digit names) and their timestamps.txt;
// the date folder's calib_cam_to_cam.txt (P_rect_00, P_rect_01, R_rect_00); and, when there,
// oxts/ (GPS/IMU) turned into rectified left-camera poses through calib_imu_to_velo.txt and
// calib_velo_to_cam.txt, as the KITTI devkit's convertOxtsToPose does.
#include <cmath>
#include <cstdio>

#include "kitti_common.hpp"
#include "orbis/util/error.hpp"

namespace orbis {
namespace {

using namespace adapters_detail;
namespace fs = std::filesystem;

// Days from 1970-01-01 to a proleptic Gregorian date (H. Hinnant's days_from_civil): no time
// zone and no locale, unlike timegm/strptime.
long long daysFromCivil(long long y, unsigned m, unsigned d) {
  y -= m <= 2;
  const long long era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yearOfEra = static_cast<unsigned>(y - era * 400);
  const unsigned dayOfYear = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned dayOfEra = yearOfEra * 365 + yearOfEra / 4 - yearOfEra / 100 + dayOfYear;
  return era * 146097 + static_cast<long long>(dayOfEra) - 719468;
}

// "2011-09-26 13:02:25.964389445" (UTC, as the drives' timestamps.txt) to seconds since 1970.
double parseDateTime(const TextRow& row, const fs::path& file) {
  if (row.fields.size() != 2) throw lineError(file.string(), row.line, "expected 'YYYY-MM-DD hh:mm:ss.fraction'");
  const std::string date(row.fields[0]), time(row.fields[1]);
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, consumedDate = 0, consumedTime = 0;
  const bool shaped = std::sscanf(date.c_str(), "%4d-%2d-%2d%n", &year, &month, &day, &consumedDate) == 3 &&
                      consumedDate == static_cast<int>(date.size()) &&
                      std::sscanf(time.c_str(), "%2d:%2d:%n", &hour, &minute, &consumedTime) == 2;
  if (!shaped || month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || hour < 0 ||
      minute < 0)
    throw lineError(file.string(), row.line, "expected 'YYYY-MM-DD hh:mm:ss.fraction', found '" + date + " " + time + "'");
  const double seconds = parseDouble(std::string_view(time).substr(static_cast<std::size_t>(consumedTime)), file, row.line);
  if (!(seconds >= 0 && seconds < 61)) throw lineError(file.string(), row.line, "seconds out of range");
  return static_cast<double>(daysFromCivil(year, static_cast<unsigned>(month), static_cast<unsigned>(day))) * 86400.0 +
         hour * 3600.0 + minute * 60.0 + seconds;
}

std::vector<double> readDateTimes(const fs::path& file, bool strictlyIncreasing) {
  std::vector<double> times;
  forEachTextRow(file, [&](const TextRow& row) {
    const double t = parseDateTime(row, file);
    if (strictlyIncreasing && !times.empty() && !(t > times.back()))
      throw lineError(file.string(), row.line, "timestamp is not after the previous row's");
    times.push_back(t);
  });
  return times;
}

// The transform of rows "R: 9 numbers" (a rotation, row-major) and "T: 3 numbers" of a KITTI
// calibration file; with no translation key, a pure rotation.
Eigen::Isometry3d readRigid(const fs::path& file, const std::string& rotationKey, const std::string& translationKey) {
  const std::vector<double> r = readCalibrationRow(file, rotationKey, 9);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 9; ++i) t.linear()(i / 3, i % 3) = r[static_cast<std::size_t>(i)];
  if (!(t.linear().transpose() * t.linear()).isApprox(Eigen::Matrix3d::Identity(), 1e-4) || t.linear().determinant() < 0)
    throw keyError(file.string(), rotationKey, "is not a rotation matrix");
  if (!translationKey.empty()) {
    const std::vector<double> v = readCalibrationRow(file, translationKey, 3);
    t.translation() << v[0], v[1], v[2];
  }
  return t;
}

// x_rect0 = T x_imu: the rectified left camera from the OXTS unit.
Eigen::Isometry3d rectifiedCameraFromImu(const fs::path& calibDir) {
  const fs::path imuToVelo = calibDir / "calib_imu_to_velo.txt", veloToCam = calibDir / "calib_velo_to_cam.txt";
  return readRigid(calibDir / "calib_cam_to_cam.txt", "R_rect_00", "") * readRigid(veloToCam, "R", "T") *
         readRigid(imuToVelo, "R", "T");
}

// One OXTS packet (lat, lon, alt, roll, pitch, yaw, ...) as a pose in a Mercator frame scaled at
// the first packet's latitude (KITTI devkit: convertOxtsToPose).
Eigen::Isometry3d oxtsPose(const fs::path& file, double& mercatorScale, bool first) {
  std::vector<double> v;
  forEachTextRow(file, [&](const TextRow& row) {
    if (!v.empty()) return;
    if (row.fields.size() < 6)
      throw lineError(file.string(), row.line, "expected an OXTS packet (lat lon alt roll pitch yaw ...)");
    for (std::size_t i = 0; i < 6; ++i) v.push_back(parseDouble(row.fields[i], file, row.line));
  });
  if (v.empty()) throw fileError(file.string(), "empty, expected an OXTS packet");
  if (!(std::abs(v[0]) < 85 && std::abs(v[1]) <= 180)) throw fileError(file.string(), "latitude or longitude out of range");
  constexpr double kEarthRadius = 6378137.0, kDegree = M_PI / 180.0;
  if (first) mercatorScale = std::cos(v[0] * kDegree);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << mercatorScale * v[1] * kDegree * kEarthRadius,
      mercatorScale * kEarthRadius * std::log(std::tan((90.0 + v[0]) * kDegree / 2.0)), v[2];
  pose.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  return pose;
}

// Rectified left-camera poses, camera-to-world with the first camera as the world.
Trajectory oxtsGroundTruth(const fs::path& oxtsDir, const Eigen::Isometry3d& cameraFromImu,
                           std::vector<std::string>& warnings) {
  const fs::path timesFile = oxtsDir / "timestamps.txt";
  const std::vector<double> times = readDateTimes(timesFile, false);
  Trajectory trajectory;
  std::vector<std::size_t> lines;
  double mercatorScale = 1.0;
  Eigen::Isometry3d firstCameraInverse = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < times.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%010zu.txt", i);
    const Eigen::Isometry3d worldFromCamera = oxtsPose(oxtsDir / "data" / name, mercatorScale, i == 0) * cameraFromImu.inverse();
    if (i == 0) firstCameraInverse = worldFromCamera.inverse();
    const Eigen::Isometry3d pose = firstCameraInverse * worldFromCamera;
    trajectory.push_back({times[i], SE3d(SO3d(pose.linear()), pose.translation())});
    lines.push_back(i + 1);
  }
  // The OXTS clock is its own: put its rows in time order like any other ground truth.
  const TimeOrder order = putInTimeOrder(times, lines);
  for (std::string& w : order.warnings(timesFile)) warnings.push_back(std::move(w));
  Trajectory ordered;
  for (const std::size_t i : order.keep) ordered.push_back(trajectory[i]);
  return ordered;
}

// The calibration lies beside the drive folders (in the date folder), or in the drive itself.
fs::path calibrationFolder(const fs::path& drive) {
  if (fs::exists(drive / "calib_cam_to_cam.txt")) return drive;
  fs::path dir = fs::absolute(drive).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // a trailing slash
  return dir.parent_path();
}

class KittiRawReader final : public KittiImagesReader {
 public:
  KittiRawReader(const fs::path& root, const DatasetOptions& options) {
    const fs::path leftTimes = root / "image_00" / "timestamps.txt";
    requireExists(leftTimes, "the KITTI raw left-camera timestamps (image_00/timestamps.txt)");
    openImages(root, {leftTimes, readDateTimes(leftTimes, true), root / "image_00" / "data", root / "image_01" / "data", 10},
               options);
    const fs::path calibDir = calibrationFolder(root);
    const fs::path camToCam = calibDir / "calib_cam_to_cam.txt";
    requireExists(camToCam, "the KITTI raw calibration calib_cam_to_cam.txt (beside the drive folder)");
    const std::vector<double> left = readCalibrationRow(camToCam, "P_rect_00", 12);  // first: errors in file order
    setCamera(left,
              sensor_ == SensorKind::Stereo ? readCalibrationRow(camToCam, "P_rect_01", 12) : std::vector<double>{},
              camToCam, "P_rect_01");
    if (fs::exists(root / "oxts" / "timestamps.txt")) {
      if (!fs::exists(calibDir / "calib_imu_to_velo.txt") || !fs::exists(calibDir / "calib_velo_to_cam.txt")) {
        warnings_.push_back(calibDir.string() +
                            ": calib_imu_to_velo.txt or calib_velo_to_cam.txt missing: no ground truth from oxts/");
        return;
      }
      groundTruth_ = oxtsGroundTruth(root / "oxts", rectifiedCameraFromImu(calibDir), warnings_);
    }
  }

  DatasetKind kind() const override { return DatasetKind::KittiRaw; }
};

}  // namespace

std::unique_ptr<DatasetReader> openKittiRaw(const std::filesystem::path& root, const DatasetOptions& options) {
  return std::make_unique<KittiRawReader>(root, options);
}

}  // namespace orbis
