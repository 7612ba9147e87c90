// orbis/map/map_covisibility.hpp — the map's covisibility graph in the shape the keyframe
// database's place queries ask for (bow::CovisibilityGraph).
//
// Contract: a view of a Map, answering by keyframe id; unknown and bad keyframes have no
// neighbours, and bad neighbours are left out. Callers hold Map::mutex() for the query.
#pragma once

#include <vector>

#include "orbis/bow/keyframe_database.hpp"
#include "orbis/map/map.hpp"

namespace orbis {

// The map's covisibility graph as the keyframe database queries it (bow::CovisibilityGraph).
class MapCovisibility {
 public:
  // A view of map.
  explicit MapCovisibility(const Map& map) : map_(map) {}

  // Every good neighbour of a keyframe.
  std::vector<bow::KeyframeId> connectedKeyframes(bow::KeyframeId id) const {
    std::vector<bow::KeyframeId> out;
    if (const KeyFrame* kf = map_.keyFrame(id); kf && !kf->isBad())
      for (const KeyFrame* n : kf->covisibles())
        if (!n->isBad()) out.push_back(n->id);
    return out;
  }

  // Up to n best good neighbours.
  std::vector<bow::KeyframeId> bestCovisibleKeyframes(bow::KeyframeId id, std::size_t n) const {
    std::vector<bow::KeyframeId> out;
    if (const KeyFrame* kf = map_.keyFrame(id); kf && !kf->isBad())
      for (const KeyFrame* c : kf->bestCovisibles(n))
        if (!c->isBad()) out.push_back(c->id);
    return out;
  }

 private:
  const Map& map_;
};

static_assert(bow::CovisibilityGraph<MapCovisibility>);

}  // namespace orbis
