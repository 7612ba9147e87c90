// orbis/adapters/frame_source.hpp — frames that arrive one after another: video files and
// streams, image folders, live cameras, and the benchmark datasets read in order.
//
// Contract: a FrameSource delivers frames in time order through next(), each with a timestamp
// (seconds) and its images, and says nothing about how many will come: next() returns nothing
// at the end (a file's last frame, a camera that stopped delivering for SourceOptions::stallSeconds,
// a cancel request); endReason() then says why when the end was not a plain end of file.
// Opening checks what can be checked at once: a file, folder or device that is missing or
// cannot be opened throws orbis::Error naming it (a missing camera within a few seconds, never
// a hang). A frame that cannot be decoded throws orbis::Error naming the source and the frame;
// the caller may go on reading. Images are 8-bit grey or BGR as decoded (RGB-D depth: raw
// CV_16U as stored); stereo from one frame (side-by-side or top-bottom) is split here.
// A live source (camera, or any source made live by makeLiveSource) captures on its own
// thread, from the first next() on, into a one-slot mailbox: when the consumer is slower than the capture, the newest frame
// wins, dropped() counts the frames overwritten, and SourceFrame::captured is the steady-clock
// instant the frame arrived (so capture-to-pose latency can be measured). Sources carry no
// calibration except the dataset wrapper's; the camera then comes from a settings file.
#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "orbis/adapters/dataset.hpp"

namespace orbis {

// One frame from a streaming source: its images, timestamp and capture time.
struct SourceFrame {
  std::size_t index = 0;   // position in the source (a live source's dropped frames count too)
  double timestamp = 0.0;  // seconds
  cv::Mat image;           // the left/colour image
  cv::Mat right;           // stereo only
  cv::Mat depth;           // RGB-D only: raw CV_16U as stored
  std::chrono::steady_clock::time_point captured{};  // when the frame was captured or read
  // What was wrong with this frame and survived.
  std::vector<std::string> warnings;
};

// One frame holding both views of a stereo camera, as many USB stereo cameras deliver them.
enum class StereoPacking { None, SideBySide, TopBottom };
// "side-by-side" or "top-bottom" (also "none"); throws orbis::Error(source) otherwise.
StereoPacking parseStereoPacking(const std::string& name, const std::string& source = "stereo packing");

// How a frame source reads its input.
struct SourceOptions {
  // Frame rate for sources without timestamps (a video container without one, a folder without
  // a times file); for a video, also overrides the container's timestamps. 0: not given.
  double fps = 0.0;
  // A timestamp list (one per frame, first column of each line, '#' comments; seconds, or
  // nanoseconds when the values exceed 1e11) that overrides every other timestamp: e.g. the
  // rgb.txt of the TUM sequence a video was encoded from, so frame i gets image i's time.
  std::optional<std::filesystem::path> timesFile;
  // How a stereo camera packs its two views into one frame.
  StereoPacking stereo = StereoPacking::None;
  // Read images as grey (the pipeline's input) instead of colour: cheaper to decode and to copy.
  bool grey = false;
  // A live source ends when no frame arrived for this long (seconds).
  double stallSeconds = 5.0;
};

// Frames arriving one after another (a video, a folder, a live camera, or a dataset read in order),
// without random access or a known count.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // The next frame, or nothing at the end. Blocks until a frame is there (a live source at most
  // about stallSeconds). Throws orbis::Error for a frame that cannot be decoded.
  virtual std::optional<SourceFrame> next() = 0;
  // What the frames come from, e.g. "video:/data/clip.mp4", "camera:/dev/video0".
  virtual std::string name() const = 0;
  // @{
  // The sensor the frames are for, and whether they come from a live device.
  virtual SensorKind sensor() const { return SensorKind::Monocular; }
  virtual bool live() const { return false; }
  // @}
  // How many frames will come, when known in advance (files, folders); a progress bar's total.
  virtual std::optional<std::size_t> expectedFrames() const { return std::nullopt; }
  // Whether the source carries its own calibration (only a dataset does), and that calibration
  // (empty without one: a settings file must give it; a dataset's camera() may throw when its
  // files do not say, e.g. which TUM Kinect recorded it).
  virtual bool hasCalibration() const { return false; }
  /** That calibration, if any. */ virtual std::optional<DatasetCamera> camera() const { return std::nullopt; }
  // Lens distortion still present in the images (zero: undistorted or unknown).
  virtual RadTanDistortion<double> distortion() const { return {}; }
  // Camera-to-world poses of the left/colour camera, when known; empty otherwise.
  virtual const Trajectory& groundTruth() const { return noGroundTruth_; }
  // Frames a live source captured but overwrote before they were taken (newest frame wins).
  virtual std::size_t dropped() const { return 0; }
  // Why the source ended early (a stalled camera, ...); empty for a plain end.
  virtual std::string endReason() const { return {}; }
  // For a live source: next() gives up waiting (returns nothing) once cancel() is true; checked
  // every few tens of milliseconds, so a signal flag can end a run promptly.
  virtual void setCancelCheck(std::function<bool()> cancel) { cancel_ = std::move(cancel); }
  // What was found wrong, and survived, while opening.
  const std::vector<std::string>& warnings() const { return warnings_; }

 protected:
  // @{
  // Warnings of opening, and the cancel check, for derived sources.
  std::vector<std::string> warnings_;
  std::function<bool()> cancel_;
  // @}

 private:
  Trajectory noGroundTruth_;
};

// A dataset read in order, with its calibration and ground truth. The reader is owned.
std::unique_ptr<FrameSource> makeDatasetSource(std::unique_ptr<DatasetReader> dataset);
// The same over a reader the caller keeps (it must outlive the source).
std::unique_ptr<FrameSource> makeDatasetSource(DatasetReader& dataset);

// A video file or stream: anything OpenCV's FFmpeg or GStreamer backend opens (a file, an
// rtsp:// or http:// URL, a GStreamer pipeline ending in appsink). Timestamps: options.timesFile,
// else options.fps (frame i at i / fps), else the container's presentation times; a source
// with none of them throws at opening. URLs and pipelines are live (captured on a thread).
std::unique_ptr<FrameSource> openVideoSource(const std::string& pathOrUrl, const SourceOptions& options = {});

// A folder of images (png, jpg, jpeg, bmp, tif, tiff, pgm, ppm, webp) in name order (numbers in
// names compared as numbers: 2.png before 10.png). Timestamps: options.timesFile, else a
// times.txt or timestamps.txt in the folder or beside it (one per image; seconds or nanoseconds),
// else options.fps, else names that are timestamps themselves (1311868164.363181.png in seconds,
// 1403636579763555584.png in nanoseconds), else 30 fps with a warning.
std::unique_ptr<FrameSource> openImageFolderSource(const std::filesystem::path& folder,
                                                   const SourceOptions& options = {});

// RGB-D from two folders, colour and depth (16-bit PNG), as RealSense and Azure Kinect tools
// export them: each folder's images in name order with the timestamps found as for
// openImageFolderSource; depth maps are paired to colour images by nearest timestamp within
// maxPairDt seconds (a colour image without one is delivered with a warning and no depth).
std::unique_ptr<FrameSource> openRgbdFolderSource(const std::filesystem::path& colourFolder,
                                                  const std::filesystem::path& depthFolder,
                                                  const SourceOptions& options = {}, double maxPairDt = 0.02);

// A live camera: a device index ("0"), a device path ("/dev/video2") or a GStreamer pipeline
// (anything with a '!'). Frames are timestamped on arrival (system clock, seconds since the
// epoch). An absent or busy device throws orbis::Error naming it; options.fps asks the device
// for that rate.
std::unique_ptr<FrameSource> openCameraSource(const std::string& device, const SourceOptions& options = {});

// Stereo from two sources delivering frames in step (two folders, two videos): frame i of each
// makes pair i, with the left source's timestamp.
std::unique_ptr<FrameSource> makeStereoPairSource(std::unique_ptr<FrameSource> left, std::unique_ptr<FrameSource> right);

// Runs `source` on a capture thread into a one-slot mailbox: the newest frame wins, dropped()
// counts the overwritten ones, and `captured` is stamped when a frame enters the mailbox. With
// paceByTimestamps (a recording played back as if live), frame i enters the mailbox no earlier
// than its timestamp's offset from the first frame's. A source already live is returned as is.
std::unique_ptr<FrameSource> makeLiveSource(std::unique_ptr<FrameSource> source, bool paceByTimestamps,
                                            double stallSeconds = 5.0);

}  // namespace orbis
