#include "scene_json.hpp"

#include <algorithm>

#include "json_out.hpp"

namespace orbis::viewer_detail {

void RecentTimings::add(double extractionMs, double trackingMs) {
  extraction_[next_] = extractionMs;
  tracking_[next_] = trackingMs;
  next_ = (next_ + 1) % kFrames;
  count_ = std::min(count_ + 1, kFrames);
}

FrameTimingMedians RecentTimings::medians() const {
  auto median = [this](std::array<double, kFrames> values) {
    if (count_ == 0) return 0.0;
    auto middle = values.begin() + static_cast<std::ptrdiff_t>(count_ / 2);
    std::nth_element(values.begin(), middle, values.begin() + static_cast<std::ptrdiff_t>(count_));
    return *middle;
  };
  return {median(extraction_), median(tracking_)};
}

std::string frameMessage(const FrameSnapshot& frame, std::string_view jpegBase64, const FrameTimingMedians& medians) {
  JsonOut out;
  out.raw("{").key("index").integer(static_cast<long long>(frame.index)).key("t").number(frame.timestamp, 6);
  out.key("state").raw("\"").raw(toString(frame.state)).raw("\"");
  out.key("newKeyFrame").raw(frame.newKeyFrame ? "true" : "false").key("inliers").integer(frame.inliers);
  out.key("width").number(frame.imageWidth, 0).key("height").number(frame.imageHeight, 0);
  out.key("ms").raw("{").key("extraction").number(frame.extractionMs, 2);
  out.key("tracking").number(frame.trackingMs, 2).key("extractionMedian").number(medians.extraction, 2);
  out.key("trackingMedian").number(medians.tracking, 2).raw("}");
  out.key("Twc");
  if (frame.state == TrackingState::Ok) out.pose(frame.Tcw.inverse());
  else out.raw("null");
  out.key("keypoints").raw("[");
  if (frame.features) {
    const auto& keypoints = frame.features->keypoints;
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      const int state = i < frame.keypointStates.size() ? static_cast<int>(frame.keypointStates[i]) : 0;
      out.separator().number(keypoints[i].u, 1).raw(",").number(keypoints[i].v, 1).raw(",").integer(state);
    }
  }
  out.raw("]").key("image");
  if (jpegBase64.empty()) out.raw("null");
  else out.raw("\"").raw(jpegBase64).raw("\"");  // base64 needs no JSON escaping
  return out.raw("}").take();
}

}  // namespace orbis::viewer_detail
