#include "orbis/map/map.hpp"

namespace orbis {

KeyFrame* Map::createKeyFrame(std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
                              std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
                              bow::BowVector bowVector, bow::FeatureVector featureVector) {
  const KeyFrameId id = keyFrames_.size();
  return adopt(std::make_unique<KeyFrame>(id, frameIndex, timestamp, Tcw, std::move(features), intrinsics,
                                          std::move(bowVector), std::move(featureVector)));
}

KeyFrame* Map::createKeyFrame(std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
                              std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
                              BowComputation computeBow) {
  const KeyFrameId id = keyFrames_.size();
  return adopt(std::make_unique<KeyFrame>(id, frameIndex, timestamp, Tcw, std::move(features), intrinsics,
                                          std::move(computeBow)));
}

KeyFrame* Map::adopt(std::unique_ptr<KeyFrame> created) {
  keyFrames_.push_back(std::move(created));
  KeyFrame* kf = keyFrames_.back().get();
  kf->setMapId(active_);
  // A map's first keyframe is its root: never culled, and the gauge its BA keeps fixed.
  if (!hasKeyFrame_[active_]) {
    hasKeyFrame_[active_] = 1;
    kf->setMapRoot(true);
  }
  return kf;
}

MapPoint* Map::createMapPoint(const Eigen::Vector3d& position, KeyFrame* reference, std::uint64_t frameIndex) {
  const MapPointId id = points_.size();
  points_.push_back(std::make_unique<MapPoint>(id, position, reference, reference ? reference->id : 0, frameIndex));
  return points_.back().get();
}

std::vector<KeyFrame*> Map::keyFrames() const {
  std::vector<KeyFrame*> out;
  out.reserve(keyFrames_.size());
  for (const auto& kf : keyFrames_)
    if (!kf->isBad()) out.push_back(kf.get());
  return out;
}

std::vector<MapPoint*> Map::mapPoints() const {
  std::vector<MapPoint*> out;
  out.reserve(points_.size());
  for (const auto& p : points_)
    if (!p->isBad()) out.push_back(p.get());
  return out;
}

std::size_t Map::keyFrameCount() const {
  std::size_t n = 0;
  for (const auto& kf : keyFrames_) n += kf->isBad() ? 0 : 1;
  return n;
}

std::uint32_t Map::startNewMap(std::uint64_t frameIndex) {
  const auto id = static_cast<std::uint32_t>(records_.size());
  records_.push_back({id, frameIndex, std::nullopt});
  hasKeyFrame_.push_back(0);
  active_ = id;
  return id;
}

namespace {
std::uint32_t mapOfPoint(const MapPoint& p) {
  if (const KeyFrame* r = p.reference()) return r->mapId();
  return p.observations().empty() ? 0 : p.observations().begin()->first->mapId();
}
}  // namespace

std::vector<KeyFrame*> Map::keyFrames(std::uint32_t mapId) const {
  std::vector<KeyFrame*> out;
  for (const auto& kf : keyFrames_)
    if (!kf->isBad() && kf->mapId() == mapId) out.push_back(kf.get());
  return out;
}

std::vector<MapPoint*> Map::mapPoints(std::uint32_t mapId) const {
  std::vector<MapPoint*> out;
  for (const auto& p : points_)
    if (!p->isBad() && mapOfPoint(*p) == mapId) out.push_back(p.get());
  return out;
}

std::size_t Map::keyFrameCount(std::uint32_t mapId) const {
  std::size_t n = 0;
  for (const auto& kf : keyFrames_) n += !kf->isBad() && kf->mapId() == mapId ? 1 : 0;
  return n;
}

std::size_t Map::mapPointCount(std::uint32_t mapId) const {
  std::size_t n = 0;
  for (const auto& p : points_) n += !p->isBad() && mapOfPoint(*p) == mapId ? 1 : 0;
  return n;
}

void Map::mergeInto(std::uint32_t from, std::uint32_t into, double scale) {
  for (const auto& kf : keyFrames_)
    if (kf->mapId() == from) {
      kf->setMapId(into);
      kf->setGauge(false);
    }
  records_.at(from).mergedInto = into;
  merges_.push_back({from, into, scale});
  if (active_ == from) active_ = into;
}

bool Map::mapLeadsTo(std::uint32_t trackedIn, std::uint32_t mapId) const {
  // Each map is merged at most once, so the chain of merges ends; the bound guards a bad record.
  for (std::size_t step = 0; step <= records_.size(); ++step) {
    if (trackedIn == mapId) return true;
    if (trackedIn >= records_.size() || !records_[trackedIn].mergedInto) return false;
    trackedIn = *records_[trackedIn].mergedInto;
  }
  return false;
}

void Map::restoreAtlas(std::vector<AtlasMapRecord> records, std::uint32_t active) {
  records_ = std::move(records);
  if (records_.empty()) records_.push_back({});
  hasKeyFrame_.assign(records_.size(), 0);
  for (const auto& kf : keyFrames_)
    if (kf->mapId() < hasKeyFrame_.size()) hasKeyFrame_[kf->mapId()] = 1;
  active_ = active < records_.size() ? active : 0;
}

std::size_t Map::mapPointCount() const {
  std::size_t n = 0;
  for (const auto& p : points_) n += p->isBad() ? 0 : 1;
  return n;
}

}  // namespace orbis
