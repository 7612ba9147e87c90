// src/viewer/scene_json.hpp — the JSON messages LiveViewer streams to its page.
//
// Contract: frameMessage: {"index","t","state","newKeyFrame","inliers","width","height",
// "ms":{"extraction","tracking"},"Twc":[12, row-major 3x4] or null,"keypoints":[x,y,state,...],
// "image":base64 JPEG or null} with state 0 unmatched, 1 matched, 2 new, 3 outlier; keypoints in
// the pixels of the full image (width x height), which the JPEG may show scaled down. mapMessage: {"live","frames",
// "keyFrames":[{"id","frame","parent","Twc":[12],"covisibles":[ids],"loops":[ids]}],
// "points":[x,y,z,firstKeyFrame,inLocalMap,...],"trajectory":[x,y,z,...],
// "loopClosures":[{"current","loop","frame","inliers"}]}. Camera coordinates as orbis keeps
// them (x right, y down, z forward), metres, 4 decimals.
#pragma once

#include <string>
#include <string_view>
#include <unordered_set>

#include "orbis/viewer/slam_observer.hpp"

namespace orbis::viewer_detail {

std::string frameMessage(const FrameSnapshot& frame, std::string_view jpegBase64 = {});
std::string mapMessage(const MapSnapshot& map, const std::unordered_set<MapPointId>& localMap, bool live);

}  // namespace orbis::viewer_detail
