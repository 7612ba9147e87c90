#include "scene_json.hpp"

#include <charconv>
#include <cstdio>

namespace orbis::viewer_detail {
namespace {

// Appends JSON numbers and lists to one string, without a DOM: the messages are large and built
// several times a second.
class JsonOut {
 public:
  JsonOut& raw(std::string_view s) {
    text_ += s;
    return *this;
  }
  JsonOut& number(double v, int decimals = 4) {
    char buffer[48];
    const auto r = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::fixed, decimals);
    text_.append(buffer, r.ptr);
    return *this;
  }
  JsonOut& integer(long long v) {
    char buffer[24];
    const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
    text_.append(buffer, r.ptr);
    return *this;
  }
  JsonOut& key(std::string_view name) {
    if (!text_.empty() && text_.back() != '{' && text_.back() != '[') text_ += ',';
    text_ += '"';
    text_ += name;
    text_ += "\":";
    return *this;
  }
  JsonOut& separator() {
    if (text_.back() != '[' && text_.back() != '{') text_ += ',';
    return *this;
  }
  JsonOut& pose(const SE3d& Twc) {
    const Eigen::Matrix3d R = Twc.rotationMatrix();
    const Eigen::Vector3d t = Twc.translation();
    raw("[");
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        if (r || c) raw(",");
        number(c < 3 ? R(r, c) : t(r), 5);
      }
    return raw("]");
  }
  std::string take() { return std::move(text_); }

 private:
  std::string text_;
};

void writeKeyFrames(JsonOut& out, const MapSnapshot& map) {
  out.key("keyFrames").raw("[");
  for (const KeyFrameSnapshot& k : map.keyFrames) {
    out.separator().raw("{");
    out.key("id").integer(k.id).key("frame").integer(static_cast<long long>(k.frameIndex));
    out.key("parent").integer(k.parent).key("Twc").pose(k.Twc);
    out.key("covisibles").raw("[");
    for (KeyFrameId c : k.covisibles) out.separator().integer(c);
    out.raw("]").key("loops").raw("[");
    for (KeyFrameId l : k.loopEdges) out.separator().integer(l);
    out.raw("]}");
  }
  out.raw("]");
}

void writePoints(JsonOut& out, const MapSnapshot& map, const std::unordered_set<MapPointId>& localMap) {
  out.key("points").raw("[");
  for (const MapPointSnapshot& p : map.points) {
    out.separator().number(p.position.x()).raw(",").number(p.position.y()).raw(",").number(p.position.z());
    out.raw(",").integer(p.firstKeyFrame).raw(localMap.count(p.id) ? ",1" : ",0");
  }
  out.raw("]").key("trajectory").raw("[");
  for (const Eigen::Vector3f& c : map.trajectory)
    out.separator().number(c.x()).raw(",").number(c.y()).raw(",").number(c.z());
  out.raw("]");
}

}  // namespace

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

std::string mapMessage(const MapSnapshot& map, const std::unordered_set<MapPointId>& localMap, bool live) {
  JsonOut out;
  out.raw("{").key("live").raw(live ? "true" : "false").key("frames").integer(static_cast<long long>(map.frames));
  writeKeyFrames(out, map);
  writePoints(out, map, localMap);
  out.key("loopClosures").raw("[");
  for (const LoopClosureEvent& e : map.loopClosures) {
    out.separator().raw("{").key("current").integer(e.current).key("loop").integer(e.loop);
    out.key("frame").integer(static_cast<long long>(e.frameIndex)).key("inliers").integer(e.inliers).raw("}");
  }
  return out.raw("]}").take();
}

}  // namespace orbis::viewer_detail
