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
// copied), in the storage prepared after the previous keep() when it is large enough (else the
// copy allocates as usual). Then it starts preparing the next storage on its thread, sized for
// `built` with some margin. One owner calls keep() (not thread-safe). The values never depend
// on the preparation: deterministic runs stay deterministic.
#pragma once

#include <cstddef>

#include "orbis/features/frame_features.hpp"
#include "orbis/util/helper_thread.hpp"

namespace orbis {

// Features copied into memory prepared off the frame's critical path (see the header comment).
class FeatureStorageReserve {
 public:
  FeatureStorageReserve() = default;
  FeatureStorageReserve(const FeatureStorageReserve&) = delete;
  FeatureStorageReserve& operator=(const FeatureStorageReserve&) = delete;
  ~FeatureStorageReserve() { helper_.join(); }  // the job writes spare_, which goes after this

  // `built`, copied into the prepared storage; starts preparing the next.
  FrameFeatures keep(const FrameFeatures& built) {
    helper_.join();  // prepared during the last frame period: normally long done
    FrameFeatures kept = std::move(spare_);
    kept = built;  // copy assignment reuses each array's capacity
    const std::size_t n = built.size() + built.size() / 8 + 64;
    helper_.run([this, n] { spare_ = prepared(n); });
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

  FrameFeatures spare_;
  HelperThread helper_;
};

}  // namespace orbis
