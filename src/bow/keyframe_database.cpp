#include "orbis/bow/keyframe_database.hpp"

namespace orbis::bow {

void KeyframeDatabase::unindex(std::uint32_t slot) {
  for (const WordEntry& e : slots_[slot].bow) {
    auto& list = inverted_[e.word];
    if (auto it = std::find(list.begin(), list.end(), slot); it != list.end()) {
      // Order inside a word's list is irrelevant (queries sort the slots they touch).
      *it = list.back();
      list.pop_back();
    }
  }
}

void KeyframeDatabase::add(KeyframeId id, const BowVector& bow) {
  std::unique_lock lock(mutex_);
  std::uint32_t slot;
  if (auto it = index_.find(id); it != index_.end()) {
    slot = it->second;
    unindex(slot);
  } else if (!freeSlots_.empty()) {
    slot = freeSlots_.back();
    freeSlots_.pop_back();
    index_.emplace(id, slot);
  } else {
    slot = static_cast<std::uint32_t>(slots_.size());
    slots_.emplace_back();
    index_.emplace(id, slot);
  }
  slots_[slot] = Slot{id, bow};
  if (!bow.empty() && bow.entries().back().word >= inverted_.size()) inverted_.resize(bow.entries().back().word + 1);
  for (const WordEntry& e : bow) inverted_[e.word].push_back(slot);
}

bool KeyframeDatabase::erase(KeyframeId id) {
  std::unique_lock lock(mutex_);
  auto it = index_.find(id);
  if (it == index_.end()) return false;
  const std::uint32_t slot = it->second;
  unindex(slot);
  slots_[slot] = Slot{};
  freeSlots_.push_back(slot);
  index_.erase(it);
  return true;
}

void KeyframeDatabase::clear() {
  std::unique_lock lock(mutex_);
  slots_.clear();
  freeSlots_.clear();
  index_.clear();
  inverted_.clear();
}

std::size_t KeyframeDatabase::size() const {
  std::shared_lock lock(mutex_);
  return index_.size();
}

bool KeyframeDatabase::contains(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  return index_.count(id) != 0;
}

std::optional<BowVector> KeyframeDatabase::bowVector(KeyframeId id) const {
  std::shared_lock lock(mutex_);
  auto it = index_.find(id);
  if (it == index_.end()) return std::nullopt;
  return slots_[it->second].bow;
}

}  // namespace orbis::bow
