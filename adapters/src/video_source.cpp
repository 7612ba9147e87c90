// Video files, streams and live cameras through OpenCV's videoio (FFmpeg, GStreamer, V4L2).
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "frame_source_common.hpp"
#include "orbis/adapters/frame_source.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace fs = std::filesystem;
using namespace sources_detail;

namespace {

// Frame i's timestamp when the container's presentation times are not used.
struct FixedTimes {
  std::vector<double> list;  // SourceOptions::timesFile
  double fps = 0;            // else i / fps
};

class CaptureSource final : public FrameSource {
 public:
  // `arrivalTimes`: stamp each frame with the wall clock when it arrives (cameras, live streams),
  // unless fixed times are given.
  CaptureSource(std::string name, cv::VideoCapture capture, const SourceOptions& options, bool live, bool arrivalTimes)
      : name_(std::move(name)), capture_(std::move(capture)), options_(options), live_(live), arrivalTimes_(arrivalTimes) {
    if (options.timesFile) fixed_.list = readTimestampList(*options.timesFile);
    else if (options.fps > 0) fixed_.fps = options.fps;
    containerFps_ = capture_.get(cv::CAP_PROP_FPS);
    if (!(containerFps_ > 0 && containerFps_ < 1000)) containerFps_ = 0;
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    if (!live_ && count > 0 && count < 1e9) frameCount_ = static_cast<std::size_t>(count);
    if (!live_ && fixed_.list.empty() && fixed_.fps <= 0 && containerFps_ <= 0)
      warnings_.push_back(name_ + ": the container gives no frame rate; timestamps come from its presentation times (give --fps if they are wrong)");
  }

  std::optional<SourceFrame> next() override {
    if (ended_) return std::nullopt;
    cv::Mat image;
    if (!capture_.read(image) || image.empty()) {
      ended_ = true;
      if (live_) reason_ = name_ + " stopped delivering frames";
      else if (frameCount_ && index_ + 1 < *frameCount_ * 9 / 10)
        reason_ = name_ + ": decoding stopped at frame " + std::to_string(index_) + " of the " + std::to_string(*frameCount_) +
                  " the container announces (a damaged or truncated file?)";
      return std::nullopt;
    }
    SourceFrame f;
    f.index = index_++;
    f.captured = steadyNow();
    if (!fixed_.list.empty()) {
      if (f.index >= fixed_.list.size()) {
        ended_ = true;
        reason_ = name_ + " has more frames than the " + std::to_string(fixed_.list.size()) +
                  " timestamps of " + options_.timesFile->string() + ": stopped there";
        return std::nullopt;
      }
      f.timestamp = fixed_.list[f.index];
    } else if (fixed_.fps > 0) {
      f.timestamp = static_cast<double>(f.index) / fixed_.fps;
    } else if (arrivalTimes_) {
      f.timestamp = wallClockSeconds();
    } else {
      f.timestamp = containerTime(f.index);
    }
    if (options_.grey && image.channels() != 1) cv::cvtColor(image, f.image, cv::COLOR_BGR2GRAY);
    else f.image = std::move(image);
    splitStereo(f, options_.stereo, name_);
    return f;
  }

  std::string name() const override { return name_; }
  SensorKind sensor() const override {
    return options_.stereo == StereoPacking::None ? SensorKind::Monocular : SensorKind::Stereo;
  }
  bool live() const override { return false; }  // the capture thread around it (makeLiveSource) is
  std::optional<std::size_t> expectedFrames() const override {
    if (!fixed_.list.empty() && frameCount_) return std::min(*frameCount_, fixed_.list.size());
    return frameCount_;
  }
  std::string endReason() const override { return reason_; }

 private:
  // The frame's presentation time; where the container repeats or lacks one, the previous
  // time plus a frame interval (so timestamps always increase).
  double containerTime(std::size_t index) {
    double t = capture_.get(cv::CAP_PROP_POS_MSEC) * 1e-3;
    const double step = containerFps_ > 0 ? 1.0 / containerFps_ : 1.0 / 30.0;
    if (!std::isfinite(t) || (index > 0 && t <= lastTime_)) {
      t = index == 0 ? 0.0 : lastTime_ + step;
      if (!repairedWarned_) {
        warnings_.push_back(name_ + ": presentation times missing or not increasing from frame " + std::to_string(index) +
                            "; frames spaced by the frame rate instead");
        repairedWarned_ = true;
      }
    }
    lastTime_ = t;
    return t;
  }

  std::string name_;
  cv::VideoCapture capture_;
  SourceOptions options_;
  bool live_, arrivalTimes_;
  FixedTimes fixed_;
  double containerFps_ = 0;
  std::optional<std::size_t> frameCount_;
  std::size_t index_ = 0;
  bool ended_ = false;
  std::string reason_;
  double lastTime_ = 0;
  bool repairedWarned_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> openVideoSource(const std::string& pathOrUrl, const SourceOptions& options) {
  const bool pipeline = looksLikePipeline(pathOrUrl);
  const bool url = !pipeline && looksLikeUrl(pathOrUrl);
  if (!pipeline && !url) {
    std::error_code ec;
    if (!fs::exists(pathOrUrl, ec)) throw fileError(pathOrUrl, "no such video file");
    if (fs::is_directory(pathOrUrl, ec)) throw fileError(pathOrUrl, "is a folder (for a folder of images use `orbis run images`)");
  }
  if (options.timesFile && !fs::is_regular_file(*options.timesFile))
    throw fileError(options.timesFile->string(), "no such timestamp list");
  cv::VideoCapture capture;
  if (pipeline) {
    capture.open(pathOrUrl, cv::CAP_GSTREAMER);
  } else {
    // FFmpeg first: it reports presentation times and frame counts; GStreamer as the fallback.
    capture.open(pathOrUrl, cv::CAP_FFMPEG);
    if (!capture.isOpened()) capture.open(pathOrUrl, cv::CAP_ANY);
  }
  if (!capture.isOpened())
    throw fileError(pathOrUrl, pipeline ? "the GStreamer pipeline cannot be started (it must end in appsink)"
                                        : "cannot be opened as a video by FFmpeg or GStreamer (not a video, a codec "
                                          "this OpenCV lacks, or an unreachable stream)");
  const bool live = pipeline || url;
  const std::string name = (pipeline ? "pipeline:" : url ? "stream:" : "video:") + pathOrUrl;
  auto source = std::make_unique<CaptureSource>(name, std::move(capture), options, live, live);
  if (!live) return source;
  return makeLiveSource(std::move(source), false, options.stallSeconds);
}

std::unique_ptr<FrameSource> openCameraSource(const std::string& device, const SourceOptions& options) {
  cv::VideoCapture capture;
  std::string name = "camera:" + device;
  if (looksLikePipeline(device)) {
    capture.open(device, cv::CAP_GSTREAMER);
    if (!capture.isOpened()) throw Error(name, "", "the GStreamer pipeline cannot be started (it must end in appsink)");
  } else {
    int index = -1;
    std::string path = device.empty() ? "0" : device;
    if (path.find_first_not_of("0123456789") == std::string::npos) {
      index = std::stoi(path);
      path = "/dev/video" + path;
    }
    std::error_code ec;
    if (!fs::exists(path, ec))
      throw Error(name, "", "no such camera (" + path + " does not exist; `ls /dev/video*` lists the cameras present)");
    if (index >= 0) capture.open(index, cv::CAP_V4L2);
    else capture.open(path, cv::CAP_V4L2);
    if (!capture.isOpened())
      throw Error(name, "", "the camera cannot be opened (busy in another program, or no permission: is the user in group video?)");
  }
  if (options.fps > 0) capture.set(cv::CAP_PROP_FPS, options.fps);
  // The device's own rate stamps nothing: frames are timed on arrival.
  SourceOptions live = options;
  live.fps = 0;
  auto source = std::make_unique<CaptureSource>(name, std::move(capture), live, true, true);
  return makeLiveSource(std::move(source), false, options.stallSeconds);
}

}  // namespace orbis
