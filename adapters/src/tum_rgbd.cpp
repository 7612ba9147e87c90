// TUM RGB-D benchmark reader: rgb.txt + depth.txt associated by nearest timestamp, 16-bit depth
// PNGs scaled to metres, groundtruth.txt (optional: the benchmark's test sequences have none).
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <regex>

#include "dataset_common.hpp"
#include "orbis/util/error.hpp"

namespace orbis {
namespace {

using namespace adapters_detail;
namespace fs = std::filesystem;

// The benchmark publishes one calibration per Kinect (freiburg1/2/3); the images of freiburg3
// are already undistorted, the others are not (their settings carry the distortion).
std::optional<PinholeCamera<double>> tumCamera(int freiburg) {
  PinholeCamera<double> c;
  c.width = 640;
  c.height = 480;
  switch (freiburg) {
    case 1:
      c.fx = 517.306408;
      c.fy = 516.469215;
      c.cx = 318.643040;
      c.cy = 255.313989;
      return c;
    case 2:
      c.fx = 520.908620;
      c.fy = 521.007327;
      c.cx = 325.141442;
      c.cy = 249.701764;
      return c;
    case 3:
      c.fx = 535.4;
      c.fy = 539.2;
      c.cx = 320.1;
      c.cy = 247.6;
      return c;
    default:
      return std::nullopt;
  }
}

// Which Kinect: from the list's "# file: 'rgbd_dataset_freiburg3_teddy.bag'" header, else
// from the folder name (freiburgN or frN).
int detectFreiburg(const fs::path& rgbList, const fs::path& root) {
  const std::regex pattern(R"((?:freiburg|fr)([123]))");
  std::smatch match;
  std::ifstream in(rgbList);
  std::string line;
  for (int i = 0; i < 5 && std::getline(in, line); ++i)
    if (!line.empty() && line[0] == '#' && std::regex_search(line, match, pattern))
      return match[1].str()[0] - '0';
  const std::string name = fs::absolute(root).lexically_normal().filename().string();
  const std::string parent = fs::absolute(root).lexically_normal().parent_path().filename().string();
  for (const std::string& s : {name, parent})
    if (std::regex_search(s, match, pattern)) return match[1].str()[0] - '0';
  return 0;
}

class TumRgbdReader final : public DatasetReader {
 public:
  TumRgbdReader(const fs::path& root, const DatasetOptions& options)
      : root_(root), options_(options), sensor_(options.sensor.value_or(SensorKind::Rgbd)) {
    if (sensor_ == SensorKind::Stereo)
      throw Error(root.string(), "", "a TUM RGB-D sequence has no stereo pair (use rgbd or mono)");
    const fs::path rgbList = root / "rgb.txt";
    requireExists(rgbList, "the TUM image list");
    rgb_ = readImageList(rgbList, root, TimeUnit::Seconds, !options.tolerateBadFrames, warnings_);
    if (sensor_ == SensorKind::Rgbd) {
      const fs::path depthList = root / "depth.txt";
      if (!fs::exists(depthList)) throw noDepth("there is no depth.txt");
      depth_ = PairedImages(rgb_,
                            readImageList(depthList, root, TimeUnit::Seconds, false, warnings_),
                            options.maxDepthDt, "depth map");
      if (options.strict) depth_.requireAll(rgb_);
      if (!rgb_.empty() && depth_.pairedOnDisk() == 0) {
        throw noDepth(depth_.listed() == 0 ? "depth.txt lists no depth map"
                                           : "none of the " + std::to_string(depth_.listed()) +
                                                 " depth maps depth.txt lists is on disk within " +
                                                 std::to_string(options.maxDepthDt) + " s of a colour image");
      }
    }
    const fs::path gtFile = root / "groundtruth.txt";
    if (fs::exists(gtFile)) groundTruth_ = readTrajectory(gtFile, TrajectoryFormat::Tum, {}, &warnings_);
    freiburg_ = detectFreiburg(rgbList, root);
  }

  // A colour-only folder, refused at once rather than skipped frame by frame.
  Error noDepth(const std::string& why) const {
    return Error(root_.string(), "",
                 "no depth maps for the colour images (" + why +
                     "), so it cannot run as RGB-D; run it as monocular: --sensor mono");
  }

  DatasetKind kind() const override { return DatasetKind::TumRgbd; }
  SensorKind sensor() const override { return sensor_; }
  std::size_t size() const override { return rgb_.size(); }
  double timestamp(std::size_t index) const override { return rgb_.at(index).t; }
  const Trajectory& groundTruth() const override { return groundTruth_; }
  const fs::path& root() const override { return root_; }

  DatasetCamera camera() const override {
    const auto pinhole = tumCamera(freiburg_);
    if (!pinhole)
      throw Error(root_.string(), "",
                  "cannot tell which TUM Kinect (freiburg1/2/3) recorded this "
                  "sequence; give the calibration in a settings file");
    if (sensor_ == SensorKind::Monocular) return *pinhole;
    // Frames carry the raw 16-bit depth; the camera says how it becomes metres.
    const double baseline = options_.tumVirtualBaseline.value_or(options_.tumBf / pinhole->fx);
    const double depthScale = options_.tumDepthScale.value_or(freiburg_ == 2 ? 5208.0 : 5000.0);
    return RgbdCamera<double>(*pinhole, baseline, depthScale);
  }

  RadTanDistortion<double> distortion() const override {
    if (freiburg_ == 1) return {0.262383, -0.953104, -0.005358, 0.002628, 1.163314};
    if (freiburg_ == 2) return {0.231222, -0.784899, -0.003257, -0.000105, 0.917205};
    return {};
  }

  DatasetFrame frame(std::size_t index) const override {
    const ListedImage& colour = rgb_.at(index);
    DatasetFrame frame;
    frame.index = index;
    frame.timestamp = colour.t;
    frame.left = loadImage(colour, cv::IMREAD_UNCHANGED);
    const ListedImage* depth =
        sensor_ == SensorKind::Rgbd ? depth_.find(rgb_, index, frame.warnings, false) : nullptr;
    if (depth) {
      frame.depth = loadImage(*depth, cv::IMREAD_UNCHANGED);
      if (frame.depth.type() != CV_16UC1)
        throw lineError(depth->listFile.string(), depth->line,
                        "depth image " + depth->file.string() + " is not 16-bit single-channel");
    }
    return frame;
  }

 private:
  fs::path root_;
  DatasetOptions options_;
  SensorKind sensor_;
  std::vector<ListedImage> rgb_;
  PairedImages depth_;
  Trajectory groundTruth_;
  int freiburg_ = 0;
};

}  // namespace

std::unique_ptr<DatasetReader> openTumRgbd(const std::filesystem::path& root, const DatasetOptions& options) {
  return std::make_unique<TumRgbdReader>(root, options);
}

}  // namespace orbis
