// orbis/io/bal.hpp — "Bundle Adjustment in the Large" problem files (problem-*.txt).
//
// Contract: the BAL text layout — a header "cameras points observations", then one line per
// observation "camera point x y", then 9 numbers per camera (angle-axis rotation, translation,
// focal length, k1, k2) and 3 per point, whitespace-separated; the model is BalProblem's
// (orbis/optim/bal_problem.hpp). readBal throws orbis::Error naming the file and line on
// malformed input or out-of-range indices; writeBal writes the same layout with round-trip
// precision.
#pragma once

#include <filesystem>

#include "orbis/optim/bal_problem.hpp"

namespace orbis {

// Reads a problem in the BAL (Bundle Adjustment in the Large) text format; throws orbis::Error
// naming the file and line.
BalProblem readBal(const std::filesystem::path& file);
// Writes a problem in the BAL text format.
void writeBal(const std::filesystem::path& file, const BalProblem& problem);

}  // namespace orbis
