// python/src/evaluation.cpp — ATE, RPE and the KITTI odometry metric, as `orbis eval` computes them.
//
// Contract: each metric takes the ground truth and the estimate as paths (read and format-
// detected as the CLI does; KITTI files may take times files) or (N, 8) TUM-row arrays, and
// returns a result object with the CLI's numbers: ate (default SE(3) alignment), rpe (default no
// alignment), kitti_metric (frame-for-frame when the sizes match and either file is KITTI, else
// associated by time, as `orbis eval kitti`). Bad names raise ValueError; nothing to evaluate
// raises orbis.Error("evaluation"). The GIL is released while the metric is computed.
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "orbis/eval/metrics.hpp"

namespace orbis::python {

using namespace pybind11::literals;

namespace {

eval::Alignment alignmentArgument(const std::string& name) {
  if (name == "se3") return eval::Alignment::SE3;
  if (name == "sim3") return eval::Alignment::Sim3;
  if (name == "none") return eval::Alignment::None;
  throw py::value_error("align: expected 'se3', 'sim3' or 'none', got '" + name + "'");
}

// A trajectory argument and whether it came from a KITTI-format file (frame-for-frame pairing).
struct TrajectoryInput {
  Trajectory poses;
  bool kittiFile = false;
};

TrajectoryInput readInput(const py::handle& value, const char* argument, const std::optional<std::string>& format,
                          const std::optional<std::string>& times) {
  TrajectoryInput in;
  in.poses = trajectoryArgument(value, argument, formatArgument(format), times.value_or(""));
  const bool path = py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__");
  if (path) {
    const std::string file = py::str(py::module_::import("os").attr("fspath")(value));
    in.kittiFile = format ? *format == "kitti" : detectTrajectoryFormat(file) == TrajectoryFormat::Kitti;
  }
  return in;
}

template <class Result>
void bindStatistics(py::class_<Result>& c, eval::ErrorStatistics Result::*member, const char* unit) {
  const std::string u = unit;
  c.def_property_readonly("rmse", [member](const Result& r) { return (r.*member).rmse; }, ("RMSE, " + u).c_str())
      .def_property_readonly("mean", [member](const Result& r) { return (r.*member).mean; })
      .def_property_readonly("median", [member](const Result& r) { return (r.*member).median; })
      .def_property_readonly("max", [member](const Result& r) { return (r.*member).max; })
      .def_property_readonly("min", [member](const Result& r) { return (r.*member).min; })
      .def_property_readonly("std", [member](const Result& r) { return (r.*member).std; }, "Population std.")
      .def_property_readonly("count", [member](const Result& r) { return (r.*member).count; });
}

py::dict statisticsDict(const eval::ErrorStatistics& s) {
  return py::dict("rmse"_a = s.rmse, "mean"_a = s.mean, "median"_a = s.median, "max"_a = s.max, "min"_a = s.min,
                  "std"_a = s.std, "count"_a = s.count);
}

void bindAte(py::module_& m) {
  py::class_<eval::AteResult> c(m, "AteResult", "Absolute trajectory error (metres) after alignment.");
  bindStatistics(c, &eval::AteResult::stats, "metres");
  c.def_property_readonly("scale", [](const eval::AteResult& r) { return r.alignment.scale(); })
      .def_property_readonly("alignment", [](const eval::AteResult& r) {
        py::array_t<double> out({4, 4});
        const Eigen::Matrix4d s = r.alignment.matrix();
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) out.mutable_at(i, j) = s(i, j);
        return out;
      }, "4 x 4 similarity mapping the estimate's world onto the ground truth's.")
      .def_property_readonly("errors", [](const eval::AteResult& r) { return vectorToArray(r.errors); })
      .def_property_readonly("aligned_estimate", [](const eval::AteResult& r) { return trajectoryToArray(r.alignedEstimate); },
                             "The matched estimate poses after alignment, (N, 8) TUM rows.")
      .def("__repr__", [](const eval::AteResult& r) {
        return "AteResult(rmse=" + std::to_string(r.stats.rmse) + ", count=" + std::to_string(r.stats.count) + ")";
      });
  m.def(
      "ate",
      [](const py::handle& gt, const py::handle& est, const std::string& align, double maxDt,
         std::optional<std::string> format, std::optional<std::string> gtTimes, std::optional<std::string> estTimes) {
        const TrajectoryInput g = readInput(gt, "gt", format, gtTimes), e = readInput(est, "est", format, estTimes);
        const eval::AteOptions options{alignmentArgument(align), maxDt};
        py::gil_scoped_release release;
        return eval::computeAte(g.poses, e.poses, options);
      },
      "gt"_a, "est"_a, "align"_a = "se3", "max_dt"_a = 0.02, "format"_a = py::none(), "gt_times"_a = py::none(),
      "est_times"_a = py::none(), "ATE as `orbis eval ate`.");
}

void bindRpe(py::module_& m) {
  py::class_<eval::RpeResult> c(m, "RpeResult", "Relative pose error: translation (metres) and rotation (degrees).");
  bindStatistics(c, &eval::RpeResult::translation, "metres");
  c.def_property_readonly("rotation_deg", [](const eval::RpeResult& r) { return statisticsDict(r.rotationDegrees); })
      .def_readonly("matched", &eval::RpeResult::matched)
      .def_property_readonly("times", [](const eval::RpeResult& r) { return vectorToArray(r.times); })
      .def_property_readonly("translation_errors", [](const eval::RpeResult& r) { return vectorToArray(r.translationErrors); })
      .def_property_readonly("rotation_errors_deg",
                             [](const eval::RpeResult& r) { return vectorToArray(r.rotationErrorsDegrees); });
  m.def(
      "rpe",
      [](const py::handle& gt, const py::handle& est, double delta, const std::string& unit, const std::string& align,
         double maxDt, std::optional<std::string> format, std::optional<std::string> gtTimes,
         std::optional<std::string> estTimes) {
        if (unit != "frames" && unit != "m") throw py::value_error("delta_unit: expected 'frames' or 'm', got '" + unit + "'");
        const TrajectoryInput g = readInput(gt, "gt", format, gtTimes), e = readInput(est, "est", format, estTimes);
        eval::RpeOptions options;
        options.delta = delta;
        options.unit = unit == "m" ? eval::DeltaUnit::Metres : eval::DeltaUnit::Frames;
        options.alignment = alignmentArgument(align);
        options.maxDt = maxDt;
        py::gil_scoped_release release;
        return eval::computeRpe(g.poses, e.poses, options);
      },
      "gt"_a, "est"_a, "delta"_a = 1.0, "delta_unit"_a = "frames", "align"_a = "none", "max_dt"_a = 0.02,
      "format"_a = py::none(), "gt_times"_a = py::none(), "est_times"_a = py::none(), "RPE as `orbis eval rpe`.");
}

// `orbis eval kitti`: pairs, alignment, then the devkit metric over the paired poses.
py::dict kittiMetric(const TrajectoryInput& g, const TrajectoryInput& e, eval::Alignment align, double maxDt) {
  eval::KittiResult kitti;
  std::size_t matched = 0;
  {
    py::gil_scoped_release release;
    const bool byIndex = g.poses.size() == e.poses.size() && (g.kittiFile || e.kittiFile);
    const auto pairs = byIndex ? eval::associateByIndex(g.poses, e.poses) : eval::associateByTime(g.poses, e.poses, maxDt);
    const Sim3d alignment = eval::alignTrajectories(g.poses, e.poses, pairs, align);
    std::vector<SE3d> gtPoses, estPoses;
    for (const auto& pair : pairs) {
      gtPoses.push_back(g.poses[pair.groundTruth].pose);
      estPoses.push_back(eval::applySimilarity(alignment, e.poses[pair.estimate].pose));
    }
    kitti = eval::computeKittiMetric(gtPoses, estPoses);
    matched = pairs.size();
  }
  py::list perLength;
  for (const auto& l : kitti.perLength)
    perLength.append(py::dict("length"_a = l.length, "segments"_a = l.segments, "t_rel"_a = l.translationPercent,
                              "r_rel"_a = l.rotationDegPer100m));
  return py::dict("t_rel"_a = kitti.translationPercent, "r_rel"_a = kitti.rotationDegPer100m,
                  "segments"_a = kitti.segments.size(), "matched"_a = matched, "per_length"_a = perLength);
}

}  // namespace

void bindEvaluation(py::module_& m) {
  bindAte(m);
  bindRpe(m);
  m.def(
      "kitti_metric",
      [](const py::handle& gt, const py::handle& est, const std::string& align, double maxDt,
         std::optional<std::string> format, std::optional<std::string> gtTimes, std::optional<std::string> estTimes) {
        return kittiMetric(readInput(gt, "gt", format, gtTimes), readInput(est, "est", format, estTimes),
                           alignmentArgument(align), maxDt);
      },
      "gt"_a, "est"_a, "align"_a = "none", "max_dt"_a = 0.02, "format"_a = py::none(), "gt_times"_a = py::none(),
      "est_times"_a = py::none(),
      "KITTI odometry metric as `orbis eval kitti`: dict t_rel (%), r_rel (deg/100 m), segments,\n"
      "matched, per_length (list of dicts length, segments, t_rel, r_rel).");
}

}  // namespace orbis::python
