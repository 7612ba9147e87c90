#include "orbis/map/map.hpp"

namespace orbis {

KeyFrame* Map::createKeyFrame(std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
                              std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
                              bow::BowVector bowVector, bow::FeatureVector featureVector) {
  const KeyFrameId id = keyFrames_.size();
  keyFrames_.push_back(std::make_unique<KeyFrame>(id, frameIndex, timestamp, Tcw, std::move(features), intrinsics,
                                                  std::move(bowVector), std::move(featureVector)));
  return keyFrames_.back().get();
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

std::size_t Map::mapPointCount() const {
  std::size_t n = 0;
  for (const auto& p : points_) n += p->isBad() ? 0 : 1;
  return n;
}

}  // namespace orbis
