// orbis/optim/solver_options.hpp — Levenberg–Marquardt settings and the summary of one solve.
//
// Contract: the stopping rules mirror Ceres Solver's so the two can be compared on equal terms:
// relative cost decrease below functionTolerance, step norm below
// parameterTolerance·(‖x‖ + parameterTolerance), largest gradient component below
// gradientTolerance, or maxIterations reached. abortFlag, when set from another thread, stops the
// solve at the next iteration boundary with the best parameters found so far (the paper aborts
// full BA when a new loop arrives). Costs are ½Σρ(‖r‖²_Ω).
#pragma once

#include <atomic>
#include <string>

namespace orbis::optim {

enum class LinearSolverKind {
  Automatic,       // dense below denseThreshold unknowns in the reduced camera system, else sparse
  DenseCholesky,   // Eigen LLT of the reduced camera system
  SparseCholesky,  // CHOLMOD supernodal; ordering and symbolic analysis once per solve
};

struct SolverOptions {
  int maxIterations = 50;
  double functionTolerance = 1e-6;
  double parameterTolerance = 1e-8;
  double gradientTolerance = 1e-10;
  // μ₀ = 1/initialTrustRadius; Ceres' default radius is 1e4.
  double initialTrustRadius = 1e4;
  // A step is accepted when actual/predicted decrease exceeds this (Ceres: 1e-3).
  double minRelativeDecrease = 1e-3;
  // Bounds on the Marquardt diagonal, as Ceres' min/max_lm_diagonal.
  double minDiagonal = 1e-6;
  double maxDiagonal = 1e32;
  LinearSolverKind linearSolver = LinearSolverKind::Automatic;
  int denseThreshold = 400;
  const std::atomic<bool>* abortFlag = nullptr;
  // Threads for the Schur complement, the back-substitution and the cost (util/parallel_for.hpp).
  // Every sum keeps its serial order, so the result is bit-identical at any count.
  int threads = 1;
};

enum class Termination {
  FunctionTolerance,
  ParameterTolerance,
  GradientTolerance,
  MaxIterations,
  Aborted,
  NumericalFailure,
  NoFreeVariables,
};

inline const char* toString(Termination t) {
  switch (t) {
    case Termination::FunctionTolerance: return "function_tolerance";
    case Termination::ParameterTolerance: return "parameter_tolerance";
    case Termination::GradientTolerance: return "gradient_tolerance";
    case Termination::MaxIterations: return "max_iterations";
    case Termination::Aborted: return "aborted";
    case Termination::NumericalFailure: return "numerical_failure";
    case Termination::NoFreeVariables: return "no_free_variables";
  }
  return "unknown";
}

struct SolverSummary {
  double initialCost = 0.0;
  double finalCost = 0.0;
  int iterations = 0;        // linear solves attempted (accepted + rejected steps)
  int successfulSteps = 0;
  Termination termination = Termination::MaxIterations;
  bool usedSparseSolver = false;
  bool converged() const {
    return termination == Termination::FunctionTolerance ||
           termination == Termination::ParameterTolerance ||
           termination == Termination::GradientTolerance;
  }
};

}  // namespace orbis::optim
