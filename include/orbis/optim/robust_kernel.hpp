// orbis/optim/robust_kernel.hpp — robust loss functions as compile-time policies.
//
// Contract: a kernel maps the squared, whitened residual norm s = rᵀΩr to ρ(s) and its first two
// derivatives, given the residual's own threshold δ (passed squared, as delta2 = δ²). The cost
// of a residual is ½ρ(s) (Ceres' convention), so ρ(s) = s for the trivial kernel. With δ² set
// to the χ² quantile of the observation's dimension (5.991 for 2-D, 7.815 for 3-D), Huber
// matches ORB-SLAM's g2o kernels. Kernels are stateless; thresholds live on each residual.
#pragma once

#include <cmath>
#include <concepts>

namespace orbis::optim {

// ρ(s), ρ'(s), ρ''(s) at one point.
struct KernelValue {
  // @{
  // ρ(s), ρ'(s), ρ''(s).
  double rho = 0.0;
  double rho1 = 1.0;
  double rho2 = 0.0;
  // @}
};

template <class K>
concept RobustKernel = requires(double s, double delta2) {
  { K::evaluate(s, delta2) } -> std::same_as<KernelValue>;
  { K::kName } -> std::convertible_to<const char*>;
};

// No kernel: ρ(s) = s.
struct TrivialKernel {
  // @{
  // Name and value.
  static constexpr const char* kName = "none";
  static KernelValue evaluate(double s, double /*delta2*/) { return {s, 1.0, 0.0}; }
  // @}
};

// Quadratic inside δ, linear outside: ρ(s) = 2δ√s − δ² for s > δ².
struct HuberKernel {
  // @{
  // Name and value.
  static constexpr const char* kName = "huber";
  static KernelValue evaluate(double s, double delta2) {
    if (s <= delta2) return {s, 1.0, 0.0};
    const double r = std::sqrt(s);
    const double delta = std::sqrt(delta2);
    return {2.0 * delta * r - delta2, delta / r, -0.5 * delta / (s * r)};
  }
  // @}
};

// ρ(s) = δ² log(1 + s/δ²): never ignores a residual, but its weight decays like 1/s.
struct CauchyKernel {
  // @{
  // Name and value.
  static constexpr const char* kName = "cauchy";
  static KernelValue evaluate(double s, double delta2) {
    const double inv = 1.0 / delta2;
    const double sum = 1.0 + s * inv;
    const double invSum = 1.0 / sum;
    return {delta2 * std::log(sum), invSum, -inv * invSum * invSum};
  }
  // @}
};

// Tukey's biweight: residuals beyond δ contribute a constant and no gradient at all.
struct TukeyKernel {
  // @{
  // Name and value.
  static constexpr const char* kName = "tukey";
  static KernelValue evaluate(double s, double delta2) {
    if (s >= delta2) return {delta2 / 3.0, 0.0, 0.0};
    const double value = 1.0 - s / delta2;
    const double value2 = value * value;
    return {delta2 / 3.0 * (1.0 - value2 * value), value2, -2.0 * value / delta2};
  }
  // @}
};

// χ² quantiles at 95% used by ORB-SLAM for outlier classification and Huber thresholds.
inline constexpr double kChi2Mono = 5.991;
// χ² 95 % quantile, 3 degrees of freedom (stereo).
inline constexpr double kChi2Stereo = 7.815;

}  // namespace orbis::optim
