// orbis/features/feature_storage.hpp — a frame's features moved into storage that a helper
// thread allocated and wrote between frames.
//
// Why: a frame that becomes a keyframe keeps its features for the map's lifetime, so every
// keyframe takes new memory, and a page touched for the first time costs a page fault (about
// 11 µs each on the 2-core VM the benchmarks run on; 100 KB is about 25 pages). Built in the
// tracking thread, those faults land inside the frame's call; copied into storage prepared
// beforehand by another thread, they land outside it, and the tracking thread's own buffers are
// freed and reused by the next frame. docs/notes/2026-11-29-speed-page-faults.md.
//
// Contract: keep(built) returns a FrameFeatures equal to `built` (every array and the grid
// copied), in storage prepared beforehand when there is some (else the copy allocates as usual;
// a prepared array too small grows as usual). Storage is prepared kBatch at a time on the helper
// thread, sized for the frame that used up the last batch with some margin, so the helper is
// woken once every kBatch frames: waking it costs the caller about 50 us on the 2-core VM, more
// than the copy (same note). One owner calls keep() (not thread-safe). The values never depend
// on the preparation: deterministic runs stay deterministic.
#pragma once

#include <cstddef>
#include <vector>

#include "orbis/features/frame_features.hpp"
#include "orbis/util/helper_thread.hpp"

namespace orbis {

// Features copied into memory prepared off the frame's critical path (see the header comment).
class FeatureStorageReserve {
 public:
  FeatureStorageReserve() = default;
  FeatureStorageReserve(const FeatureStorageReserve&) = delete;
  FeatureStorageReserve& operator=(const FeatureStorageReserve&) = delete;
  ~FeatureStorageReserve() { helper_.join(); }  // the job writes incoming_, which goes after this

  // Prepared storages per wake of the helper.
  static constexpr std::size_t kBatch = 4;

  // `built`, copied into prepared storage; starts preparing the next batch when none is left.
  FrameFeatures keep(const FrameFeatures& built) {
    if (spares_.empty()) {
      helper_.join();  // the batch started kBatch - 1 frames ago: normally long done
      spares_.swap(incoming_);  // empty before the first batch
    }
    FrameFeatures kept;
    if (!spares_.empty()) {
      kept = std::move(spares_.back());
      spares_.pop_back();
    }
    kept = built;  // copy assignment reuses each array's capacity
    if (spares_.empty()) {
      const std::size_t n = built.size() + built.size() / 8 + 64;
      helper_.run([this, n] {  // incoming_ is empty: it was swapped with the used-up spares_
        for (std::size_t i = 0; i < kBatch; ++i) incoming_.push_back(prepared(n));
      });
    }
    return kept;
  }

  // Empty features whose arrays have room for n keypoints, every page written once.
  static FrameFeatures prepared(std::size_t n) {
    FrameFeatures f;
    touch(f.keypoints, n);
    touch(f.keypointsUn, n);
    touch(f.descriptors, n);
    touch(f.uRight, n);
    touch(f.depth, n);
    f.grid.reserve(n);
    return f;
  }

 private:
  template <class T>
  static void touch(std::vector<T>& v, std::size_t n) {
    v.resize(n);  // value-initialises, so every page is written (faulted in) here
    v.clear();    // keeps the capacity
  }

  std::vector<FrameFeatures> spares_;    // prepared, ready for keep()
  std::vector<FrameFeatures> incoming_;  // written by the helper's job between run() and join()
  HelperThread helper_;
};

}  // namespace orbis
