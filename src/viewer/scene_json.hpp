// src/viewer/scene_json.hpp — the frame message LiveViewer streams to its page (the map
// messages: map_delta.hpp).
//
// Contract: frameMessage: {"index","t","state","newKeyFrame","inliers","width","height",
// "ms":{"extraction","tracking","extractionMedian","trackingMedian"} (medians over the last
// RecentTimings::kFrames frames, all of them, not only those sent),"Twc":[12, row-major 3x4] or null,"keypoints":[x,y,state,...],
// "image":base64 JPEG or null} with state 0 unmatched, 1 matched, 2 new, 3 outlier; keypoints in
// the pixels of the full image (width x height), which the JPEG may show scaled down. Camera
// coordinates as orbis keeps them (x right, y down, z forward), metres.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

#include "orbis/viewer/slam_observer.hpp"

namespace orbis::viewer_detail {

struct FrameTimingMedians {
  double extraction = 0, tracking = 0;
};

// The extraction and tracking times of the last kFrames frames: filled for every frame (on the
// tracking thread: two numbers into a ring), read when a message is made.
class RecentTimings {
 public:
  static constexpr std::size_t kFrames = 100;
  void add(double extractionMs, double trackingMs);
  FrameTimingMedians medians() const;

 private:
  std::array<double, kFrames> extraction_{}, tracking_{};
  std::size_t count_ = 0, next_ = 0;
};

std::string frameMessage(const FrameSnapshot& frame, std::string_view jpegBase64 = {},
                         const FrameTimingMedians& medians = {});

}  // namespace orbis::viewer_detail
