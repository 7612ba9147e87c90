// Private helpers shared by the frame sources: timestamp lists, natural name order, stereo
// splitting, the end-of-source bookkeeping.
#pragma once

#include <chrono>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "orbis/adapters/frame_source.hpp"

namespace orbis::sources_detail {

// One timestamp per non-empty, non-comment ('#') line, from its first field: seconds, or
// nanoseconds when any value exceeds 1e11 (no recording is 3000 years long). Throws
// orbis::Error naming the file and line for a field that is not a number.
std::vector<double> readTimestampList(const std::filesystem::path& file);

// a.png < b.png, and digit runs compared as numbers: frame2.png < frame10.png.
bool naturalLess(const std::string& a, const std::string& b);

// The timestamp a file name stands for ("1311868164.363181" seconds, a run of 16+ digits
// nanoseconds), when it is one.
std::optional<double> timestampFromName(const std::string& stem);

// Splits a packed stereo frame into its left and right halves (copies: each half continuous).
// Throws orbis::Error(source) when the frame cannot be halved (an odd width or height).
void splitStereo(SourceFrame& frame, StereoPacking packing, const std::string& source);

inline std::chrono::steady_clock::time_point steadyNow() { return std::chrono::steady_clock::now(); }

// Seconds since the epoch on the system clock: the timestamp of a frame taken on arrival.
double wallClockSeconds();

// "rtsp://...", "http://...", "file://...": opened as a URL, not a path.
bool looksLikeUrl(const std::string& s);
// A GStreamer pipeline description: "v4l2src ! videoconvert ! appsink".
bool looksLikePipeline(const std::string& s);

}  // namespace orbis::sources_detail
