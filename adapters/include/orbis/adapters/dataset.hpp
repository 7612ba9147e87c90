// orbis/adapters/dataset.hpp — benchmark sequences (TUM RGB-D, EuRoC MAV, KITTI odometry)
// read frame by frame, in their own on-disk layouts.
//
// Contract: openDataset reads only the small text files (lists, timestamps, calibration,
// ground truth) and checks them; images are loaded when a frame is asked for, so a whole
// sequence is never held in memory. Frames come in time order; frame(i) may be called in any
// order. A missing file, an unreadable image or a malformed line throws orbis::Error naming
// the file (and the line, for text files). Lists and ground truth whose rows are out of time
// order are sorted, and of rows with equal timestamps the first is kept, each kind of repair
// one entry in DatasetReader::warnings() with its count. A missing right image or
// depth map is reported on the frame (DatasetFrame::warnings) or, with DatasetOptions::strict,
// thrown; it is never skipped silently. Ground truth is given as camera-to-world poses of the
// left (or colour) camera — for EuRoC, of the rectified left camera when rectifying.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "orbis/camera/distortion.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/sensor_kind.hpp"
#include "orbis/camera/stereo.hpp"
#include "orbis/io/trajectory.hpp"

namespace orbis {

// The on-disk layouts orbis reads: TUM RGB-D, EuRoC MAV, KITTI odometry and KITTI raw.
enum class DatasetKind { TumRgbd, Euroc, Kitti, KittiRaw };
// SensorKind, parseSensorKind and toString(SensorKind): orbis/camera/sensor_kind.hpp (shared with
// the settings reader).

// "tum", "euroc", "kitti", "kitti-raw"; throws orbis::Error(source) otherwise.
DatasetKind parseDatasetKind(std::string_view name, const std::string& source = "dataset kind");
// "tum", "euroc", "kitti" or "kitti-raw".
std::string_view toString(DatasetKind kind);
// Recognises a dataset folder by its files (rgb.txt; mav0/; sequences/ or times.txt;
// image_00/timestamps.txt for a KITTI raw drive).
std::optional<DatasetKind> detectDatasetKind(const std::filesystem::path& root);

// How a dataset is read.
struct DatasetOptions {
  // The sensor to read as; empty means the dataset's own (TUM: RGB-D, EuRoC and KITTI: stereo,
  // or monocular when the KITTI sequence has no image_1). Monocular skips right/depth images.
  std::optional<SensorKind> sensor;
  double maxDepthDt = 0.02;          // TUM: largest |t_rgb - t_depth| of an associated pair, seconds
  double maxStereoDt = 0.003;        // EuRoC: largest |t_cam0 - t_cam1| of a stereo pair, seconds
  // TUM: raw depth value / scale = metres (the camera's depthScale). Empty: ORB-SLAM2's TUM1-3
  // settings, 5000 (the PNGs' factor), or 5208 for freiburg2, whose Kinect reads ~4 % long.
  std::optional<double> tumDepthScale;
  // TUM: the virtual stereo baseline times fx (pixels x metres). 40 is what ORB-SLAM2's TUM1-3
  // settings give every Kinect (about 7.5 cm at fx 535), so runs without a settings file match
  // runs with examples/settings/TUM3.yaml. tumVirtualBaseline (metres), when set, wins.
  double tumBf = 40.0;
  // TUM: the virtual baseline in metres, instead of tumBf.
  std::optional<double> tumVirtualBaseline;
  bool rectify = true;        // EuRoC: deliver rectified images and calibration (what the pipeline eats)
  bool strict = false;        // a missing right image or depth map throws instead of warning
  // A long run should survive a bad frame: a listed left/colour image that does not exist is then
  // an error of that frame only (frame(i) throws, naming list file and line) instead of an error
  // when opening.
  bool tolerateBadFrames = false;
  std::string kittiSequence;  // KITTI: "06" when root holds several sequences
};

// One frame of a sequence, images loaded.
struct DatasetFrame {
  // Position in the sequence.
  std::size_t index = 0;
  double timestamp = 0.0;  // seconds
  cv::Mat left;            // 8-bit, grey or BGR as stored (the colour image for RGB-D)
  cv::Mat right;           // stereo only; empty when missing (see warnings)
  cv::Mat depth;           // RGB-D only: raw CV_16U as stored (metres = value / the camera's
                           // depthScale), 0 = no reading; empty when missing
  // What was wrong with this frame and survived (a missing right image or depth map).
  std::vector<std::string> warnings;
};

// The camera a sequence is seen through, as the dataset calibrates it.
using DatasetCamera = std::variant<PinholeCamera<double>, RectifiedStereoCamera<double>, RgbdCamera<double>>;

// A sequence in a dataset's layout: text files read when opened, images when a frame is asked for.
class DatasetReader {
 public:
  virtual ~DatasetReader() = default;

  // @{
  // The layout, the sensor it is read as, and the number of frames.
  virtual DatasetKind kind() const = 0;
  virtual SensorKind sensor() const = 0;
  virtual std::size_t size() const = 0;
  // @}
  virtual double timestamp(std::size_t index) const = 0;  // without loading images
  // Loads frame index (< size()); throws orbis::Error for an unreadable image.
  virtual DatasetFrame frame(std::size_t index) const = 0;
  // Camera-to-world poses of the left/colour camera, time-ordered; empty when the dataset has none.
  virtual const Trajectory& groundTruth() const = 0;
  // The camera, as the dataset calibrates it.
  virtual DatasetCamera camera() const = 0;
  // Lens distortion still present in the delivered left images (zero when they are rectified
  // or undistorted already): TUM freiburg1/2 images are distorted.
  virtual RadTanDistortion<double> distortion() const { return {}; }
  // The sequence folder.
  virtual const std::filesystem::path& root() const = 0;
  // What was found wrong, and survived, while opening (rows put in time order, ...).
  const std::vector<std::string>& warnings() const { return warnings_; }

  // Sequential reading: the next frame, or nothing past the end.
  std::optional<DatasetFrame> next() {
    if (cursor_ >= size()) return std::nullopt;
    return frame(cursor_++);
  }
  // Starts sequential reading again at the first frame.
  void rewind() { cursor_ = 0; }

 protected:
  // Warnings of opening, filled by the reader.
  std::vector<std::string> warnings_;

 private:
  std::size_t cursor_ = 0;
};

// Opens the sequence at root in the given layout; throws orbis::Error naming the file and line of
// any defect.
std::unique_ptr<DatasetReader> openDataset(DatasetKind kind, const std::filesystem::path& root,
                                           const DatasetOptions& options = {});

// @{
// The individual readers, for callers that know the kind at compile time.
std::unique_ptr<DatasetReader> openTumRgbd(const std::filesystem::path& root, const DatasetOptions& options);
std::unique_ptr<DatasetReader> openEuroc(const std::filesystem::path& root, const DatasetOptions& options);
std::unique_ptr<DatasetReader> openKitti(const std::filesystem::path& root, const DatasetOptions& options);
// @}
// A KITTI raw drive folder (2011_09_26_drive_0001_sync: image_00/, image_01/, oxts/) with the
// calib_*.txt files beside it (the date folder) or in it. Ground truth: the OXTS poses as
// rectified left-camera poses, the first camera being the world.
std::unique_ptr<DatasetReader> openKittiRaw(const std::filesystem::path& root, const DatasetOptions& options);

}  // namespace orbis
