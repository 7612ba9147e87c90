// Image folders as frame sources: one camera's images, or paired colour and depth folders.
#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "frame_source_common.hpp"
#include "orbis/adapters/frame_source.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace fs = std::filesystem;
using namespace sources_detail;

namespace {

bool isImageFile(const fs::path& p) {
  static const std::set<std::string> kExtensions = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm", ".webp"};
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return kExtensions.count(ext) > 0;
}

std::vector<fs::path> listImages(const fs::path& folder) {
  std::error_code ec;
  if (!fs::exists(folder, ec)) throw fileError(folder.string(), "no such folder");
  if (!fs::is_directory(folder, ec))
    throw fileError(folder.string(), "is not a folder (for a video file use `orbis run video`)");
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file() && isImageFile(entry.path())) images.push_back(entry.path());
  if (ec) throw fileError(folder.string(), "cannot list the folder (" + ec.message() + ")");
  if (images.empty())
    throw fileError(folder.string(), "holds no image (png, jpg, jpeg, bmp, tif, tiff, pgm, ppm, webp)");
  // Names that are timestamps (1311868164.5.png, 1311868164.25.png) sort by their value: their
  // fractions need not have one width. Any other names sort naturally (frame2 before frame10).
  std::vector<std::optional<double>> stamps;
  for (const fs::path& p : images) stamps.push_back(timestampFromName(p.stem().string()));
  if (std::all_of(stamps.begin(), stamps.end(), [](const auto& t) { return t.has_value(); })) {
    std::vector<std::size_t> order(images.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return *stamps[a] < *stamps[b]; });
    std::vector<fs::path> sorted;
    for (std::size_t i : order) sorted.push_back(images[i]);
    return sorted;
  }
  std::sort(images.begin(), images.end(),
            [](const fs::path& a, const fs::path& b) { return naturalLess(a.filename().string(), b.filename().string()); });
  return images;
}

// The folder's timestamps, by the rules of openImageFolderSource; `how` says which was used.
std::vector<double> folderTimestamps(const fs::path& folder, const std::vector<fs::path>& images,
                                     const SourceOptions& options, std::vector<std::string>& warnings) {
  std::optional<fs::path> list = options.timesFile;
  if (!list) {
    for (const fs::path& dir : {folder, folder.parent_path()})
      for (const char* name : {"times.txt", "timestamps.txt"})
        if (!list && fs::is_regular_file(dir / name)) list = dir / name;
  }
  if (list) {
    std::vector<double> times = readTimestampList(*list);
    if (times.size() < images.size())
      throw fileError(list->string(), "lists " + std::to_string(times.size()) + " timestamps for the " +
                                          std::to_string(images.size()) + " images of " + folder.string());
    if (times.size() > images.size())
      warnings.push_back(list->string() + " lists " + std::to_string(times.size()) + " timestamps for " +
                         std::to_string(images.size()) + " images: the first " + std::to_string(images.size()) + " used");
    times.resize(images.size());
    return times;
  }
  std::vector<double> times(images.size());
  if (options.fps > 0) {
    for (std::size_t i = 0; i < images.size(); ++i) times[i] = static_cast<double>(i) / options.fps;
    return times;
  }
  bool named = true;
  for (std::size_t i = 0; i < images.size() && named; ++i) {
    const auto t = timestampFromName(images[i].stem().string());
    named = t.has_value();
    if (t) times[i] = *t;
  }
  if (named) return times;
  warnings.push_back(folder.string() + ": no times.txt/timestamps.txt and no --fps: frames timed at 30 fps");
  for (std::size_t i = 0; i < images.size(); ++i) times[i] = static_cast<double>(i) / 30.0;
  return times;
}

cv::Mat readImage(const fs::path& file, bool grey, bool depth, std::size_t index) {
  cv::Mat image = cv::imread(file.string(), depth ? cv::IMREAD_ANYDEPTH : grey ? cv::IMREAD_GRAYSCALE : cv::IMREAD_UNCHANGED);
  if (image.empty()) throw Error(file.string(), "frame " + std::to_string(index), "cannot be read as an image");
  if (depth) {
    if (image.type() != CV_16UC1)
      throw Error(file.string(), "frame " + std::to_string(index), "a depth map must be a 16-bit single-channel image");
    return image;
  }
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 256.0);  // 16-bit colour: keep the high byte
  return image;
}

class ImageFolderSource final : public FrameSource {
 public:
  ImageFolderSource(const fs::path& folder, const SourceOptions& options)
      : folder_(folder), options_(options), images_(listImages(folder)) {
    times_ = folderTimestamps(folder, images_, options, warnings_);
  }
  std::optional<SourceFrame> next() override {
    if (cursor_ >= images_.size()) return std::nullopt;
    const std::size_t i = cursor_++;
    SourceFrame f;
    f.index = i;
    f.timestamp = times_[i];
    f.image = readImage(images_[i], options_.grey, false, i);
    f.captured = steadyNow();
    splitStereo(f, options_.stereo, images_[i].string());
    return f;
  }
  std::string name() const override { return "images:" + folder_.string(); }
  SensorKind sensor() const override {
    return options_.stereo == StereoPacking::None ? SensorKind::Monocular : SensorKind::Stereo;
  }
  std::optional<std::size_t> expectedFrames() const override { return images_.size(); }

 private:
  fs::path folder_;
  SourceOptions options_;
  std::vector<fs::path> images_;
  std::vector<double> times_;
  std::size_t cursor_ = 0;
};

class RgbdFolderSource final : public FrameSource {
 public:
  RgbdFolderSource(const fs::path& colour, const fs::path& depth, const SourceOptions& options, double maxPairDt)
      : colourFolder_(colour), options_(options), colour_(listImages(colour)), depth_(listImages(depth)) {
    SourceOptions depthOptions = options;
    depthOptions.timesFile.reset();  // a --times list is the colour stream's
    colourTimes_ = folderTimestamps(colour, colour_, options, warnings_);
    depthTimes_ = folderTimestamps(depth, depth_, depthOptions, warnings_);
    pairs_.assign(colour_.size(), -1);
    std::size_t unpaired = 0;
    for (std::size_t i = 0; i < colour_.size(); ++i) {
      const auto it = std::lower_bound(depthTimes_.begin(), depthTimes_.end(), colourTimes_[i]);
      double best = maxPairDt;
      for (auto c : {it, it == depthTimes_.begin() ? it : std::prev(it)}) {
        if (c == depthTimes_.end()) continue;
        if (const double dt = std::abs(*c - colourTimes_[i]); dt <= best) {
          best = dt;
          pairs_[i] = static_cast<long>(c - depthTimes_.begin());
        }
      }
      unpaired += pairs_[i] < 0;
    }
    if (unpaired == colour_.size())
      throw fileError(depth.string(), "no depth map lies within " + std::to_string(maxPairDt) + " s of any colour image of " +
                                          colour.string() + " (check both folders' timestamps)");
    if (unpaired)
      warnings_.push_back(std::to_string(unpaired) + " colour images have no depth map within " + std::to_string(maxPairDt) + " s");
  }
  std::optional<SourceFrame> next() override {
    if (cursor_ >= colour_.size()) return std::nullopt;
    const std::size_t i = cursor_++;
    SourceFrame f;
    f.index = i;
    f.timestamp = colourTimes_[i];
    f.image = readImage(colour_[i], options_.grey, false, i);
    if (pairs_[i] >= 0) f.depth = readImage(depth_[static_cast<std::size_t>(pairs_[i])], false, true, i);
    else f.warnings.push_back("no depth map for " + colour_[i].filename().string());
    f.captured = steadyNow();
    return f;
  }
  std::string name() const override { return "rgbd-images:" + colourFolder_.string(); }
  SensorKind sensor() const override { return SensorKind::Rgbd; }
  std::optional<std::size_t> expectedFrames() const override { return colour_.size(); }

 private:
  fs::path colourFolder_;
  SourceOptions options_;
  std::vector<fs::path> colour_, depth_;
  std::vector<double> colourTimes_, depthTimes_;
  std::vector<long> pairs_;
  std::size_t cursor_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> openImageFolderSource(const fs::path& folder, const SourceOptions& options) {
  return std::make_unique<ImageFolderSource>(folder, options);
}

std::unique_ptr<FrameSource> openRgbdFolderSource(const fs::path& colourFolder, const fs::path& depthFolder,
                                                  const SourceOptions& options, double maxPairDt) {
  return std::make_unique<RgbdFolderSource>(colourFolder, depthFolder, options, maxPairDt);
}

}  // namespace orbis
