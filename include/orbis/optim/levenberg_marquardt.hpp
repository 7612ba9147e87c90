// orbis/optim/levenberg_marquardt.hpp — the Levenberg–Marquardt loop, independent of how the
// linear systems are built.
//
// Contract: drives any LinearizedModel (Problem implements it): linearize at the current
// parameters, solve the damped system (H + μ·diag(H))δ = −g, evaluate the candidate, accept it
// when actual/predicted decrease > minRelativeDecrease. μ follows Nielsen's rule: on success
// μ ← μ·max(1/3, 1 − (2ρ − 1)³) and ν ← 2, on failure μ ← μ·ν and ν ← 2ν. Stops on the
// SolverOptions rules; the model always holds the best accepted parameters on return.
#pragma once

#include "orbis/optim/solver_options.hpp"

#include <algorithm>
#include <cmath>
#include <concepts>

namespace orbis::optim {

template <class M>
concept LinearizedModel = requires(M& m, double mu, double& decrease, double& stepNorm) {
  { m.hasFreeVariables() } -> std::convertible_to<bool>;
  { m.linearize() } -> std::convertible_to<double>;         // cost; builds H and g
  { m.maxGradient() } -> std::convertible_to<double>;       // ‖g‖∞ of the last linearisation
  { m.solveDamped(mu, decrease, stepNorm) } -> std::convertible_to<bool>;
  { m.parameterNorm() } -> std::convertible_to<double>;
  { m.candidateCost() } -> std::convertible_to<double>;     // cost at x ⊞ δ of the last solve
  m.acceptCandidate();
};

// Minimises a linearised model by Levenberg–Marquardt (Nielsen's damping, Ceres' stopping rules).
template <LinearizedModel M>
SolverSummary levenbergMarquardt(M& model, const SolverOptions& options) {
  SolverSummary summary;
  double cost = model.linearize();
  summary.initialCost = summary.finalCost = cost;
  if (!model.hasFreeVariables()) {
    summary.termination = Termination::NoFreeVariables;
    return summary;
  }
  if (model.maxGradient() <= options.gradientTolerance) {
    summary.termination = Termination::GradientTolerance;
    return summary;
  }
  double mu = 1.0 / options.initialTrustRadius;
  double nu = 2.0;
  summary.termination = Termination::MaxIterations;
  int consecutiveFailures = 0;
  while (summary.iterations < options.maxIterations) {
    if (options.abortFlag && options.abortFlag->load(std::memory_order_relaxed)) {
      summary.termination = Termination::Aborted;
      break;
    }
    ++summary.iterations;
    double predicted = 0.0, stepNorm = 0.0;
    const bool solved = model.solveDamped(mu, predicted, stepNorm);
    if (!solved || !(predicted > 0.0)) {
      mu *= nu;
      nu *= 2.0;
      if (++consecutiveFailures > 30) {
        summary.termination = Termination::NumericalFailure;
        break;
      }
      continue;
    }
    const double xNorm = model.parameterNorm();
    if (stepNorm <= options.parameterTolerance * (xNorm + options.parameterTolerance)) {
      summary.termination = Termination::ParameterTolerance;
      break;
    }
    const double newCost = model.candidateCost();
    const double actual = cost - newCost;
    const double rho = actual / predicted;
    if (std::isfinite(newCost) && rho > options.minRelativeDecrease) {
      model.acceptCandidate();
      ++summary.successfulSteps;
      consecutiveFailures = 0;
      const double relativeDecrease = actual / cost;
      const double t = 2.0 * rho - 1.0;
      mu *= std::max(1.0 / 3.0, 1.0 - t * t * t);
      nu = 2.0;
      cost = newCost;
      if (relativeDecrease <= options.functionTolerance) {
        summary.termination = Termination::FunctionTolerance;
        break;
      }
      cost = model.linearize();
      if (model.maxGradient() <= options.gradientTolerance) {
        summary.termination = Termination::GradientTolerance;
        break;
      }
    } else {
      mu *= nu;
      nu *= 2.0;
      if (++consecutiveFailures > 30) {
        summary.termination = Termination::NumericalFailure;
        break;
      }
    }
  }
  summary.finalCost = cost;
  return summary;
}

}  // namespace orbis::optim
