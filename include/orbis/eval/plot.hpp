// orbis/eval/plot.hpp — a picture of an evaluation: the estimate over the ground truth seen
// from above, and the error over time.
//
// Contract: writeEvaluationPlot draws two panels — left, the trajectories projected on the
// two world axes along which the ground truth extends most (equal scale on both, so shapes
// are true), right, the per-pose error against time since the first ground-truth pose — and
// writes a PNG (OpenCV) or an SVG (hand-written), chosen by the file extension (.png/.svg).
// Throws orbis::Error naming the file for another extension or a failed write.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "orbis/io/trajectory.hpp"

namespace orbis::eval {

// What an evaluation plot draws: a top view of ground truth and aligned estimate, and the error
// over time.
struct EvaluationPlot {
  std::string title;               // drawn at the top, e.g. "ATE 0.0135 m RMSE, 786 poses"
  Trajectory groundTruth;          // drawn whole
  Trajectory estimate;             // already aligned to the ground truth
  std::vector<double> errorTimes;  // seconds (absolute; shifted to the first GT pose)
  std::vector<double> errors;      // one per errorTimes entry
  // The error axis's label.
  std::string errorLabel = "error [m]";
  std::optional<double> errorReference;  // drawn as a dashed level, e.g. the RMSE
  // The label of the dashed reference level.
  std::string errorReferenceLabel;
};

// Writes the plot as PNG or SVG (by the file's extension).
void writeEvaluationPlot(const std::filesystem::path& file, const EvaluationPlot& plot);

}  // namespace orbis::eval
