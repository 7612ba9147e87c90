// The two-view initialiser on synthetic scenes with known motion: a general 3-D scene (F must
// win), a plane (H must win), both with 0.5 px noise and 20% outliers and the motion recovered
// to 0.5° in rotation and 1° in translation direction; a pure rotation and a static camera
// refused for low parallax; the same seed giving the same bits.
#include "orbis/geometry/two_view.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

namespace orbis {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kImageWidth = 640, kImageHeight = 480;

Eigen::Matrix3d intrinsics() {
  Eigen::Matrix3d K;
  K << 520, 0, 320, 0, 520, 240, 0, 0, 1;
  return K;
}

struct Motion {
  Eigen::Matrix3d rotation;     // frame 1 -> frame 2
  Eigen::Vector3d translation;  // x₂ = R·x₁ + t
};

struct SceneOptions {
  int matches = 300;
  double noisePx = 0.5;
  double outlierFraction = 0.2;
  unsigned seed = 7;
};

bool inImage(const Eigen::Vector2d& p) { return p.x() >= 0 && p.y() >= 0 && p.x() < kImageWidth && p.y() < kImageHeight; }

// Matches of points drawn by `samplePoint` (frame 1) seen by both cameras; then noise, and a
// share of second-view positions replaced by random pixels (wrong matches).
std::vector<TwoViewMatch> makeMatches(const Motion& motion, const std::function<Eigen::Vector3d(std::mt19937&)>& samplePoint,
                                      const SceneOptions& options) {
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> noise(0.0, options.noisePx);
  std::uniform_real_distribution<double> u(0.0, kImageWidth), v(0.0, kImageHeight), unit(0.0, 1.0);
  const Eigen::Matrix3d K = intrinsics();
  std::vector<TwoViewMatch> matches;
  while (int(matches.size()) < options.matches) {
    const Eigen::Vector3d X = samplePoint(rng);
    const Eigen::Vector3d X2 = motion.rotation * X + motion.translation;
    if (X.z() <= 0 || X2.z() <= 0) continue;
    TwoViewMatch m;
    m.first = (K * X).hnormalized();
    m.second = (K * X2).hnormalized();
    if (!inImage(m.first) || !inImage(m.second)) continue;
    m.first += Eigen::Vector2d(noise(rng), noise(rng));
    m.second += Eigen::Vector2d(noise(rng), noise(rng));
    if (unit(rng) < options.outlierFraction) m.second = {u(rng), v(rng)};
    matches.push_back(m);
  }
  return matches;
}

Eigen::Vector3d boxPoint(std::mt19937& rng) {
  std::uniform_real_distribution<double> x(-3, 3), y(-2.5, 2.5), z(3, 8);
  return {x(rng), y(rng), z(rng)};
}

// A plane tilted against both image axes, about 6 m away.
Eigen::Vector3d planePoint(std::mt19937& rng) {
  std::uniform_real_distribution<double> a(-5, 5), b(-4, 4);
  const double s = a(rng), t = b(rng);
  return Eigen::Vector3d(0, 0, 6) + s * Eigen::Vector3d(1, 0, 0.3) + t * Eigen::Vector3d(0, 1, -0.2);
}

Motion generalMotion() {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(6 * kDeg, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  return {R, Eigen::Vector3d(-0.8, 0.1, 0.25)};
}

double rotationErrorDeg(const Eigen::Matrix3d& estimated, const Eigen::Matrix3d& truth) {
  return Eigen::AngleAxisd(estimated * truth.transpose()).angle() / kDeg;
}

double directionErrorDeg(const Eigen::Vector3d& estimated, const Eigen::Vector3d& truth) {
  return std::acos(std::clamp(estimated.normalized().dot(truth.normalized()), -1.0, 1.0)) / kDeg;
}

TwoViewResult initialise(const std::vector<TwoViewMatch>& matches, unsigned seed = 1) {
  std::mt19937 rng(seed);
  return initialiseTwoView(matches, intrinsics(), rng);
}

void expectRecovered(const TwoViewResult& r, const Motion& truth, const std::vector<TwoViewMatch>& matches) {
  ASSERT_TRUE(r.accepted()) << toString(r.refusal) << " (R_H " << r.homographyRatio << ", good " << r.goodPoints
                            << ", second " << r.secondBestGood << ", parallax " << r.parallaxDeg << ")";
  const double rotationError = rotationErrorDeg(r.rotation, truth.rotation);
  const double directionError = directionErrorDeg(r.translation, truth.translation);
  EXPECT_LT(rotationError, 0.5);
  EXPECT_LT(directionError, 1.0);
  EXPECT_NEAR(r.translation.norm(), 1.0, 1e-9);
  ASSERT_EQ(r.points.size(), matches.size());
  ASSERT_EQ(r.triangulated.size(), matches.size());
  // Triangulated points are in front of both cameras and reproject onto their keypoints.
  int triangulated = 0;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (!r.triangulated[i]) continue;
    ++triangulated;
    const Eigen::Vector3d X = r.points[i];
    EXPECT_GT(X.z(), 0);
    EXPECT_GT((r.rotation * X + r.translation).z(), 0);
    EXPECT_LT(((intrinsics() * X).hnormalized() - matches[i].first).norm(), 2.0);
  }
  EXPECT_GE(triangulated, 50);
  std::printf("  model %s, R_H %.3f, inliers %d, good %d (runner-up %d), parallax %.2f deg, "
              "rotation error %.4f deg, translation direction error %.4f deg\n",
              std::string(toString(r.model)).c_str(), r.homographyRatio, r.inliers, r.goodPoints, r.secondBestGood,
              r.parallaxDeg, rotationError, directionError);
}

// Three scenes of one kind (seeds 7-9): the expected model wins and the motion is recovered.
void expectModelAndMotion(const std::function<Eigen::Vector3d(std::mt19937&)>& samplePoint, TwoViewModel expected) {
  const Motion truth = generalMotion();
  for (unsigned seed : {7u, 8u, 9u}) {
    const auto matches = makeMatches(truth, samplePoint, {.seed = seed});
    const TwoViewResult r = initialise(matches, seed);
    EXPECT_EQ(r.model, expected) << "R_H " << r.homographyRatio;
    expectRecovered(r, truth, matches);
    // Wrong matches must not pass as inliers in bulk: about 60 of the 300 are wrong.
    EXPECT_LE(r.inliers, 260);
  }
}

TEST(TwoView, GeneralSceneChoosesFundamentalAndRecoversMotion) { expectModelAndMotion(boxPoint, TwoViewModel::Fundamental); }

TEST(TwoView, PlanarSceneChoosesHomographyAndRecoversMotion) { expectModelAndMotion(planePoint, TwoViewModel::Homography); }

TEST(TwoView, PureRotationIsRefusedForLowParallax) {
  const Motion rotation{Eigen::AngleAxisd(8 * kDeg, Eigen::Vector3d(0.1, 1, 0).normalized()).toRotationMatrix(),
                        Eigen::Vector3d::Zero()};
  for (unsigned seed : {7u, 8u, 9u}) {
    const TwoViewResult r = initialise(makeMatches(rotation, boxPoint, {.seed = seed}), seed);
    EXPECT_EQ(r.refusal, TwoViewRefusal::LowParallax) << toString(r.refusal) << ", parallax " << r.parallaxDeg;
  }
}

TEST(TwoView, StaticCameraIsRefusedForLowParallax) {
  const Motion still{Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()};
  // Identical views, exactly, and the same with keypoint noise and wrong matches.
  const TwoViewResult exact = initialise(makeMatches(still, boxPoint, {.noisePx = 0, .outlierFraction = 0}));
  EXPECT_EQ(exact.refusal, TwoViewRefusal::LowParallax) << toString(exact.refusal);
  const TwoViewResult noisy = initialise(makeMatches(still, boxPoint, {}));
  EXPECT_EQ(noisy.refusal, TwoViewRefusal::LowParallax) << toString(noisy.refusal);
}

TEST(TwoView, TooFewMatchesAreRefused) {
  const TwoViewResult r = initialise(makeMatches(generalMotion(), boxPoint, {.matches = 40}));
  EXPECT_EQ(r.refusal, TwoViewRefusal::TooFewMatches);
}

TEST(TwoView, SameSeedGivesIdenticalResult) {
  const auto matches = makeMatches(generalMotion(), boxPoint, {});
  const TwoViewResult a = initialise(matches, 42), b = initialise(matches, 42);
  ASSERT_TRUE(a.accepted());
  EXPECT_EQ(a.homographyRatio, b.homographyRatio);
  EXPECT_EQ(a.rotation, b.rotation);
  EXPECT_EQ(a.translation, b.translation);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.triangulated, b.triangulated);
  EXPECT_EQ(a.goodPoints, b.goodPoints);
}

}  // namespace
}  // namespace orbis
