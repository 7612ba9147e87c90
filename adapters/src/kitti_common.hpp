// Private: what the two KITTI readers share (odometry sequences, raw drives): numbered left and
// right images, one per row of a times file, read as stereo or monocular; calibration rows
// "KEY: numbers...".
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "dataset_common.hpp"

namespace orbis::adapters_detail {

// The numbers of the row "key: v1 v2 ..." of a KITTI calibration file (other rows, such as
// calib_time, are not looked at). Throws orbis::Error naming the file and key when the row is
// missing, or the line when it does not hold exactly `count` numbers.
std::vector<double> readCalibrationRow(const std::filesystem::path& file, const std::string& key, std::size_t count);

class KittiImagesReader : public DatasetReader {
 public:
  SensorKind sensor() const override { return sensor_; }
  std::size_t size() const override { return images_.times.size(); }
  double timestamp(std::size_t index) const override { return images_.times.at(index); }
  const Trajectory& groundTruth() const override { return groundTruth_; }
  const std::filesystem::path& root() const override { return root_; }
  DatasetCamera camera() const override;
  DatasetFrame frame(std::size_t index) const override;

 protected:
  struct Images {
    std::filesystem::path timesFile;        // named in errors: row i is frame i
    std::vector<double> times;
    std::filesystem::path leftDir, rightDir;
    int digits = 6;                         // frame i is leftDir / "%0<digits>zu.png"
  };
  // Chooses the sensor (stereo when the right folder exists), checks the images are there (as
  // options ask) and takes the image size from the first left image.
  void openImages(const std::filesystem::path& root, Images images, const DatasetOptions& options);
  // fx, fy, cx, cy from a 3x4 projection (row-major); the baseline from the right one's P(0,3).
  void setCamera(const std::vector<double>& leftProjection, const std::vector<double>& rightProjection,
                 const std::filesystem::path& calibFile, const std::string& rightKey);
  std::filesystem::path imagePath(int camera, std::size_t index) const;

  std::filesystem::path root_;
  Images images_;
  SensorKind sensor_ = SensorKind::Stereo;
  PinholeCamera<double> pinhole_;
  double baseline_ = 0.0;
  Trajectory groundTruth_;
};

}  // namespace orbis::adapters_detail
