#include "scene_json.hpp"

#include "json_out.hpp"

namespace orbis::viewer_detail {

std::string frameMessage(const FrameSnapshot& frame, std::string_view jpegBase64) {
  JsonOut out;
  out.raw("{").key("index").integer(static_cast<long long>(frame.index)).key("t").number(frame.timestamp, 6);
  out.key("state").raw("\"").raw(toString(frame.state)).raw("\"");
  out.key("newKeyFrame").raw(frame.newKeyFrame ? "true" : "false").key("inliers").integer(frame.inliers);
  out.key("width").number(frame.imageWidth, 0).key("height").number(frame.imageHeight, 0);
  out.key("ms").raw("{").key("extraction").number(frame.extractionMs, 2);
  out.key("tracking").number(frame.trackingMs, 2).raw("}");
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
