// KITTI odometry reader: sequences/NN/{image_0, image_1 (optional), times.txt, calib.txt} and
// poses/NN.txt (optional: sequences 11-21 have no public ground truth).
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "dataset_common.hpp"
#include "orbis/util/error.hpp"

namespace orbis {
namespace {

using namespace adapters_detail;
namespace fs = std::filesystem;

struct KittiLayout {
  fs::path sequenceDir;  // holds times.txt, calib.txt, image_0
  fs::path posesFile;    // may not exist
};

// root may be the dataset root (with sequences/ and poses/) or a sequence folder itself.
KittiLayout locate(const fs::path& root, const std::string& sequence) {
  if (fs::exists(root / "times.txt")) {
    fs::path dir = fs::absolute(root).lexically_normal();
    if (dir.filename().empty()) dir = dir.parent_path();  // a trailing slash
    return {root, dir.parent_path().parent_path() / "poses" / (dir.filename().string() + ".txt")};
  }
  const fs::path sequences = root / "sequences";
  requireExists(sequences, "the KITTI sequences folder");
  std::string chosen = sequence;
  if (chosen.empty()) {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(sequences))
      if (entry.is_directory()) found.push_back(entry.path().filename().string());
    if (found.size() != 1)
      throw fileError(sequences.string(), "holds " + std::to_string(found.size()) +
                                              " sequences; name one (DatasetOptions::kittiSequence)");
    chosen = found.front();
  }
  return {sequences / chosen, root / "poses" / (chosen + ".txt")};
}

// calib.txt rows "P0: p00 ... p23"; returns the 3x4 projection named key.
Eigen::Matrix<double, 3, 4> readProjection(const fs::path& calibFile, const std::string& key) {
  Eigen::Matrix<double, 3, 4> projection;
  bool found = false;
  forEachTextRow(calibFile, [&](const TextRow& row) {
    if (row.fields.front() != key + ":") return;
    if (row.fields.size() != 13)
      throw lineError(
          calibFile.string(), row.line,
          "expected " + key + ": followed by 12 numbers, found " + std::to_string(row.fields.size() - 1));
    for (int i = 0; i < 12; ++i)
      projection(i / 4, i % 4) = parseDouble(row.fields[i + 1], calibFile, row.line);
    found = true;
  });
  if (!found) throw keyError(calibFile.string(), key, "missing");
  return projection;
}

class KittiReader final : public DatasetReader {
 public:
  KittiReader(const fs::path& root, const DatasetOptions& options) : root_(root), options_(options) {
    const KittiLayout layout = locate(root, options.kittiSequence);
    sequenceDir_ = layout.sequenceDir;
    const fs::path timesFile = sequenceDir_ / "times.txt";
    requireExists(timesFile, "the KITTI times file");
    timesFile_ = timesFile;
    times_ = readTimestamps(timesFile);
    const bool hasRight = fs::is_directory(sequenceDir_ / "image_1");
    sensor_ = options.sensor.value_or(hasRight ? SensorKind::Stereo : SensorKind::Monocular);
    if (sensor_ == SensorKind::Rgbd)
      throw Error(root.string(), "", "KITTI has no depth maps (use stereo or mono)");
    if (sensor_ == SensorKind::Stereo && !hasRight)
      throw fileError((sequenceDir_ / "image_1").string(), "does not exist (stereo needs the right images)");

    for (std::size_t i = 0; i < times_.size(); ++i) {
      if (!options.tolerateBadFrames && !fs::exists(imagePath(0, i)))
        throw lineError(timesFile.string(), i + 1, "image " + imagePath(0, i).string() + " does not exist");
      if (sensor_ == SensorKind::Stereo && options.strict && !fs::exists(imagePath(1, i)))
        throw lineError(timesFile.string(), i + 1,
                        "right image " + imagePath(1, i).string() + " does not exist");
    }

    const fs::path calibFile = sequenceDir_ / "calib.txt";
    requireExists(calibFile, "the KITTI calibration");
    const Eigen::Matrix<double, 3, 4> p0 = readProjection(calibFile, "P0");
    pinhole_.fx = p0(0, 0);
    pinhole_.fy = p0(1, 1);
    pinhole_.cx = p0(0, 2);
    pinhole_.cy = p0(1, 2);
    const cv::Mat first = loadImage(imagePath(0, 0), cv::IMREAD_UNCHANGED, timesFile, 1);
    pinhole_.width = first.cols;
    pinhole_.height = first.rows;
    if (sensor_ == SensorKind::Stereo) {
      const Eigen::Matrix<double, 3, 4> p1 = readProjection(calibFile, "P1");
      baseline_ = -p1(0, 3) / p1(0, 0);  // P1 = K [I | -b e_x]
      if (!(baseline_ > 0)) throw keyError(calibFile.string(), "P1", "gives a non-positive baseline");
    }

    if (fs::exists(layout.posesFile)) {
      groundTruth_ = readTrajectory(layout.posesFile, TrajectoryFormat::Kitti, timesFile);
    }
  }

  DatasetKind kind() const override { return DatasetKind::Kitti; }
  SensorKind sensor() const override { return sensor_; }
  std::size_t size() const override { return times_.size(); }
  double timestamp(std::size_t index) const override { return times_.at(index); }
  const Trajectory& groundTruth() const override { return groundTruth_; }
  const fs::path& root() const override { return root_; }

  DatasetCamera camera() const override {
    if (sensor_ == SensorKind::Monocular) return pinhole_;
    return RectifiedStereoCamera<double>(pinhole_, baseline_);
  }

  DatasetFrame frame(std::size_t index) const override {
    DatasetFrame frame;
    frame.index = index;
    frame.timestamp = times_.at(index);
    frame.left = loadImage(imagePath(0, index), cv::IMREAD_UNCHANGED, timesFile_, index + 1);
    if (sensor_ == SensorKind::Stereo) {
      const fs::path right = imagePath(1, index);
      if (fs::exists(right))
        frame.right = loadImage(right, cv::IMREAD_UNCHANGED, timesFile_, index + 1);
      else
        reportMissing(frame.warnings, false, timesFile_, index + 1,
                      "right image " + right.string() + " does not exist");
    }
    return frame;
  }

 private:
  fs::path imagePath(int camera, std::size_t index) const {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.png", index);
    return sequenceDir_ / ("image_" + std::to_string(camera)) / name;
  }

  fs::path root_, sequenceDir_, timesFile_;
  DatasetOptions options_;
  SensorKind sensor_ = SensorKind::Stereo;
  std::vector<double> times_;
  PinholeCamera<double> pinhole_;
  double baseline_ = 0.0;
  Trajectory groundTruth_;
};

}  // namespace

std::unique_ptr<DatasetReader> openKitti(const std::filesystem::path& root, const DatasetOptions& options) {
  return std::make_unique<KittiReader>(root, options);
}

}  // namespace orbis
