// orbis/io/trajectory.hpp — stamped camera trajectories and their three file formats.
//
// Contract: a Trajectory is a time-ordered list of camera-to-world poses (T_wc, so
// pose.translation() is the camera centre in world coordinates), timestamps in seconds.
// Readers accept the benchmarks' own layouts:
//   TUM    "t tx ty tz qx qy qz qw" (whitespace separated, '#' comments);
//   KITTI  12 numbers per line, the 3x4 matrix [R|t] row-major; timestamps come from a
//          times file (one number per line, same count) or are the frame index 0,1,2,...;
//   EuRoC  csv "t_ns, px, py, pz, qw, qx, qy, qz[, ignored columns...]", '#' header.
// Quaternions are normalised on reading, rotation matrices re-orthonormalised. A malformed
// line, a non-finite number or a zero quaternion throws orbis::Error naming the file and the
// line. Published files repeat timestamps (TUM fr2/desk's ground truth) or list rows out of
// order: TUM and EuRoC rows are sorted by time and, of rows with equal timestamps, the first is
// kept, as evo does; each kind of repair is one warning with its count (put in `warnings`, or
// printed on stderr when none is given). KITTI times files must increase strictly (a row is a
// frame index). Writers throw orbis::Error naming the path when it cannot be written. Timestamps are doubles: EuRoC nanoseconds survive a round
// trip to within ~0.3 microseconds at present-day epochs.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "orbis/geometry/se3.hpp"

namespace orbis {

// A pose with its timestamp.
struct StampedPose {
  double t = 0.0;  // seconds
  SE3d pose;       // camera-to-world
};
// A trajectory: poses in time order.
using Trajectory = std::vector<StampedPose>;

// The trajectory file formats: TUM (t x y z qx qy qz qw), KITTI (3×4 row-major) and EuRoC csv.
enum class TrajectoryFormat { Tum, Kitti, Euroc };

// "tum", "kitti" or "euroc"; throws orbis::Error(source) for anything else.
TrajectoryFormat parseTrajectoryFormat(std::string_view name, const std::string& source = "format");
// "tum", "kitti" or "euroc".
std::string_view toString(TrajectoryFormat format);

// Guesses from the first data row: comma-separated (or in a .csv) with integer nanoseconds first
// → EuRoC, else 8 columns → TUM, 12 → KITTI. Throws orbis::Error naming the file when it cannot tell.
TrajectoryFormat detectTrajectoryFormat(const std::filesystem::path& file);

// kittiTimesFile is used only for TrajectoryFormat::Kitti; empty means "frame index".
Trajectory readTrajectory(const std::filesystem::path& file, TrajectoryFormat format,
                          const std::filesystem::path& kittiTimesFile = {},
                          std::vector<std::string>* warnings = nullptr);
// Reads a KITTI times.txt-style file: one timestamp per line, strictly increasing.
std::vector<double> readTimestamps(const std::filesystem::path& file);

// Writes a trajectory in the given format.
void writeTrajectory(const std::filesystem::path& file, const Trajectory& trajectory,
                     TrajectoryFormat format);

// One-to-one association of two increasing timestamp lists, nearest pairs first, within maxDt
// seconds (inclusive), as the TUM benchmark's associate.py does. Returns (index in a, index in
// b) pairs ordered by the index in a.
std::vector<std::pair<std::size_t, std::size_t>> associateTimestamps(const std::vector<double>& a,
                                                                     const std::vector<double>& b,
                                                                     double maxDt);

// The poses of `trajectory` from `span`'s first timestamp minus `marginSeconds` to its last plus
// `marginSeconds` (all of them when `span` is empty): the ground truth an estimate covers, so a
// short run drawn over a whole sequence's ground truth is not a speck in the view.
Trajectory posesCovering(const Trajectory& trajectory, const Trajectory& span, double marginSeconds);

// Rows of a time-stamped file put in time order: `keep` holds the indices of the rows to keep,
// sorted by time (stable, so of equal timestamps the first in the file comes first) with every
// row whose timestamp equals the one kept before it dropped.
struct TimeOrder {
  // The rows to keep, in time order.
  std::vector<std::size_t> keep;
  // @{
  // Rows dropped for a repeated timestamp, and rows earlier than their predecessor.
  std::size_t repeated = 0, outOfOrder = 0;                  // rows dropped / rows earlier than their predecessor
  // @}
  // @{
  // The first line of each kind (1-based; 0 when none).
  std::size_t firstRepeatedLine = 0, firstOutOfOrderLine = 0;  // 1-based lines, 0 when none
  // @}
  // One warning per kind of repair, naming the file, the count and the first line.
  std::vector<std::string> warnings(const std::filesystem::path& file) const;
};
// times[i] was read from line lines[i].
TimeOrder putInTimeOrder(const std::vector<double>& times, const std::vector<std::size_t>& lines);

// ---- Text tables, shared with the dataset adapters ------------------------------------------
// One data row of a text table: its 1-based line number and its fields (split on whitespace
// and commas; blank lines and lines starting with '#' are skipped). The views die with the row.
struct TextRow {
  // The row's line number, 1-based.
  std::size_t line = 0;
  // The row's fields.
  std::span<const std::string_view> fields;
};
// Calls visit for every data row of file; throws orbis::Error when the file cannot be opened.
void forEachTextRow(const std::filesystem::path& file, const std::function<void(const TextRow&)>& visit);
// Parses a field as a finite double / an integer; throws orbis::Error naming file and line.
double parseDouble(std::string_view field, const std::filesystem::path& file, std::size_t line);
// An integer field; throws orbis::Error naming file and line.
long long parseInteger(std::string_view field, const std::filesystem::path& file, std::size_t line);

}  // namespace orbis
