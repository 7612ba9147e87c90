#include "map_delta.hpp"

#include <algorithm>

#include "json_out.hpp"

namespace orbis::viewer_detail {
namespace {

bool moved(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return ((a - b).cwiseAbs().array() > MapDeltaEncoder::kMoveTolerance).any();
}

bool keyFrameChanged(const KeyFrameSnapshot& sent, const KeyFrameSnapshot& now) {
  if (sent.parent != now.parent || sent.covisibles != now.covisibles || sent.loopEdges != now.loopEdges ||
      sent.mapId != now.mapId)
    return true;
  // Translation in metres, rotation entries (about radians for small turns): one tolerance.
  return (sent.Twc.matrix3x4() - now.Twc.matrix3x4()).cwiseAbs().maxCoeff() > MapDeltaEncoder::kMoveTolerance;
}

void writeKeyFrame(JsonOut& out, const KeyFrameSnapshot& k) {
  out.separator().raw("{");
  out.key("id").integer(static_cast<long long>(k.id)).key("frame").integer(static_cast<long long>(k.frameIndex));
  out.key("parent").integer(k.parent).key("map").integer(k.mapId).key("Twc").pose(k.Twc);
  out.key("covisibles").raw("[");
  for (KeyFrameId c : k.covisibles) out.separator().integer(static_cast<long long>(c));
  out.raw("]").key("loops").raw("[");
  for (KeyFrameId l : k.loopEdges) out.separator().integer(static_cast<long long>(l));
  out.raw("]}");
}

void writePoint(JsonOut& out, MapPointId id, const Eigen::Vector3f& p, KeyFrameId firstKeyFrame, bool local) {
  out.separator().integer(static_cast<long long>(id)).raw(",");
  out.number(p.x()).raw(",").number(p.y()).raw(",").number(p.z());
  out.raw(",").integer(static_cast<long long>(firstKeyFrame)).raw(local ? ",1" : ",0");
}

void writeIds(JsonOut& out, std::string_view name, const std::vector<std::uint64_t>& ids) {
  out.key(name).raw("[");
  for (std::uint64_t id : ids) out.separator().integer(static_cast<long long>(id));
  out.raw("]");
}

void writeTrajectory(JsonOut& out, const std::vector<Eigen::Vector3f>& trajectory, std::size_t from) {
  out.key("trajectoryFrom").integer(static_cast<long long>(from)).key("trajectory").raw("[");
  for (std::size_t i = from; i < trajectory.size(); ++i)
    out.separator().number(trajectory[i].x()).raw(",").number(trajectory[i].y()).raw(",").number(trajectory[i].z());
  out.raw("]").key("trajectoryLength").integer(static_cast<long long>(trajectory.size()));
}

void writeHeader(JsonOut& out, std::uint64_t seq, bool full, bool live, std::size_t frames) {
  out.raw("{").key("seq").integer(static_cast<long long>(seq)).key("full").raw(full ? "true" : "false");
  out.key("live").raw(live ? "true" : "false").key("frames").integer(static_cast<long long>(frames));
}

void writeLoopClosures(JsonOut& out, const std::vector<LoopClosureEvent>& closures) {
  out.key("loopClosures").raw("[");
  for (const LoopClosureEvent& e : closures) {
    out.separator().raw("{").key("current").integer(static_cast<long long>(e.current));
    out.key("loop").integer(static_cast<long long>(e.loop)).key("frame").integer(static_cast<long long>(e.frameIndex));
    out.key("inliers").integer(e.inliers).raw("}");
  }
  out.raw("]");
}

void writeMerges(JsonOut& out, const std::vector<MapMergeEvent>& merges) {
  out.key("merges").raw("[");
  for (const MapMergeEvent& e : merges) {
    out.separator().raw("{").key("frame").integer(static_cast<long long>(e.frameIndex));
    out.key("kept").integer(e.keptMap).key("moved").integer(e.movedMap).key("inliers").integer(e.inliers).raw("}");
  }
  out.raw("]");
}

// Drops what the snapshot of message `seq` no longer held (points, keyframes: id -> entry with
// seenIn); returns their ids.
template <typename SentById>
std::vector<std::uint64_t> dropUnseen(SentById& sent, std::uint64_t seq) {
  std::vector<std::uint64_t> dropped;
  for (auto it = sent.begin(); it != sent.end();)
    if (it->second.seenIn != seq) {
      dropped.push_back(it->first);
      it = sent.erase(it);
    } else {
      ++it;
    }
  return dropped;
}

}  // namespace

MapDeltaEncoder::Message MapDeltaEncoder::encode(const MapSnapshot& map, const std::unordered_set<MapPointId>& localMap,
                                                 bool live) {
  std::lock_guard lock(mutex_);
  const std::uint64_t seq = ++seq_;
  live_ = live;
  frames_ = map.frames;
  loopClosures_ = map.loopClosures;
  merges_ = map.merges;
  JsonOut out;
  writeHeader(out, seq, false, live, map.frames);

  out.key("keyFrames").raw("[");
  for (const KeyFrameSnapshot& k : map.keyFrames) {
    auto [sent, added] = keyFrames_.try_emplace(k.id);
    if (added || keyFrameChanged(sent->second.keyFrame, k)) {
      sent->second.keyFrame = k;
      writeKeyFrame(out, k);
    }
    sent->second.seenIn = seq;
  }
  out.raw("]");
  writeIds(out, "removedKeyFrames", dropUnseen(keyFrames_, seq));

  out.key("points").raw("[");
  for (const MapPointSnapshot& p : map.points) {
    const bool local = localMap.count(p.id) > 0;
    auto [sent, added] = points_.try_emplace(p.id);
    SentPoint& s = sent->second;
    if (added || s.local != local || moved(s.position, p.position)) {
      s.position = p.position;
      s.firstKeyFrame = p.firstKeyFrame;
      s.local = local;
      writePoint(out, p.id, p.position, p.firstKeyFrame, local);
    }
    s.seenIn = seq;
  }
  out.raw("]");
  writeIds(out, "removedPoints", dropUnseen(points_, seq));

  // The unchanged beginning keeps the positions sent, so small moves cannot add up unseen.
  std::size_t from = 0;
  const std::size_t common = std::min(trajectory_.size(), map.trajectory.size());
  while (from < common && !moved(trajectory_[from], map.trajectory[from])) ++from;
  trajectory_.resize(from);
  trajectory_.insert(trajectory_.end(), map.trajectory.begin() + static_cast<std::ptrdiff_t>(from), map.trajectory.end());
  writeTrajectory(out, trajectory_, from);
  writeLoopClosures(out, loopClosures_);
  writeMerges(out, merges_);
  return {seq, out.raw("}").take()};
}

MapDeltaEncoder::Message MapDeltaEncoder::full() const {
  std::lock_guard lock(mutex_);
  JsonOut out;
  writeHeader(out, seq_, true, live_, frames_);
  out.key("keyFrames").raw("[");
  for (const auto& [id, sent] : keyFrames_) writeKeyFrame(out, sent.keyFrame);
  out.raw("]");
  writeIds(out, "removedKeyFrames", {});
  out.key("points").raw("[");
  for (const auto& [id, p] : points_) writePoint(out, id, p.position, p.firstKeyFrame, p.local);
  out.raw("]");
  writeIds(out, "removedPoints", {});
  writeTrajectory(out, trajectory_, 0);
  writeLoopClosures(out, loopClosures_);
  writeMerges(out, merges_);
  return {seq_, out.raw("}").take()};
}

}  // namespace orbis::viewer_detail
