// orbis ba FILE — solves a "Bundle Adjustment in the Large" problem with the orbis solver.
#include "command.hpp"
#include "orbis/io/bal.hpp"
#include "orbis/optim/bal.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace orbis::cli {
namespace {

int runBa(const std::vector<std::string>& args) {
  ArgParser parser("orbis ba FILE [options]",
                   "Reads a BAL problem (problem-*.txt), solves it with Levenberg-Marquardt, Huber\n"
                   "loss on the pixel residuals and a Schur complement on the points, and prints\n"
                   "the initial and final cost (1/2 sum rho(|r|^2), Ceres' convention).");
  parser.positional("FILE", "BAL problem in text form")
      .option("--huber", "DELTA", "Huber threshold in pixels", "1.0")
      .option("--max-iterations", "N", "iteration cap", "50")
      .option("--function-tolerance", "T", "stop when the relative cost decrease falls below T", "1e-6")
      .option("--linear-solver", "KIND", "auto, dense or sparse (CHOLMOD)", "auto")
      .option("--output", "FILE", "write the solved problem in BAL form")
      .flag("--json", "print one JSON object on standard output instead of text");
  if (!parser.parse(args)) return 0;

  optim::SolverOptions options;
  options.maxIterations = static_cast<int>(parser.getInt("--max-iterations"));
  options.functionTolerance = parser.getDouble("--function-tolerance");
  const std::string kind = parser.get("--linear-solver");
  if (kind == "dense") options.linearSolver = optim::LinearSolverKind::DenseCholesky;
  else if (kind == "sparse") options.linearSolver = optim::LinearSolverKind::SparseCholesky;
  else if (kind != "auto") throw Error("argument --linear-solver", "", "expected auto, dense or sparse, got '" + kind + "'");
  const double huber = parser.getDouble("--huber");
  if (!(huber > 0.0)) throw Error("argument --huber", "", "expected a positive threshold");

  BalProblem bal = readBal(parser.pos(0));
  const auto start = std::chrono::steady_clock::now();
  const optim::SolverSummary summary = optim::solveBal(bal, options, huber);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (const auto out = parser.getOptional("--output")) writeBal(*out, bal);

  if (parser.has("--json")) {
    JsonWriter json;
    json.beginObject()
        .field("initial_cost", summary.initialCost)
        .field("final_cost", summary.finalCost)
        .field("iterations", summary.iterations)
        .field("seconds", seconds)
        .endObject();
    std::printf("%s\n", json.str().c_str());
  } else {
    std::printf("problem       %zu cameras, %zu points, %zu observations\n", bal.cameras.size(),
                bal.points.size(), bal.observations.size());
    std::printf("initial_cost  %.10g\nfinal_cost    %.10g\niterations    %d (%d accepted)\n",
                summary.initialCost, summary.finalCost, summary.iterations, summary.successfulSteps);
    std::printf("termination   %s\nlinear solver %s\nseconds       %.3f\n", optim::toString(summary.termination),
                summary.usedSparseSolver ? "sparse (CHOLMOD supernodal)" : "dense (LLT)", seconds);
  }
  return 0;
}

}  // namespace

ORBIS_REGISTER_COMMAND("ba", "solve a BAL bundle-adjustment problem (problem-*.txt)", runBa);

}  // namespace orbis::cli
