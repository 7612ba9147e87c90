// src/viewer/scene_json.hpp — the frame message LiveViewer streams to its page (the map
// messages: map_delta.hpp).
//
// Contract: frameMessage: {"index","t","state","newKeyFrame","inliers","width","height",
// "ms":{"extraction","tracking"},"Twc":[12, row-major 3x4] or null,"keypoints":[x,y,state,...],
// "image":base64 JPEG or null} with state 0 unmatched, 1 matched, 2 new, 3 outlier; keypoints in
// the pixels of the full image (width x height), which the JPEG may show scaled down. Camera
// coordinates as orbis keeps them (x right, y down, z forward), metres.
#pragma once

#include <string>
#include <string_view>

#include "orbis/viewer/slam_observer.hpp"

namespace orbis::viewer_detail {

std::string frameMessage(const FrameSnapshot& frame, std::string_view jpegBase64 = {});

}  // namespace orbis::viewer_detail
