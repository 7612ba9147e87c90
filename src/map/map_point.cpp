#include "orbis/map/map_point.hpp"

#include <algorithm>
#include <cmath>

#include "orbis/map/key_frame.hpp"

namespace orbis {

namespace {
bool isStereoObservation(const KeyFrame* kf, std::size_t index) { return kf->features().uRight[index] >= 0; }
}  // namespace

std::size_t ObservationList::find(KeyFrameId id) const {
  const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
  return it != ids_.end() && *it == id ? static_cast<std::size_t>(it - ids_.begin()) : ids_.size();
}

bool ObservationList::insert(KeyFrame* kf, KeyFrameId id, std::size_t index) {
  const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
  if (it != ids_.end() && *it == id) return false;
  const auto at = it - ids_.begin();
  entries_.insert(entries_.begin() + at, {kf, index});
  ids_.insert(it, id);
  return true;
}

void ObservationList::erase(std::size_t k) {
  const auto at = static_cast<std::ptrdiff_t>(k);
  entries_.erase(entries_.begin() + at);
  ids_.erase(ids_.begin() + at);
}

void ObservationList::clear() {
  entries_.clear();
  ids_.clear();
}

bool MapPoint::isObservedBy(const KeyFrame* kf) const { return observations_.find(kf->id) != observations_.size(); }

long MapPoint::indexIn(const KeyFrame* kf) const {
  const std::size_t k = observations_.find(kf->id);
  return k == observations_.size() ? -1 : static_cast<long>(observations_.entries_[k].second);
}

void MapPoint::addObservation(KeyFrame* kf, std::size_t index) {
  if (observations_.insert(kf, kf->id, index)) observationCount_ += isStereoObservation(kf, index) ? 2 : 1;
}

bool MapPoint::eraseObservation(KeyFrame* kf) {
  const std::size_t k = observations_.find(kf->id);
  if (k == observations_.size()) return false;
  observationCount_ -= isStereoObservation(kf, observations_.entries_[k].second) ? 2 : 1;
  observations_.erase(k);
  if (reference_ == kf) reference_ = observations_.empty() ? nullptr : observations_.begin()->first;
  if (observationCount_ <= 2 && !bad_) {
    setBad();
    return true;
  }
  return false;
}

void MapPoint::setBad() {
  bad_ = true;
  for (const auto& [kf, index] : observations_) kf->erasePoint(index);
  observations_.clear();
  observationCount_ = 0;
}

void MapPoint::replaceWith(MapPoint* other) {
  if (other == this || other == nullptr) return;
  for (const auto& [kf, index] : observations_) {
    if (!other->isObservedBy(kf)) {
      kf->setPoint(index, other);
      other->addObservation(kf, index);
    } else {
      kf->erasePoint(index);
    }
  }
  other->increaseFound(found_);
  other->increaseVisible(visible_);
  other->computeDistinctiveDescriptor();
  observations_.clear();
  observationCount_ = 0;
  bad_ = true;
  replacedBy_ = other;
}

void MapPoint::computeDistinctiveDescriptor() {
  if (bad_ || observations_.empty()) return;
  std::vector<const OrbDescriptor*> ds;
  ds.reserve(observations_.size());
  for (const auto& [kf, index] : observations_)
    if (!kf->isBad()) ds.push_back(&kf->features().descriptors[index]);
  if (ds.empty()) return;
  const std::size_t n = ds.size();
  std::vector<int> dist(n * n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) dist[i * n + j] = dist[j * n + i] = hammingDistance(*ds[i], *ds[j]);
  int bestMedian = INT32_MAX;
  std::size_t best = 0;
  std::vector<int> row(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(dist.begin() + static_cast<long>(i * n), dist.begin() + static_cast<long>((i + 1) * n), row.begin());
    std::nth_element(row.begin(), row.begin() + static_cast<long>((n - 1) / 2), row.end());
    const int median = row[(n - 1) / 2];
    if (median < bestMedian) {
      bestMedian = median;
      best = i;
    }
  }
  descriptor_ = *ds[best];
}

void MapPoint::updateNormalAndDepth() {
  if (bad_ || observations_.empty() || reference_ == nullptr) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& [kf, index] : observations_) {
    const Eigen::Vector3d dir = position_ - kf->cameraCenter();
    const double len = dir.norm();
    if (len > 0) {
      normal += dir / len;
      ++n;
    }
  }
  const long refIndex = indexIn(reference_);
  if (refIndex < 0) return;
  const auto& levels = reference_->features().scales;
  const int octave = reference_->features().keypointsUn[static_cast<std::size_t>(refIndex)].octave;
  const float dist = static_cast<float>((position_ - reference_->cameraCenter()).norm());
  const float levelScale = levels.scale[static_cast<std::size_t>(octave)];
  maxDistance_ = dist * levelScale;
  minDistance_ = maxDistance_ / levels.scale.back();
  if (n > 0) normal_ = normal / static_cast<double>(n);
}

int MapPoint::predictScale(float distance, int levels, float logScaleFactor) const {
  const float ratio = maxDistance_ / distance;
  int level = static_cast<int>(std::ceil(std::log(ratio) / logScaleFactor));
  return std::clamp(level, 0, levels - 1);
}

}  // namespace orbis
