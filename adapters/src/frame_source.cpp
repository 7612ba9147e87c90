// The frame-source helpers, the dataset wrapper and the two-source stereo pair.
#include "orbis/adapters/frame_source.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <charconv>
#include <fstream>
#include <sstream>

#include "frame_source_common.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace fs = std::filesystem;

StereoPacking parseStereoPacking(const std::string& name, const std::string& source) {
  if (name == "side-by-side" || name == "sbs") return StereoPacking::SideBySide;
  if (name == "top-bottom" || name == "tb") return StereoPacking::TopBottom;
  if (name == "none") return StereoPacking::None;
  throw Error(source, "", "expected side-by-side or top-bottom, got '" + name + "'");
}

namespace sources_detail {

std::vector<double> readTimestampList(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw fileError(file.string(), "cannot open the timestamp list");
  std::vector<double> times;
  std::string line;
  std::size_t lineNumber = 0;
  bool nanoseconds = false;
  while (std::getline(in, line)) {
    ++lineNumber;
    std::istringstream fields(line);
    std::string first;
    if (!(fields >> first) || first[0] == '#') continue;
    if (first.back() == ',') first.pop_back();  // a CSV row (EuRoC's data.csv: "ns,file")
    if (const auto comma = first.find(','); comma != std::string::npos) first.resize(comma);
    double t = 0;
    const auto [end, ec] = std::from_chars(first.data(), first.data() + first.size(), t);
    if (ec != std::errc() || end != first.data() + first.size() || !std::isfinite(t))
      throw lineError(file.string(), lineNumber, "expected a timestamp (seconds or nanoseconds), got '" + first + "'");
    if (t > 1e11) nanoseconds = true;
    times.push_back(t);
  }
  if (times.empty()) throw fileError(file.string(), "the timestamp list holds no timestamp");
  if (nanoseconds)
    for (double& t : times) t *= 1e-9;
  return times;
}

bool naturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t iEnd = i, jEnd = j;
      while (iEnd < a.size() && std::isdigit(static_cast<unsigned char>(a[iEnd]))) ++iEnd;
      while (jEnd < b.size() && std::isdigit(static_cast<unsigned char>(b[jEnd]))) ++jEnd;
      // Compare as numbers without overflow: strip leading zeros, then length, then digits.
      std::size_t iStart = i, jStart = j;
      while (iStart + 1 < iEnd && a[iStart] == '0') ++iStart;
      while (jStart + 1 < jEnd && b[jStart] == '0') ++jStart;
      if (iEnd - iStart != jEnd - jStart) return iEnd - iStart < jEnd - jStart;
      if (const int c = a.compare(iStart, iEnd - iStart, b, jStart, jEnd - jStart); c != 0) return c < 0;
      i = iEnd;
      j = jEnd;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

std::optional<double> timestampFromName(const std::string& stem) {
  const auto dot = stem.find('.');
  const auto allDigits = [](const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
  };
  if (dot != std::string::npos) {
    if (!allDigits(stem.substr(0, dot)) || !allDigits(stem.substr(dot + 1))) return std::nullopt;
    return std::stod(stem);
  }
  if (allDigits(stem) && stem.size() >= 16) return std::stod(stem) * 1e-9;
  return std::nullopt;
}

void splitStereo(SourceFrame& frame, StereoPacking packing, const std::string& source) {
  if (packing == StereoPacking::None) return;
  const cv::Mat packed = frame.image;
  if (packing == StereoPacking::SideBySide) {
    if (packed.cols % 2 != 0)
      throw Error(source, "frame " + std::to_string(frame.index),
                  "a side-by-side stereo frame needs an even width, got " + std::to_string(packed.cols));
    const int half = packed.cols / 2;
    frame.image = packed.colRange(0, half).clone();
    frame.right = packed.colRange(half, packed.cols).clone();
  } else {
    if (packed.rows % 2 != 0)
      throw Error(source, "frame " + std::to_string(frame.index),
                  "a top-bottom stereo frame needs an even height, got " + std::to_string(packed.rows));
    const int half = packed.rows / 2;
    frame.image = packed.rowRange(0, half).clone();
    frame.right = packed.rowRange(half, packed.rows).clone();
  }
}

double wallClockSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool looksLikeUrl(const std::string& s) { return s.find("://") != std::string::npos; }
bool looksLikePipeline(const std::string& s) { return s.find('!') != std::string::npos; }

}  // namespace sources_detail

namespace {

// A dataset's frames in order, with its calibration and ground truth.
class DatasetSource final : public FrameSource {
 public:
  DatasetSource(std::unique_ptr<DatasetReader> owned, DatasetReader& dataset) : owned_(std::move(owned)), dataset_(dataset) {
    warnings_ = dataset_.warnings();
  }
  std::optional<SourceFrame> next() override {
    if (cursor_ >= dataset_.size()) return std::nullopt;
    const std::size_t i = cursor_++;
    DatasetFrame f = dataset_.frame(i);  // throws for this frame only: the caller may go on
    SourceFrame s;
    s.index = i;
    s.timestamp = f.timestamp;
    s.image = std::move(f.left);
    s.right = std::move(f.right);
    s.depth = std::move(f.depth);
    s.captured = sources_detail::steadyNow();
    s.warnings = std::move(f.warnings);
    return s;
  }
  std::string name() const override {
    return std::string(toString(dataset_.kind())) + ":" + dataset_.root().filename().string();
  }
  SensorKind sensor() const override { return dataset_.sensor(); }
  std::optional<std::size_t> expectedFrames() const override { return dataset_.size(); }
  bool hasCalibration() const override { return true; }
  std::optional<DatasetCamera> camera() const override { return dataset_.camera(); }
  RadTanDistortion<double> distortion() const override { return dataset_.distortion(); }
  const Trajectory& groundTruth() const override { return dataset_.groundTruth(); }

 private:
  std::unique_ptr<DatasetReader> owned_;
  DatasetReader& dataset_;
  std::size_t cursor_ = 0;
};

class StereoPairSource final : public FrameSource {
 public:
  StereoPairSource(std::unique_ptr<FrameSource> left, std::unique_ptr<FrameSource> right)
      : left_(std::move(left)), right_(std::move(right)) {
    warnings_ = left_->warnings();
    warnings_.insert(warnings_.end(), right_->warnings().begin(), right_->warnings().end());
  }
  std::optional<SourceFrame> next() override {
    auto l = left_->next();
    auto r = right_->next();
    if (!l || !r) {
      if (l || r) reason_ = (l ? right_->name() : left_->name()) + " ended before " + (l ? left_->name() : right_->name());
      return std::nullopt;
    }
    l->right = std::move(r->image);
    for (auto& w : r->warnings) l->warnings.push_back(std::move(w));
    return l;
  }
  std::string name() const override { return "stereo:" + left_->name() + "+" + right_->name(); }
  SensorKind sensor() const override { return SensorKind::Stereo; }
  bool live() const override { return left_->live() || right_->live(); }
  std::optional<std::size_t> expectedFrames() const override { return left_->expectedFrames(); }
  std::size_t dropped() const override { return left_->dropped() + right_->dropped(); }
  std::string endReason() const override {
    if (!reason_.empty()) return reason_;
    return left_->endReason().empty() ? right_->endReason() : left_->endReason();
  }
  void setCancelCheck(std::function<bool()> cancel) override {
    left_->setCancelCheck(cancel);
    right_->setCancelCheck(std::move(cancel));
  }

 private:
  std::unique_ptr<FrameSource> left_, right_;
  std::string reason_;
};

}  // namespace

std::unique_ptr<FrameSource> makeDatasetSource(std::unique_ptr<DatasetReader> dataset) {
  DatasetReader& reader = *dataset;
  return std::make_unique<DatasetSource>(std::move(dataset), reader);
}

std::unique_ptr<FrameSource> makeDatasetSource(DatasetReader& dataset) {
  return std::make_unique<DatasetSource>(nullptr, dataset);
}

std::unique_ptr<FrameSource> makeStereoPairSource(std::unique_ptr<FrameSource> left, std::unique_ptr<FrameSource> right) {
  return std::make_unique<StereoPairSource>(std::move(left), std::move(right));
}

}  // namespace orbis
