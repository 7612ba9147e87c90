// The KITTI readers' shared part; see kitti_common.hpp.
#include "kitti_common.hpp"

#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "orbis/util/error.hpp"

namespace orbis::adapters_detail {

namespace fs = std::filesystem;

std::vector<double> readCalibrationRow(const fs::path& file, const std::string& key, std::size_t count) {
  std::vector<double> values;
  bool found = false;
  forEachTextRow(file, [&](const TextRow& row) {
    if (found || row.fields.front() != key + ":") return;
    if (row.fields.size() != count + 1)
      throw lineError(file.string(), row.line,
                      "expected " + key + ": followed by " + std::to_string(count) + " numbers, found " +
                          std::to_string(row.fields.size() - 1));
    for (std::size_t i = 0; i < count; ++i) values.push_back(parseDouble(row.fields[i + 1], file, row.line));
    found = true;
  });
  if (!found) throw keyError(file.string(), key, "missing");
  return values;
}

void KittiImagesReader::openImages(const fs::path& root, Images images, const DatasetOptions& options) {
  root_ = root;
  images_ = std::move(images);
  const bool hasRight = fs::is_directory(images_.rightDir);
  sensor_ = options.sensor.value_or(hasRight ? SensorKind::Stereo : SensorKind::Monocular);
  if (sensor_ == SensorKind::Rgbd) throw Error(root.string(), "", "KITTI has no depth maps (use stereo or mono)");
  if (sensor_ == SensorKind::Stereo && !hasRight)
    throw fileError(images_.rightDir.string(), "does not exist (stereo needs the right images)");
  if (images_.times.empty()) throw fileError(images_.timesFile.string(), "lists no frame");
  for (std::size_t i = 0; i < images_.times.size(); ++i) {
    if (!options.tolerateBadFrames && !fs::exists(imagePath(0, i)))
      throw lineError(images_.timesFile.string(), i + 1, "image " + imagePath(0, i).string() + " does not exist");
    if (sensor_ == SensorKind::Stereo && options.strict && !fs::exists(imagePath(1, i)))
      throw lineError(images_.timesFile.string(), i + 1,
                      "right image " + imagePath(1, i).string() + " does not exist");
  }
  const cv::Mat first = loadImage(imagePath(0, 0), cv::IMREAD_UNCHANGED, images_.timesFile, 1);
  pinhole_.width = first.cols;
  pinhole_.height = first.rows;
}

void KittiImagesReader::setCamera(const std::vector<double>& left, const std::vector<double>& right,
                                  const fs::path& calibFile, const std::string& rightKey) {
  pinhole_.fx = left[0];
  pinhole_.cx = left[2];
  pinhole_.fy = left[5];
  pinhole_.cy = left[6];
  if (!(pinhole_.fx > 0 && pinhole_.fy > 0)) throw fileError(calibFile.string(), "gives a non-positive focal length");
  if (sensor_ != SensorKind::Stereo) return;
  baseline_ = (left[3] - right[3]) / right[0];  // P = K [I | t]: P(0,3) = -fx b for a camera b to the right
  if (!(baseline_ > 0)) throw keyError(calibFile.string(), rightKey, "gives a non-positive baseline");
}

DatasetCamera KittiImagesReader::camera() const {
  if (sensor_ == SensorKind::Monocular) return pinhole_;
  return RectifiedStereoCamera<double>(pinhole_, baseline_);
}

DatasetFrame KittiImagesReader::frame(std::size_t index) const {
  DatasetFrame frame;
  frame.index = index;
  frame.timestamp = images_.times.at(index);
  frame.left = loadImage(imagePath(0, index), cv::IMREAD_UNCHANGED, images_.timesFile, index + 1);
  if (sensor_ == SensorKind::Stereo) {
    const fs::path right = imagePath(1, index);
    if (fs::exists(right))
      frame.right = loadImage(right, cv::IMREAD_UNCHANGED, images_.timesFile, index + 1);
    else
      reportMissing(frame.warnings, false, images_.timesFile, index + 1,
                    "right image " + right.string() + " does not exist");
  }
  return frame;
}

fs::path KittiImagesReader::imagePath(int camera, std::size_t index) const {
  char name[32];
  std::snprintf(name, sizeof name, "%0*zu.png", images_.digits, index);
  return (camera == 0 ? images_.leftDir : images_.rightDir) / name;
}

}  // namespace orbis::adapters_detail
