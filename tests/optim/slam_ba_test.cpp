// The pipeline's bundle adjustments on seeded SLAM-shaped scenes (the benchmark generator):
// motion-only BA flags the outliers, local BA keeps fixed keyframes and recovers the free ones,
// full BA can be aborted, and the essential graph closes a loop.
#include "../../benchmarks/ba_problem_generator.hpp"

#include "orbis/camera/fisheye_plane_camera.hpp"
#include "orbis/io/bal.hpp"
#include "orbis/optim/pose_graph.hpp"
#include "orbis/optim/slam_ba.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <numbers>
#include <random>

namespace orbis::optim {
namespace {

double rotationError(const SE3d& a, const SE3d& b) { return (a.so3().inverse() * b.so3()).log().norm(); }
double positionError(const SE3d& a, const SE3d& b) {
  return (a.inverse().translation() - b.inverse().translation()).norm();
}

// Bit-for-bit equality of the stored numbers (memcmp of the whole object would compare padding).
bool sameBits(const SE3d& a, const SE3d& b) {
  return std::memcmp(a.unitQuaternion().coeffs().data(), b.unitQuaternion().coeffs().data(), 4 * sizeof(double)) == 0 &&
         std::memcmp(a.translation().data(), b.translation().data(), 3 * sizeof(double)) == 0;
}

struct Classification {
  int truePositives = 0, falsePositives = 0, outliers = 0, inliers = 0;
};
Classification classify(const std::vector<char>& flagged, const std::vector<char>& truth) {
  Classification c;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    if (truth[k]) { ++c.outliers; c.truePositives += flagged[k] != 0; }
    else { ++c.inliers; c.falsePositives += flagged[k] != 0; }
  }
  return c;
}

TEST(OptimSlamBa, MotionOnlyFlagsOutliers) {
  const auto scene = bench::makeMotionOnlyScene(600, 0.5, 0.1, 42);
  SE3d pose = scene.initialPoses[0];
  const double startError = positionError(pose, scene.truePoses[0]);
  const MotionOnlyResult result =
      motionOnlyBundleAdjustment(scene.camera, pose, scene.truePoints, scene.observations);
  const Classification c = classify(result.outlier, scene.isOutlier);
  std::printf("motion-only: %d obs, %d true outliers: flagged %d of them, %d inliers wrongly; "
              "position error %.4f -> %.4f m, rotation error %.5f rad\n",
              static_cast<int>(scene.observations.size()), c.outliers, c.truePositives, c.falsePositives,
              startError, positionError(pose, scene.truePoses[0]), rotationError(pose, scene.truePoses[0]));
  EXPECT_GT(c.outliers, 30);
  EXPECT_GE(c.truePositives, 0.95 * c.outliers);
  EXPECT_LE(c.falsePositives, 0.08 * c.inliers);  // χ² at 95%: ~5% of inliers by construction
  EXPECT_EQ(result.inliers, static_cast<int>(scene.observations.size()) - c.truePositives - c.falsePositives);
  EXPECT_LT(positionError(pose, scene.truePoses[0]), 0.2 * startError);
  EXPECT_LT(rotationError(pose, scene.truePoses[0]), 1e-3);
}

TEST(OptimSlamBa, MotionOnlyMonocular) {
  const auto scene = bench::makeMotionOnlyScene(400, 0.0, 0.05, 43);
  SE3d pose = scene.initialPoses[0];
  const MotionOnlyResult result =
      motionOnlyBundleAdjustment(scene.camera.pinhole, pose, scene.truePoints, scene.observations);
  const Classification c = classify(result.outlier, scene.isOutlier);
  EXPECT_GE(c.truePositives, 0.95 * c.outliers);
  EXPECT_LT(positionError(pose, scene.truePoses[0]), 0.01);
}

// Motion-only BA as it ran on the general sparse problem before PoseOnlyProblem: the reference
// the specialised path must match bit for bit.
template <class Camera>
SE3d motionOnlyOnTheGeneralProblem(const Camera& camera, SE3d pose, std::span<const Eigen::Vector3d> points,
                                   std::span<const SlamObservation> observations, std::vector<char>& outlier) {
  const MotionOnlyOptions options;
  SlamProblem<Camera> robust;
  robust.addPose(pose);
  for (const auto& p : points) robust.addPoint(p, /*fixed=*/true);
  std::vector<ResidualId> ids;
  for (const auto& o : observations) ids.push_back(slam_detail::addObservation(robust, camera, o, kChi2Mono, kChi2Stereo));
  outlier.assign(observations.size(), 0);
  SolverOptions solver;
  solver.maxIterations = options.iterationsPerRound;
  solver.linearSolver = LinearSolverKind::DenseCholesky;
  const SE3d prior = pose;
  auto round = [&](auto& problem) {
    problem.setPose(0, prior);
    problem.solve(solver);
    int inliers = 0;
    for (std::size_t k = 0; k < observations.size(); ++k) {
      const double threshold = observations[k].isStereo() && ids[k].term == 1 ? kChi2Stereo : kChi2Mono;
      outlier[k] = problem.chi2(ids[k]) > threshold;
      problem.setActive(ids[k], !outlier[k]);
      inliers += !outlier[k];
    }
    pose = problem.pose(0);
    return inliers >= 10;
  };
  bool goOn = true;
  for (int r = 0; r < options.robustRounds && goOn; ++r) goOn = round(robust);
  auto plain = withoutKernel(robust);
  for (int r = options.robustRounds; r < options.rounds && goOn; ++r) goOn = round(plain);
  return pose;
}

// PoseOnlyProblem forms every sum as the general problem does: the same pose to the last bit,
// with stereo and monocular observations and with monocular ones only.
TEST(OptimSlamBa, MotionOnlyGivesTheSameBitsAsTheGeneralProblem) {
  for (const std::uint32_t seed : {42u, 43u, 44u}) {
    const auto scene = bench::makeMotionOnlyScene(500, seed == 43u ? 0.0 : 0.5, 0.1, seed);
    std::vector<char> referenceOutliers;
    const SE3d reference = motionOnlyOnTheGeneralProblem(scene.camera, scene.initialPoses[0], scene.truePoints,
                                                         scene.observations, referenceOutliers);
    SE3d pose = scene.initialPoses[0];
    const MotionOnlyResult result = motionOnlyBundleAdjustment(scene.camera, pose, scene.truePoints, scene.observations);
    EXPECT_TRUE(sameBits(pose, reference)) << "seed " << seed;
    EXPECT_EQ(result.outlier, referenceOutliers) << "seed " << seed;

    const SE3d monoReference = motionOnlyOnTheGeneralProblem(scene.camera.pinhole, scene.initialPoses[0],
                                                             scene.truePoints, scene.observations, referenceOutliers);
    SE3d monoPose = scene.initialPoses[0];
    const MotionOnlyResult mono =
        motionOnlyBundleAdjustment(scene.camera.pinhole, monoPose, scene.truePoints, scene.observations);
    EXPECT_TRUE(sameBits(monoPose, monoReference)) << "seed " << seed;
    EXPECT_EQ(mono.outlier, referenceOutliers) << "seed " << seed;
  }
}

// A fisheye camera's observations are on its tangent plane but weighted in its lens's pixels:
// a 1.5 px error at 75 degrees off axis (about 13 px on the plane) is an inlier, a 15 px one an
// outlier, and the pose comes back from a perturbed start through the lens's Jacobian.
TEST(OptimSlamBa, MotionOnlyThroughAFisheyeLens) {
  KannalaBrandtCamera<double> lens;
  lens.fx = lens.fy = 199.722, lens.cx = 320, lens.cy = 240, lens.k1 = 0.01, lens.k2 = -0.002, lens.k3 = 0.0005;
  lens.width = 640, lens.height = 480;
  const auto camera = FisheyePlaneCamera<double>::ofLens(lens);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const SE3d truth = SE3d::exp((SE3d::Tangent() << 0.1, -0.05, 0.2, 0.02, -0.03, 0.01).finished());
  std::vector<Eigen::Vector3d> points;
  std::vector<SlamObservation> observations;
  const auto observe = [&](double thetaDegrees, double lensError) {
    const double theta = thetaDegrees * std::numbers::pi / 180, azimuth = 2 * std::numbers::pi * u(rng);
    const Eigen::Vector3d ray(std::sin(theta) * std::cos(azimuth), std::sin(theta) * std::sin(azimuth), std::cos(theta));
    const Eigen::Vector3d pc = (2.0 + 6.0 * u(rng)) * ray;
    points.push_back(truth.inverse() * pc);
    // The keypoint moved by lensError fisheye pixels radially, then put on the plane as the
    // sensor's features do.
    const Eigen::Vector2d px = lens.project(pc);
    const Eigen::Vector2d radial = (px - Eigen::Vector2d(lens.cx, lens.cy)).normalized();
    const Eigen::Vector2d onPlane = camera.pinhole.project(lens.bearing(px + lensError * radial));
    observations.push_back({0, static_cast<int>(points.size() - 1), Eigen::Vector3d(onPlane.x(), onPlane.y(), -1), 1.0});
  };
  for (int k = 0; k < 200; ++k) observe(80.0 * u(rng), 0.0);
  const std::size_t modest = observations.size();
  observe(75.0, 1.5);
  const std::size_t gross = observations.size();
  observe(75.0, 15.0);
  SE3d pose = SE3d::exp((SE3d::Tangent() << 0.05, 0.02, -0.04, 0.01, 0.01, -0.02).finished()) * truth;
  const MotionOnlyResult result = motionOnlyBundleAdjustment(camera, pose, points, observations);
  std::printf("fisheye motion-only: %d inliers of %zu; position error %.2e m, rotation error %.2e rad\n",
              result.inliers, observations.size(), positionError(pose, truth), rotationError(pose, truth));
  EXPECT_FALSE(result.outlier[modest]);
  EXPECT_TRUE(result.outlier[gross]);
  EXPECT_EQ(result.inliers, static_cast<int>(observations.size()) - 1);
  // From 7 cm and 0.024 rad off to the truth up to the one 1.5 px inlier's pull.
  EXPECT_LT(positionError(pose, truth), 2e-3);
  EXPECT_LT(rotationError(pose, truth), 5e-4);
  // The same 1.5 px measured on the plane (the tangent-plane pinhole alone) is far beyond χ².
  const Eigen::Vector2d planeError =
      camera.pinhole.project(truth * points[modest]) - observations[modest].measurement.head<2>();
  EXPECT_GT(planeError.squaredNorm(), 5.991);
}

TEST(OptimSlamBa, LocalBaKeepsFixedKeyframesAndRecoversFreeOnes) {
  bench::SlamSceneSpec spec;
  spec.keyframes = 12;
  spec.points = 1500;
  spec.seed = 5;
  const auto scene = bench::makeSlamScene(spec);
  auto poses = scene.initialPoses;
  auto points = scene.initialPoints;
  double before = 0.0, after = 0.0;
  for (int k = 0; k < spec.keyframes; ++k) before = std::max(before, positionError(poses[k], scene.truePoses[k]));
  const BundleAdjustmentResult result =
      bundleAdjustment(scene.camera, poses, scene.poseFixed, points, scene.observations);
  for (int k = 0; k < spec.keyframes; ++k) after = std::max(after, positionError(poses[k], scene.truePoses[k]));
  const Classification c = classify(result.outlier, scene.isOutlier);
  std::printf("local BA: %zu obs, worst keyframe position error %.4f -> %.4f m; outliers flagged "
              "%d/%d, inliers flagged %d/%d; cost %.1f -> %.1f (robust), %.1f (refined)\n",
              scene.observations.size(), before, after, c.truePositives, c.outliers, c.falsePositives,
              c.inliers, result.robustPass.initialCost, result.robustPass.finalCost, result.refinePass.finalCost);
  for (int k = 0; k < spec.fixedKeyframes; ++k) {
    EXPECT_TRUE(sameBits(poses[k], scene.initialPoses[k])) << "keyframe " << k;
  }
  EXPECT_LT(after, 0.1 * before);
  EXPECT_GE(c.truePositives, 0.95 * c.outliers);
  EXPECT_LE(c.falsePositives, 0.08 * c.inliers);
}

// The solver's threads (SolverOptions::threads) share the linearisation, the Schur complement,
// the back-substitution and the cost but keep every sum in its serial order: the same bits at
// any thread count, on a problem large enough to be shared (more than 4096 point pairs).
TEST(OptimSlamBa, LocalBaGivesTheSameBitsAtAnyThreadCount) {
  bench::SlamSceneSpec spec;
  spec.keyframes = 15;
  spec.points = 3000;
  spec.seed = 9;
  const auto scene = bench::makeSlamScene(spec);
  std::vector<std::vector<SE3d>> poses;
  std::vector<std::vector<Eigen::Vector3d>> points;
  std::vector<BundleAdjustmentResult> results;
  for (int threads : {1, 2, 3}) {
    poses.push_back(scene.initialPoses);
    points.push_back(scene.initialPoints);
    BundleAdjustmentOptions options;
    options.threads = threads;
    results.push_back(bundleAdjustment(scene.camera, poses.back(), scene.poseFixed, points.back(), scene.observations, options));
  }
  EXPECT_LT(results[0].refinePass.finalCost, 0.5 * results[0].robustPass.initialCost);
  for (std::size_t t = 1; t < results.size(); ++t) {
    EXPECT_EQ(results[t].robustPass.iterations, results[0].robustPass.iterations);
    EXPECT_EQ(results[t].refinePass.iterations, results[0].refinePass.iterations);
    EXPECT_EQ(std::memcmp(&results[t].refinePass.finalCost, &results[0].refinePass.finalCost, sizeof(double)), 0);
    EXPECT_EQ(results[t].outlier, results[0].outlier);
    for (std::size_t k = 0; k < poses[0].size(); ++k) EXPECT_TRUE(sameBits(poses[t][k], poses[0][k])) << "keyframe " << k;
    for (std::size_t l = 0; l < points[0].size(); ++l)
      ASSERT_EQ(std::memcmp(points[t][l].data(), points[0][l].data(), 3 * sizeof(double)), 0) << "point " << l;
  }
}

TEST(OptimSlamBa, FullBaStopsWhenAborted) {
  bench::SlamSceneSpec spec;
  spec.keyframes = 10;
  spec.points = 500;
  spec.seed = 6;
  const auto scene = bench::makeSlamScene(spec);
  auto poses = scene.initialPoses;
  auto points = scene.initialPoints;
  std::atomic<bool> abort{true};
  const auto aborted = fullBundleAdjustment(scene.camera, poses, points, scene.observations, 20, &abort);
  EXPECT_EQ(aborted.robustPass.termination, Termination::Aborted);
  EXPECT_TRUE(sameBits(poses[5], scene.initialPoses[5]));
  abort = false;
  const auto full = fullBundleAdjustment(scene.camera, poses, points, scene.observations, 20, &abort);
  EXPECT_LT(full.robustPass.finalCost, 0.5 * full.robustPass.initialCost);
  EXPECT_TRUE(sameBits(poses[0], scene.initialPoses[0]));  // first keyframe fixed
}

TEST(OptimSlamBa, LocalBaDumpsItsProblemForReplay) {
  bench::SlamSceneSpec spec;
  spec.keyframes = 5;
  spec.points = 200;
  spec.stereoFraction = 0.0;
  spec.seed = 8;
  const auto scene = bench::makeSlamScene(spec);
  auto poses = scene.initialPoses;
  auto points = scene.initialPoints;
  BundleAdjustmentOptions options;
  const auto dump = std::filesystem::temp_directory_path() / "orbis_local_ba_dump.txt";
  options.inspectBal = [&](const BalProblem& problem) { writeBal(dump, problem); };
  bundleAdjustment(scene.camera, poses, scene.poseFixed, points, scene.observations, options);
  const BalProblem bal = readBal(dump);
  std::filesystem::remove(dump);
  EXPECT_EQ(bal.cameras.size(), scene.initialPoses.size());
  EXPECT_EQ(bal.points.size(), scene.initialPoints.size());
  EXPECT_EQ(bal.observations.size(), scene.observations.size());
  EXPECT_NEAR(bal.points[17].x(), scene.initialPoints[17].x(), 1e-12);  // dumped before solving
}

}  // namespace
}  // namespace orbis::optim
