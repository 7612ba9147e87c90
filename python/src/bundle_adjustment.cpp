// python/src/bundle_adjustment.cpp — "Bundle Adjustment in the Large" problems and orbis's solver.
//
// Contract: BalProblem holds BAL's cameras (N x 9: angle-axis, translation, f, k1, k2), points
// (M x 3) and observations (K camera indices, K point indices, K x 2 pixels); read_bal /
// BalProblem.write use the library's BAL reader and writer, and a BalProblem can be built from
// arrays (indices checked: ValueError). solve_bal(problem, ...) solves it in place exactly as
// `orbis ba` (Levenberg-Marquardt, Huber loss on pixels, Schur complement) with the GIL released,
// and returns the summary as a dict: initial_cost, final_cost (Ceres' 1/2 sum rho), iterations,
// successful_steps, termination, sparse, seconds.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <chrono>

#include "bindings.hpp"
#include "errors.hpp"
#include "orbis/io/bal.hpp"
#include "orbis/optim/bal.hpp"

namespace orbis::python {

using namespace pybind11::literals;

namespace {

using Rows = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Indices = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

template <int Columns, class Vector>
py::array_t<double> rowsToArray(const std::vector<Vector>& rows) {
  py::array_t<double> out({static_cast<py::ssize_t>(rows.size()), py::ssize_t{Columns}});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int c = 0; c < Columns; ++c) a(static_cast<py::ssize_t>(i), c) = rows[i][c];
  return out;
}

template <int Columns, class Vector>
std::vector<Vector> rowsFromArray(const Rows& array, const char* argument) {
  if (array.ndim() != 2 || array.shape(1) != Columns)
    throw py::value_error(std::string(argument) + ": expected shape (N, " + std::to_string(Columns) + ")");
  std::vector<Vector> out(static_cast<std::size_t>(array.shape(0)));
  auto a = array.unchecked<2>();
  for (std::size_t i = 0; i < out.size(); ++i)
    for (int c = 0; c < Columns; ++c) out[i][c] = a(static_cast<py::ssize_t>(i), c);
  return out;
}

// Assigns new values to existing rows (cameras or points); their number is fixed by the observations.
template <int Columns, class Vector>
void replaceRows(std::vector<Vector>& rows, const Rows& array, const char* argument) {
  auto replacement = rowsFromArray<Columns, Vector>(array, argument);
  if (replacement.size() != rows.size()) throw py::value_error(std::string(argument) + ": the count cannot change");
  rows = std::move(replacement);
}

std::vector<BalObservation> observationsFromArrays(const Indices& cameras, const Indices& points, const Rows& pixels,
                                                   std::size_t cameraCount, std::size_t pointCount) {
  const py::ssize_t n = cameras.size();
  if (cameras.ndim() != 1 || points.ndim() != 1 || points.size() != n || pixels.ndim() != 2 ||
      pixels.shape(0) != n || pixels.shape(1) != 2)
    throw py::value_error("observations: expected camera_index (K,), point_index (K,) and pixels (K, 2)");
  std::vector<BalObservation> out(static_cast<std::size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    const std::int64_t c = cameras.at(i), p = points.at(i);
    if (c < 0 || static_cast<std::size_t>(c) >= cameraCount || p < 0 || static_cast<std::size_t>(p) >= pointCount)
      throw py::value_error("observation " + std::to_string(i) + ": camera or point index out of range");
    out[static_cast<std::size_t>(i)] = {static_cast<int>(c), static_cast<int>(p), pixels.at(i, 0), pixels.at(i, 1)};
  }
  return out;
}

py::dict solve(BalProblem& problem, double huber, int maxIterations, double functionTolerance,
               const std::string& linearSolver) {
  if (!(huber > 0)) throw py::value_error("huber: expected a positive threshold in pixels");
  optim::SolverOptions options;
  options.maxIterations = maxIterations;
  options.functionTolerance = functionTolerance;
  if (linearSolver == "dense") options.linearSolver = optim::LinearSolverKind::DenseCholesky;
  else if (linearSolver == "sparse") options.linearSolver = optim::LinearSolverKind::SparseCholesky;
  else if (linearSolver != "auto") throw py::value_error("linear_solver: expected 'auto', 'dense' or 'sparse'");
  optim::SolverSummary summary;
  double seconds = 0;
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    summary = optim::solveBal(problem, options, huber);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return py::dict("initial_cost"_a = summary.initialCost, "final_cost"_a = summary.finalCost,
                  "iterations"_a = summary.iterations, "successful_steps"_a = summary.successfulSteps,
                  "termination"_a = optim::toString(summary.termination), "sparse"_a = summary.usedSparseSolver,
                  "seconds"_a = seconds);
}

}  // namespace

void bindBundleAdjustment(py::module_& m) {
  py::class_<BalProblem>(m, "BalProblem", "A BAL bundle-adjustment problem (cameras, points, observations).")
      .def(py::init([](const Rows& cameras, const Rows& points, const Indices& cameraIndex, const Indices& pointIndex,
                       const Rows& pixels) {
             BalProblem p;
             p.cameras = rowsFromArray<9, BalProblem::Camera>(cameras, "cameras");
             p.points = rowsFromArray<3, Eigen::Vector3d>(points, "points");
             p.observations = observationsFromArrays(cameraIndex, pointIndex, pixels, p.cameras.size(), p.points.size());
             return p;
           }),
           "cameras"_a, "points"_a, "camera_index"_a, "point_index"_a, "pixels"_a)
      .def_property(
          "cameras", [](const BalProblem& p) { return rowsToArray<9>(p.cameras); },
          [](BalProblem& p, const Rows& a) { replaceRows<9>(p.cameras, a, "cameras"); },
          "(N, 9) float64: angle-axis (3), translation (3), f, k1, k2 (a copy; assign to change).")
      .def_property(
          "points", [](const BalProblem& p) { return rowsToArray<3>(p.points); },
          [](BalProblem& p, const Rows& a) { replaceRows<3>(p.points, a, "points"); },
          "(M, 3) float64 (a copy; assign to change).")
      .def_property_readonly(
          "observations",
          [](const BalProblem& p) {
            const auto n = static_cast<py::ssize_t>(p.observations.size());
            py::array_t<std::int64_t> cameras(n), points(n);
            py::array_t<double> pixels({n, py::ssize_t{2}});
            for (py::ssize_t i = 0; i < n; ++i) {
              const BalObservation& o = p.observations[static_cast<std::size_t>(i)];
              cameras.mutable_at(i) = o.camera, points.mutable_at(i) = o.point;
              pixels.mutable_at(i, 0) = o.x, pixels.mutable_at(i, 1) = o.y;
            }
            return py::make_tuple(cameras, points, pixels);
          },
          "(camera_index (K,), point_index (K,), pixels (K, 2)).")
      .def("write", [](const BalProblem& p, const std::filesystem::path& path) { writeBal(path, p); }, "path"_a)
      .def("__repr__", [](const BalProblem& p) {
        return "BalProblem(cameras=" + std::to_string(p.cameras.size()) + ", points=" + std::to_string(p.points.size()) +
               ", observations=" + std::to_string(p.observations.size()) + ")";
      });
  m.def(
      "read_bal",
      [](const std::filesystem::path& path) {
        requireFile(path);
        py::gil_scoped_release release;
        return readBal(path);
      },
      "path"_a, "Reads a BAL problem file (problem-*.txt).");
  m.def("solve_bal", &solve, "problem"_a, "huber"_a = 1.0, "max_iterations"_a = 50, "function_tolerance"_a = 1e-6,
        "linear_solver"_a = "auto", "Solves in place as `orbis ba`; returns the summary dict.");
}

}  // namespace orbis::python
