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

// How the reduced camera system is solved.
enum class LinearSolverKind {
  Automatic,       // dense below denseThreshold unknowns in the reduced camera system, else sparse
  DenseCholesky,   // Eigen LLT of the reduced camera system
  SparseCholesky,  // CHOLMOD supernodal; ordering and symbolic analysis once per solve
};

// Levenberg–Marquardt settings (Ceres' defaults where not noted).
struct SolverOptions {
  // @{
  // Iteration cap, and stopping tolerances on the relative cost decrease, the step and the
  // gradient.
  int maxIterations = 50;
  double functionTolerance = 1e-6;
  double parameterTolerance = 1e-8;
  double gradientTolerance = 1e-10;
  // @}
  // μ₀ = 1/initialTrustRadius; Ceres' default radius is 1e4.
  double initialTrustRadius = 1e4;
  // A step is accepted when actual/predicted decrease exceeds this (Ceres: 1e-3).
  double minRelativeDecrease = 1e-3;
  // Bounds on the Marquardt diagonal, as Ceres' min/max_lm_diagonal.
  double minDiagonal = 1e-6;
  // Upper bound of the Marquardt diagonal.
  double maxDiagonal = 1e32;
  // The reduced system's solver.
  LinearSolverKind linearSolver = LinearSolverKind::Automatic;
  // Unknowns from which Automatic uses CHOLMOD.
  int denseThreshold = 400;
  // Stops the solve from another thread when set.
  const std::atomic<bool>* abortFlag = nullptr;
  // Threads for the Schur complement, the back-substitution and the cost (util/parallel_for.hpp).
  // Every sum keeps its serial order, so the result is bit-identical at any count.
  int threads = 1;
};

// Why a solve stopped.
enum class Termination {
  FunctionTolerance,
  ParameterTolerance,
  GradientTolerance,
  MaxIterations,
  Aborted,
  NumericalFailure,
  NoFreeVariables,
};

// The reason's name.
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

// What a solve did.
struct SolverSummary {
  // @{
  // Cost ½Σρ before and after.
  double initialCost = 0.0;
  double finalCost = 0.0;
  // @}
  int iterations = 0;        // linear solves attempted (accepted + rejected steps)
  // Accepted steps.
  int successfulSteps = 0;
  // Why it stopped.
  Termination termination = Termination::MaxIterations;
  // Whether CHOLMOD solved the reduced system.
  bool usedSparseSolver = false;
  // Whether a tolerance stopped it.
  bool converged() const {
    return termination == Termination::FunctionTolerance ||
           termination == Termination::ParameterTolerance ||
           termination == Termination::GradientTolerance;
  }
};

}  // namespace orbis::optim
