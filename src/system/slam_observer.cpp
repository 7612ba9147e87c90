#include "orbis/viewer/slam_observer.hpp"

#include "orbis/map/map.hpp"

namespace orbis {

MapSnapshot snapshotOfMap(const Map& map) {
  MapSnapshot snapshot;
  const std::vector<KeyFrame*> keyFrames = map.keyFrames();
  snapshot.keyFrames.reserve(keyFrames.size());
  for (const KeyFrame* kf : keyFrames) {
    KeyFrameSnapshot k;
    k.id = kf->id;
    k.frameIndex = kf->frameIndex;
    k.Twc = kf->Twc();
    if (kf->parent()) k.parent = static_cast<std::int64_t>(kf->parent()->id);
    k.mapId = kf->mapId();
    for (const KeyFrame* c : kf->covisiblesWithWeightAtLeast(MapSnapshot::kStrongCovisibility))
      if (c->id > kf->id) k.covisibles.push_back(c->id);  // each edge once
    for (const KeyFrame* l : kf->loopEdges()) k.loopEdges.push_back(l->id);
    snapshot.keyFrames.push_back(std::move(k));
  }
  const std::vector<MapPoint*> points = map.mapPoints();
  snapshot.points.reserve(points.size());
  for (const MapPoint* p : points) snapshot.points.push_back({p->id, p->position().cast<float>(), p->firstKeyFrame});
  return snapshot;
}

}  // namespace orbis
