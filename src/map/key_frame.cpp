#include "orbis/map/key_frame.hpp"

#include <algorithm>
#include <functional>
#include <utility>

namespace orbis {

KeyFrame::KeyFrame(KeyFrameId id, std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
                   std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
                   bow::BowVector bowVector, bow::FeatureVector featureVector)
    : id(id),
      frameIndex(frameIndex),
      timestamp(timestamp),
      intrinsics(intrinsics),
      features_(std::move(features)),
      bow_(std::move(bowVector)),
      featureVector_(std::move(featureVector)),
      Tcw_(Tcw),
      points_(features_->size(), nullptr),
      occupied_((points_.size() + 63) / 64, 0) {}

KeyFrame::KeyFrame(KeyFrameId id, std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
                   std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
                   BowComputation computeBow)
    : KeyFrame(id, frameIndex, timestamp, Tcw, std::move(features), intrinsics, {}, {}) {
  pendingBow_ = std::move(computeBow);
}

void KeyFrame::ensureBow() const {
  std::call_once(bowOnce_, [this] {
    if (!pendingBow_) return;
    pendingBow_(*features_, bow_, featureVector_);
    pendingBow_ = nullptr;
  });
}

void KeyFrame::erasePoint(const MapPoint* p) {
  forEachOccupiedSlot([&](std::size_t i) {
    if (points_[i] == p) erasePoint(i);
  });
}

int KeyFrame::trackedPoints(int minObservations) const {
  int n = 0;
  forEachPoint([&](const MapPoint* p) {
    if (!p->isBad() && (minObservations <= 0 || p->observationCount() >= minObservations)) ++n;
  });
  return n;
}

std::vector<MapPoint*> KeyFrame::goodPoints() const {
  std::vector<MapPoint*> out;
  forEachPoint([&](MapPoint* p) {
    if (!p->isBad()) out.push_back(p);
  });
  std::sort(out.begin(), out.end(), ById{});
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void KeyFrame::addConnection(KeyFrame* kf, int weight) {
  auto [it, inserted] = connectedWeights_.emplace(kf, weight);
  if (!inserted) {
    if (it->second == weight) return;
    it->second = weight;
  }
  updateBestCovisibles();
}

void KeyFrame::eraseConnection(KeyFrame* kf) {
  if (connectedWeights_.erase(kf)) updateBestCovisibles();
}

int KeyFrame::weight(const KeyFrame* kf) const {
  const auto it = connectedWeights_.find(const_cast<KeyFrame*>(kf));
  return it == connectedWeights_.end() ? 0 : it->second;
}

void KeyFrame::updateBestCovisibles() {
  std::vector<std::pair<int, KeyFrame*>> byWeight;
  byWeight.reserve(connectedWeights_.size());
  for (const auto& [kf, w] : connectedWeights_) byWeight.emplace_back(w, kf);
  std::sort(byWeight.begin(), byWeight.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second->id < b.second->id;
  });
  orderedConnected_.clear();
  orderedWeights_.clear();
  for (const auto& [w, kf] : byWeight) {
    orderedConnected_.push_back(kf);
    orderedWeights_.push_back(w);
  }
}

std::vector<KeyFrame*> KeyFrame::bestCovisibles(std::size_t n) const {
  return {orderedConnected_.begin(), orderedConnected_.begin() + static_cast<long>(std::min(n, orderedConnected_.size()))};
}

std::vector<KeyFrame*> KeyFrame::covisiblesWithWeightAtLeast(int w) const {
  std::vector<KeyFrame*> out;
  for (std::size_t i = 0; i < orderedConnected_.size() && orderedWeights_[i] >= w; ++i) out.push_back(orderedConnected_[i]);
  return out;
}

std::set<KeyFrame*, ById> KeyFrame::connectedSet() const {
  std::set<KeyFrame*, ById> s;
  for (const auto& [kf, w] : connectedWeights_) s.insert(kf);
  return s;
}

void KeyFrame::updateConnections() {
  std::map<KeyFrame*, int, ById> counter;
  for (MapPoint* p : points_) {
    if (!p || p->isBad()) continue;
    for (const auto& [kf, index] : p->observations())
      if (kf != this && !kf->isBad()) ++counter[kf];
  }
  if (counter.empty()) return;
  KeyFrame* best = nullptr;
  int bestWeight = 0;
  std::map<KeyFrame*, int, ById> kept;
  for (const auto& [kf, w] : counter) {
    if (w > bestWeight) {  // ties keep the lowest id: map iterates by id
      bestWeight = w;
      best = kf;
    }
    if (w >= kCovisibilityThreshold) {
      kept.emplace(kf, w);
      kf->addConnection(this, w);
    }
  }
  // ORB-SLAM keeps at least the strongest neighbour even below the threshold.
  if (kept.empty()) {
    kept.emplace(best, bestWeight);
    best->addConnection(this, bestWeight);
  }
  connectedWeights_ = std::move(kept);
  updateBestCovisibles();
  if (firstConnection_ && !mapRoot_) {  // a map's root stays the root of its spanning tree
    parent_ = orderedConnected_.front();
    parent_->addChild(this);
    firstConnection_ = false;
  }
}

void KeyFrame::changeParent(KeyFrame* parent) {
  if (parent == this) return;
  if (parent_) parent_->eraseChild(this);
  parent_ = parent;
  parent->addChild(this);
  // A keyframe with a parent is in the tree: its next updateConnections() must not re-parent it
  // behind the old parent's back (keyframes restored from a map file come through here).
  firstConnection_ = false;
}

bool KeyFrame::setBad() {
  if (mapRoot_ || protected_ || bad_) return false;
  for (const auto& [kf, w] : connectedWeights_) kf->eraseConnection(this);
  forEachOccupiedSlot([&](std::size_t i) {
    // A point turning bad below detaches itself from this keyframe too, emptying slots ahead.
    if (MapPoint* p = points_[i]) {
      erasePoint(i);
      p->eraseObservation(this);
    }
  });
  connectedWeights_.clear();
  orderedConnected_.clear();
  orderedWeights_.clear();

  // Re-attach the children: repeatedly pick the child with the strongest covisibility link to a
  // keyframe already in the tree (the parent, or children re-attached before it).
  std::set<KeyFrame*, ById> candidates;
  if (parent_) candidates.insert(parent_);
  while (!children_.empty()) {
    KeyFrame* bestChild = nullptr;
    KeyFrame* bestParent = nullptr;
    int bestWeight = -1;
    for (KeyFrame* child : children_) {
      if (child->isBad()) continue;
      for (KeyFrame* neighbour : child->covisibles()) {
        if (!candidates.count(neighbour)) continue;
        const int w = child->weight(neighbour);
        if (w > bestWeight) {
          bestWeight = w;
          bestChild = child;
          bestParent = neighbour;
        }
      }
    }
    if (!bestChild) break;
    bestChild->changeParent(bestParent);
    candidates.insert(bestChild);
    children_.erase(bestChild);
  }
  // Children with no covisibility link to the tree hang from the original parent.
  const auto orphans = children_;
  for (KeyFrame* child : orphans)
    if (parent_) child->changeParent(parent_);
  children_.clear();
  if (parent_) {
    parent_->eraseChild(this);
    Tcp_ = Tcw_ * parent_->Tcw().inverse();
  }
  bad_ = true;
  return true;
}

std::vector<int> KeyFrame::featuresInArea(float u, float v, float r) const {
  return features_->grid.featuresInArea(u, v, r);
}

std::vector<MapPoint*> distinctGoodPoints(const std::vector<KeyFrame*>& keyFrames) {
  std::vector<MapPoint*> met;
  for (const KeyFrame* kf : keyFrames)
    kf->forEachPoint([&](MapPoint* p) {
      if (!p->isBad()) met.push_back(p);
    });
  // (point, position met) sorted: the first of each run of one point is its first meeting.
  std::vector<std::pair<MapPoint*, std::size_t>> byPoint(met.size());
  for (std::size_t i = 0; i < met.size(); ++i) byPoint[i] = {met[i], i};
  std::sort(byPoint.begin(), byPoint.end(), [](const auto& a, const auto& b) {
    return std::less<MapPoint*>{}(a.first, b.first) || (a.first == b.first && a.second < b.second);
  });
  std::vector<char> first(met.size(), 0);
  for (std::size_t k = 0; k < byPoint.size(); ++k)
    if (k == 0 || byPoint[k].first != byPoint[k - 1].first) first[byPoint[k].second] = 1;
  std::vector<MapPoint*> out;
  for (std::size_t i = 0; i < met.size(); ++i)
    if (first[i]) out.push_back(met[i]);
  return out;
}

}  // namespace orbis
