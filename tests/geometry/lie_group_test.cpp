// One typed harness for every Lie group × scalar: group axioms, exp/log round trips (random,
// near identity, near π), adjoint, hat/vee, action vs. matrix, and every analytic Jacobian
// against central differences. A new group is tested by adding it to GroupTypes below.
#include "orbis/geometry/se3.hpp"
#include "orbis/geometry/sim3.hpp"
#include "orbis/geometry/so3.hpp"

#include <gtest/gtest.h>
#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace orbis {
namespace {

static_assert(LieGroupWithJacobians<SO3d> && LieGroupWithJacobians<SO3f>);
static_assert(LieGroupWithJacobians<SE3d> && LieGroupWithJacobians<SE3f>);
static_assert(LieGroupWithJacobians<Sim3d> && LieGroupWithJacobians<Sim3f>);

constexpr double kPi = std::numbers::pi;

template <class G>
using Scalar = typename G::Scalar;
template <class G>
using DoubleOf = decltype(G().template cast<double>());

// Tolerances per scalar type. "value" bounds round-trip errors of O(1) quantities; "jacobian"
// bounds |analytic − numeric| where numeric is a central difference of the double instantiation
// (step 1e-5, itself accurate to ~1e-10), so for float it measures float's own rounding.
template <class S>
struct Tol;
template <>
struct Tol<double> {
  static constexpr double value = 1e-12;
  static constexpr double relative = 1e-12;
  static constexpr double jacobian = 1e-8;
};
template <>
struct Tol<float> {
  static constexpr double value = 5e-6;
  static constexpr double relative = 1e-5;
  static constexpr double jacobian = 1e-5;
};

template <class G>
std::string groupName() {
  std::string name = G::kDoF == 3 ? "SO3" : G::kDoF == 6 ? "SE3" : "Sim3";
  return name + (std::is_same_v<Scalar<G>, float> ? "<float>" : "<double>");
}

// Where the rotation vector sits in the tangent: SO3 (ω), SE3 (υ, ω), Sim3 (υ, ω, σ).
template <class G>
constexpr int kRotationOffset = G::kDoF == 3 ? 0 : 3;

// A tangent whose rotation part has exactly the given angle (random axis) and whose other
// parts are uniform in [−linearScale, linearScale].
template <class G>
typename G::Tangent makeTangent(std::mt19937& rng, double angle, double linearScale) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Matrix<double, G::kDoF, 1> xi;
  for (int i = 0; i < G::kDoF; ++i) xi[i] = linearScale * unit(rng);
  Eigen::Vector3d axis(unit(rng), unit(rng), unit(rng));
  axis.normalize();
  xi.template segment<3>(kRotationOffset<G>) = angle * axis;
  return xi.template cast<Scalar<G>>();
}

template <class G>
G randomElement(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(0.0, kPi - 0.01);
  return G::exp(makeTangent<G>(rng, angle(rng), 2.0));
}

template <class G>
typename G::Point randomPoint(std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-3.0, 3.0);
  return Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).cast<Scalar<G>>();
}

// The group's action through its matrix, as a check on operator*(Point).
template <class G>
typename G::Point applyMatrix(const G& g, const typename G::Point& p) {
  if constexpr (G::kMatrixDim == 3) {
    return g.matrix() * p;
  } else {
    return (g.matrix() * p.homogeneous()).template head<3>();
  }
}

template <class G>
double matrixDistance(const G& a, const G& b) {
  return (a.matrix().template cast<double>() - b.matrix().template cast<double>())
      .cwiseAbs()
      .maxCoeff();
}

// Central differences of f: R^N -> R^M at 0, in double.
template <int M, int N, class F>
Eigen::Matrix<double, M, N> numericJacobian(F f, double step = 1e-5) {
  Eigen::Matrix<double, M, N> j;
  for (int c = 0; c < N; ++c) {
    Eigen::Matrix<double, N, 1> d = Eigen::Matrix<double, N, 1>::Zero();
    d[c] = step;
    j.col(c) = (f(d) - f(-d)) / (2.0 * step);
  }
  return j;
}

template <class G>
class LieGroupTest : public ::testing::Test {
 protected:
  using S = Scalar<G>;
  using Tangent = typename G::Tangent;
  std::mt19937 rng{20240611u};

  // Tangents for round trips: random angles in [0, π), near identity, near π.
  std::vector<Tangent> roundTripTangents() {
    std::vector<Tangent> out;
    std::uniform_real_distribution<double> angle(0.0, kPi - 1e-3);
    for (int i = 0; i < 40; ++i) out.push_back(makeTangent<G>(rng, angle(rng), 2.0));
    for (int i = 0; i < 5; ++i) out.push_back(makeTangent<G>(rng, kPi - 1e-6, 2.0));
    for (int i = 0; i < 5; ++i) out.push_back(makeTangent<G>(rng, 0.0, 2.0));  // pure translation
    const double threshold = double(lie_detail::Numerics<S>::smallAngle());
    out.push_back(makeTangent<G>(rng, 0.999 * threshold, 2.0));
    out.push_back(makeTangent<G>(rng, 1.001 * threshold, 2.0));
    appendScaleCases(out, kPi - 1e-6);
    return out;
  }

  // Sim3's W switches between a series and closed forms on |σ| + θ and on tiny θ or σ; put
  // tangents on both sides of each switch. No-op for the other groups.
  void appendScaleCases(std::vector<Tangent>& out, double nearPi) {
    if constexpr (G::kDoF == 7) {
      const double tiny = double(lie_detail::Numerics<S>::tinyAngle());
      const double cases[][2] = {{0.0, 1.0},        {0.5 * tiny, 0.8},  {2.0 * tiny, 0.8},
                                 {0.3, 0.199},      {0.3, 0.201},       {0.6, 0.0},
                                 {0.6, 0.5 * tiny}, {0.6, -2.0 * tiny}, {0.0, -1.5},
                                 {nearPi, -0.7},    {1e-9, 1e-9}};
      for (const auto& [angle, sigma] : cases) {
        Tangent xi = makeTangent<G>(rng, angle, 1.0);
        xi[6] = S(sigma);
        out.push_back(xi);
      }
    }
  }

  // Tangents for Jacobian checks: random, near identity, both sides of the Taylor switch, and
  // near π (not closer than 1e-3: log is discontinuous at π, so differences across it are void).
  std::vector<Tangent> jacobianTangents() {
    std::vector<Tangent> out;
    std::uniform_real_distribution<double> angle(0.0, kPi - 0.05);
    for (int i = 0; i < 20; ++i) out.push_back(makeTangent<G>(rng, angle(rng), 1.5));
    out.push_back(makeTangent<G>(rng, 1e-9, 1.5));
    out.push_back(makeTangent<G>(rng, 1e-9, 1e-9));
    const double threshold = double(lie_detail::Numerics<S>::smallAngle());
    out.push_back(makeTangent<G>(rng, 0.999 * threshold, 1.5));
    out.push_back(makeTangent<G>(rng, 1.001 * threshold, 1.5));
    out.push_back(makeTangent<G>(rng, kPi - 1e-3, 1.5));
    appendScaleCases(out, kPi - 1e-3);
    return out;
  }

  // Checks one analytic Jacobian over all test tangents and prints the largest discrepancy.
  template <class Analytic, class Numeric>
  void checkJacobian(const char* name, Analytic analytic, Numeric numeric) {
    double worst = 0.0;
    for (const Tangent& xi : jacobianTangents()) {
      const auto a = analytic(xi).template cast<double>().eval();
      const auto n = numeric(xi.template cast<double>().eval());
      const double diff = (a - n).cwiseAbs().maxCoeff();
      EXPECT_LT(diff, Tol<S>::jacobian) << name << " at xi = " << xi.transpose() << "\nanalytic\n"
                                        << a << "\nnumeric\n"
                                        << n;
      worst = std::max(worst, diff);
    }
    std::cout << "[jacobian] " << groupName<G>() << " " << name << " max|diff| = " << worst
              << std::endl;
  }
};

using GroupTypes = ::testing::Types<SO3f, SO3d, SE3f, SE3d, Sim3f, Sim3d>;

class GroupNames {
 public:
  template <class G>
  static std::string GetName(int) {
    std::string n = groupName<G>();
    for (char& c : n)
      if (c == '<' || c == '>') c = '_';
    return n;
  }
};
TYPED_TEST_SUITE(LieGroupTest, GroupTypes, GroupNames);

TYPED_TEST(LieGroupTest, GroupAxioms) {
  using G = TypeParam;
  const double tol = Tol<Scalar<G>>::value;
  for (int i = 0; i < 30; ++i) {
    const G a = randomElement<G>(this->rng), b = randomElement<G>(this->rng),
            c = randomElement<G>(this->rng);
    EXPECT_LT(matrixDistance<G>((a * b) * c, a * (b * c)), 10 * tol);
    EXPECT_LT(matrixDistance<G>(G() * a, a), tol);
    EXPECT_LT(matrixDistance<G>(a * G(), a), tol);
    EXPECT_LT(matrixDistance<G>(a * a.inverse(), G()), 10 * tol);
    EXPECT_LT(matrixDistance<G>(a.inverse() * a, G()), 10 * tol);
    // The matrix representation is a homomorphism.
    const auto product = (a.matrix() * b.matrix()).eval();
    EXPECT_LT(((a * b).matrix() - product).cwiseAbs().maxCoeff(), 10 * tol);
  }
}

TYPED_TEST(LieGroupTest, ExpLogRoundTrip) {
  using G = TypeParam;
  const double tol = Tol<Scalar<G>>::value;
  for (const auto& xi : this->roundTripTangents()) {
    const G g = G::exp(xi);
    const double diff = (g.log() - xi).template cast<double>().cwiseAbs().maxCoeff();
    EXPECT_LT(diff, 20 * tol) << "log(exp(xi)) != xi for xi = " << xi.transpose();
    EXPECT_LT(matrixDistance<G>(G::exp(g.log()), g), 20 * tol);
  }
  for (int i = 0; i < 20; ++i) {
    const G g = randomElement<G>(this->rng);
    EXPECT_LT(matrixDistance<G>(G::exp(g.log()), g), 20 * tol);
  }
}

TYPED_TEST(LieGroupTest, ExpLogNearIdentityIsRelativelyExact) {
  using G = TypeParam;
  for (int i = 0; i < 20; ++i) {
    const auto xi = makeTangent<G>(this->rng, 1e-9, 1e-9);
    auto back = G::exp(xi).log();
    if constexpr (G::kDoF == 7) {
      // Sim3 stores s = e^σ, not σ: 1 + σ rounds, so σ comes back to absolute precision ε only.
      const double eps = double(std::numeric_limits<Scalar<G>>::epsilon());
      EXPECT_LT(std::abs(double(back[6] - xi[6])), 2 * eps);
      back[6] = xi[6];
    }
    const double rel =
        (back - xi).template cast<double>().norm() / xi.template cast<double>().norm();
    EXPECT_LT(rel, Tol<Scalar<G>>::relative) << "xi = " << xi.transpose();
  }
  EXPECT_EQ(G::exp(G::Tangent::Zero()).log(), G::Tangent::Zero());
}

TYPED_TEST(LieGroupTest, ExpMatchesMatrixExponentialOfHat) {
  using G = TypeParam;
  using GD = DoubleOf<G>;
  for (const auto& xi : this->roundTripTangents()) {
    const auto xd = xi.template cast<double>().eval();
    const auto expected = GD::hat(xd).exp().eval();
    const double diff =
        (G::exp(xi).matrix().template cast<double>() - expected).cwiseAbs().maxCoeff();
    EXPECT_LT(diff, 20 * Tol<Scalar<G>>::value) << "xi = " << xi.transpose();
  }
}

TYPED_TEST(LieGroupTest, HatVeeRoundTrip) {
  using G = TypeParam;
  for (const auto& xi : this->roundTripTangents()) EXPECT_EQ(G::vee(G::hat(xi)), xi);
}

TYPED_TEST(LieGroupTest, AdjointConjugatesExp) {
  using G = TypeParam;
  const double tol = Tol<Scalar<G>>::value;
  std::uniform_real_distribution<double> angle(0.0, 2.5);
  for (int i = 0; i < 30; ++i) {
    const G g = randomElement<G>(this->rng);
    const auto xi = makeTangent<G>(this->rng, angle(this->rng), 1.0);
    const typename G::Tangent adjXi = g.Adj() * xi;
    EXPECT_LT(matrixDistance<G>(G::exp(adjXi), g * G::exp(xi) * g.inverse()), 50 * tol);
  }
}

TYPED_TEST(LieGroupTest, ActionOnPointsMatchesMatrix) {
  using G = TypeParam;
  const double tol = Tol<Scalar<G>>::value;
  for (int i = 0; i < 30; ++i) {
    const G g = randomElement<G>(this->rng);
    const auto p = randomPoint<G>(this->rng);
    const double diff = (g * p - applyMatrix(g, p)).template cast<double>().cwiseAbs().maxCoeff();
    EXPECT_LT(diff, 50 * tol);
    const double back = (g.inverse() * (g * p) - p).template cast<double>().cwiseAbs().maxCoeff();
    EXPECT_LT(back, 50 * tol);
  }
}

TYPED_TEST(LieGroupTest, CastPreservesElement) {
  using G = TypeParam;
  const G g = randomElement<G>(this->rng);
  const auto d = g.template cast<double>();
  EXPECT_LT((d.matrix() - g.matrix().template cast<double>()).cwiseAbs().maxCoeff(), 1e-6);
  const auto back = d.template cast<Scalar<G>>();
  EXPECT_LT(matrixDistance<G>(back, g), Tol<Scalar<G>>::value);
}

// Builds a group element from Eigen parts; the non-rotation parts are fixed per group.
template <class G, class Rotation>
G fromParts(const Rotation& rotation) {
  using S = Scalar<G>;
  const Eigen::Matrix<S, 3, 1> t(S(0.3), S(-1.2), S(2.5));
  if constexpr (G::kDoF == 3) {
    return G(rotation);
  } else if constexpr (G::kDoF == 6) {
    return G(rotation, t);
  } else {
    return G(S(1.7), rotation, t);
  }
}

TYPED_TEST(LieGroupTest, FromMatrixRoundTrip) {
  using G = TypeParam;
  const double tol = Tol<Scalar<G>>::value;
  for (int i = 0; i < 20; ++i) {
    const G g = randomElement<G>(this->rng);
    EXPECT_LT(matrixDistance<G>(G::fromMatrix(g.matrix()), g), 10 * tol);
    if constexpr (G::kMatrixDim == 4) {
      EXPECT_LT(matrixDistance<G>(G::fromMatrix(g.matrix3x4()), g), 10 * tol);
    }
  }
}

TYPED_TEST(LieGroupTest, AccessorsMatchMatrix) {
  using G = TypeParam;
  const double tol = Tol<Scalar<G>>::value;
  for (int i = 0; i < 10; ++i) {
    const G g = randomElement<G>(this->rng);
    const auto m = g.matrix().template cast<double>().eval();
    if constexpr (G::kDoF == 3) {
      EXPECT_LT(
          (g.unitQuaternion().toRotationMatrix().template cast<double>() - m).cwiseAbs().maxCoeff(),
          tol);
    } else {
      double scale = 1.0;
      if constexpr (G::kDoF == 7) scale = double(g.scale());
      EXPECT_LT((scale * g.rotationMatrix().template cast<double>() - m.template block<3, 3>(0, 0))
                    .cwiseAbs()
                    .maxCoeff(),
                10 * tol);
      EXPECT_LT((g.so3().matrix() - g.rotationMatrix()).cwiseAbs().maxCoeff(), tol);
      const Eigen::Vector3d translationColumn = m.template block<3, 1>(0, 3);
      EXPECT_EQ(g.translation().template cast<double>(), translationColumn);
      EXPECT_EQ(m.row(3), Eigen::RowVector4d(0, 0, 0, 1));
    }
  }
}

TYPED_TEST(LieGroupTest, ConstructionRenormalisesRotation) {
  using G = TypeParam;
  using S = Scalar<G>;
  const double tol = Tol<S>::value;
  const G reference = randomElement<G>(this->rng);
  const Eigen::Quaternion<S> unit = reference.unitQuaternion();
  Eigen::Quaternion<S> scaled = unit;
  scaled.coeffs() *= S(1.7);
  const G fromQuaternion = fromParts<G>(scaled);
  EXPECT_NEAR(double(fromQuaternion.unitQuaternion().norm()), 1.0, tol);
  EXPECT_LT(matrixDistance<G>(fromQuaternion, fromParts<G>(unit)), 10 * tol);

  // A rotation matrix with 1e-4 of noise becomes a nearby exact rotation.
  std::uniform_real_distribution<double> noise(-1e-4, 1e-4);
  Eigen::Matrix<S, 3, 3> noisy = unit.toRotationMatrix();
  for (int i = 0; i < 9; ++i) noisy(i / 3, i % 3) += S(noise(this->rng));
  const G fromNoisy = fromParts<G>(noisy);
  const auto R = fromNoisy.unitQuaternion().toRotationMatrix().template cast<double>().eval();
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 10 * tol);
  EXPECT_LT(matrixDistance<G>(fromNoisy, fromParts<G>(unit)), 1e-3);
}

TYPED_TEST(LieGroupTest, LongProductsStayNormalised) {
  using G = TypeParam;
  using S = Scalar<G>;
  G product;
  for (int i = 0; i < 20000; ++i) product = product * G::exp(makeTangent<G>(this->rng, 0.3, 0.01));
  const double drift = std::abs(double(product.unitQuaternion().squaredNorm()) - 1.0);
  EXPECT_LT(drift, 2.0 * double(lie_detail::Numerics<S>::quaternionDrift()));
  product.normalize();
  EXPECT_NEAR(double(product.unitQuaternion().norm()), 1.0,
              4 * double(std::numeric_limits<S>::epsilon()));
}

TYPED_TEST(LieGroupTest, LeftJacobian) {
  using G = TypeParam;
  using GD = DoubleOf<G>;
  this->checkJacobian(
      "leftJacobian", [](const auto& xi) { return G::leftJacobian(xi); },
      [](const typename GD::Tangent& xi) {
        const GD base = GD::exp(xi);
        return numericJacobian<G::kDoF, G::kDoF>([&](const typename GD::Tangent& d) {
          return (GD::exp(xi + d) * base.inverse()).log();
        });
      });
}

TYPED_TEST(LieGroupTest, RightJacobian) {
  using G = TypeParam;
  using GD = DoubleOf<G>;
  this->checkJacobian(
      "rightJacobian", [](const auto& xi) { return G::rightJacobian(xi); },
      [](const typename GD::Tangent& xi) {
        const GD baseInv = GD::exp(xi).inverse();
        return numericJacobian<G::kDoF, G::kDoF>(
            [&](const typename GD::Tangent& d) { return (baseInv * GD::exp(xi + d)).log(); });
      });
}

TYPED_TEST(LieGroupTest, LeftJacobianInverse) {
  using G = TypeParam;
  using GD = DoubleOf<G>;
  this->checkJacobian(
      "leftJacobianInverse", [](const auto& xi) { return G::leftJacobianInverse(xi); },
      [](const typename GD::Tangent& xi) {
        const GD base = GD::exp(xi);
        return numericJacobian<G::kDoF, G::kDoF>(
            [&](const typename GD::Tangent& d) { return (GD::exp(d) * base).log(); });
      });
}

TYPED_TEST(LieGroupTest, RightJacobianInverse) {
  using G = TypeParam;
  using GD = DoubleOf<G>;
  this->checkJacobian(
      "rightJacobianInverse", [](const auto& xi) { return G::rightJacobianInverse(xi); },
      [](const typename GD::Tangent& xi) {
        const GD base = GD::exp(xi);
        return numericJacobian<G::kDoF, G::kDoF>(
            [&](const typename GD::Tangent& d) { return (base * GD::exp(d)).log(); });
      });
}

// The test point is derived from the tangent so the shared checkJacobian can drive it.
TYPED_TEST(LieGroupTest, PointJacobianLeft) {
  using G = TypeParam;
  using GD = DoubleOf<G>;
  const auto pointFor = [](const auto& xi) {
    using Sc = typename std::decay_t<decltype(xi)>::Scalar;
    return Eigen::Matrix<Sc, 3, 1>(Sc(1.5) - xi[0], Sc(-0.7) + xi[1], Sc(2.0) + xi[2]);
  };
  this->checkJacobian(
      "pointJacobianLeft",
      [&](const auto& xi) { return G::pointJacobianLeft(G::exp(xi) * pointFor(xi)); },
      [&](const typename GD::Tangent& xi) {
        const typename GD::Point q = GD::exp(xi) * pointFor(xi);
        return numericJacobian<3, G::kDoF>(
            [&](const typename GD::Tangent& d) { return GD::exp(d) * q; });
      });
}

}  // namespace
}  // namespace orbis
