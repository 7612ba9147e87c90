// python/src/trajectories.cpp — trajectory files to and from N x 8 NumPy arrays.
//
// Contract: read_trajectory(path, format=None, times=None) is orbis::readTrajectory (format
// detected as `orbis eval` does when None; KITTI times from a times.txt file or the frame index)
// and returns (N, 8) float64 TUM rows t x y z qx qy qz qw, camera-to-world. write_trajectory
// writes such rows in 'tum', 'kitti' or 'euroc' form with the library's writer. A bad format name
// raises ValueError, a missing file MissingFileError, a malformed one orbis.Error naming the line.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "errors.hpp"

namespace orbis::python {

using namespace pybind11::literals;

std::string formatArgument(const std::optional<std::string>& format) {
  if (!format) return "";
  if (*format != "tum" && *format != "kitti" && *format != "euroc")
    throw py::value_error("format: expected 'tum', 'kitti' or 'euroc', got '" + *format + "'");
  return *format;
}

void bindTrajectories(py::module_& m) {
  m.def(
      "read_trajectory",
      [](const py::handle& path, std::optional<std::string> format, std::optional<std::string> times) {
        return trajectoryToArray(trajectoryArgument(path, "path", formatArgument(format), times.value_or("")));
      },
      "path"_a, "format"_a = py::none(), "times"_a = py::none(),
      "Reads a TUM, KITTI or EuRoC trajectory file into (N, 8) float64 rows t x y z qx qy qz qw.\n"
      "format None detects it; times: a KITTI times.txt (default: the frame index).");
  m.def(
      "write_trajectory",
      [](const std::filesystem::path& path, const py::handle& rows, const std::string& format) {
        const Trajectory trajectory = trajectoryFromArray(rows, "trajectory");
        const TrajectoryFormat f = parseTrajectoryFormat(formatArgument(format), "format");
        py::gil_scoped_release release;
        writeTrajectory(path, trajectory, f);
      },
      "path"_a, "trajectory"_a, "format"_a = "tum",
      "Writes (N, 8) rows t x y z qx qy qz qw as a 'tum', 'kitti' or 'euroc' trajectory file.");
}

}  // namespace orbis::python
