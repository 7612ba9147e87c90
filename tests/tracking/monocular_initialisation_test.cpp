// Tracker<Monocular>'s two-view initialisation on synthetic features (projected 3-D points with
// one descriptor each, a few bits flipped per view, 0.3 px noise): a sideways-moving camera
// waits while the parallax is low, then initialises with two keyframes, points at median
// depth 1 and the true motion direction; a rotating and a static camera never initialise and
// say why; the same frames give the same map bits. A monocular merge (issue 32) that moves the
// tracker's map by a similarity rescales the motion model and the kept trajectory with it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "orbis/geometry/sim3.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/tracking/tracker.hpp"

namespace orbis {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
const PinholeCamera<double> kCamera{520, 520, 320, 240, 640, 480};

const OrbVocabulary& vocabulary() {
  static const OrbVocabulary voc = OrbVocabulary::load(defaultVocabularyPath());
  return voc;
}

struct Landmark {
  Eigen::Vector3d position;
  OrbDescriptor descriptor;
};

std::vector<Landmark> makeLandmarks(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(-4, 4), y(-3, 3), z(3, 8);
  std::vector<Landmark> landmarks(800);
  for (Landmark& l : landmarks) {
    l.position = {x(rng), y(rng), z(rng)};
    for (auto& w : l.descriptor.words) w = (std::uint64_t(rng()) << 32) | rng();
  }
  return landmarks;
}

// The features a camera at Tcw sees: one level-0 keypoint per visible landmark.
std::shared_ptr<const FrameFeatures> observe(const std::vector<Landmark>& landmarks, const SE3d& Tcw,
                                             std::mt19937& rng) {
  std::normal_distribution<float> noise(0.f, 0.3f);
  std::uniform_int_distribution<int> bit(0, 255);
  auto f = std::make_shared<FrameFeatures>();
  for (const Landmark& l : landmarks) {
    const Eigen::Vector3d pc = Tcw * l.position;
    if (pc.z() <= 0.1) continue;
    const Eigen::Vector2d px = kCamera.project(pc);
    if (!kCamera.inImage(px.x(), px.y())) continue;
    f->keypoints.push_back({float(px.x()) + noise(rng), float(px.y()) + noise(rng), 0.f, 1.f, 0});
    OrbDescriptor d = l.descriptor;
    for (int k = 0; k < 6; ++k) {
      const int b = bit(rng);
      d.words[std::size_t(b / 64)] ^= std::uint64_t(1) << (b % 64);
    }
    f->descriptors.push_back(d);
  }
  detail::finishMonocular(*f, kCamera, {}, kCamera.width, kCamera.height);
  return f;
}

Frame<PinholeCamera<double>> makeFrame(std::uint64_t index, std::shared_ptr<const FrameFeatures> features) {
  Frame<PinholeCamera<double>> frame;
  frame.index = index;
  frame.timestamp = 0.1 * double(index);
  frame.camera = &kCamera;
  frame.intrinsics = {kCamera.fx, kCamera.fy, kCamera.cx, kCamera.cy};
  frame.intrinsics.maxX = kCamera.width;
  frame.intrinsics.maxY = kCamera.height;
  frame.features = std::move(features);
  return frame;
}

struct TrackerRun {
  std::vector<TrackingState> states;
  std::vector<TwoViewRefusal> refusals;
  std::vector<SE3d> truth;  // Tcw per frame
};

// Feeds `frames` poses (world -> camera) to a fresh tracker over `map`.
TrackerRun runTracker(Map& map, const std::vector<SE3d>& poses, unsigned seed = 3) {
  const std::vector<Landmark> landmarks = makeLandmarks(seed);
  std::mt19937 rng(seed);
  Tracker<Monocular> tracker(map, vocabulary(), nullptr, TrackerOptions{});
  TrackerRun run;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const TrackResult r = tracker.track(makeFrame(k, observe(landmarks, poses[k], rng)));
    run.states.push_back(r.state);
    run.refusals.push_back(tracker.initialisationRefusal());
  }
  run.truth = poses;
  return run;
}

// A camera moving 2 cm sideways per frame (x), turning slightly towards the scene.
std::vector<SE3d> sidewaysPoses(int frames) {
  std::vector<SE3d> poses;
  for (int k = 0; k < frames; ++k) {
    const Eigen::Matrix3d Rwc = Eigen::AngleAxisd(-0.1 * k * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix();
    poses.push_back(SE3d(Rwc, Eigen::Vector3d(0.02 * k, 0.002 * k, 0)).inverse());
  }
  return poses;
}

int firstInitialisedFrame(const TrackerRun& run) {
  const auto it = std::find(run.states.begin(), run.states.end(), TrackingState::Ok);
  return it == run.states.end() ? -1 : int(it - run.states.begin());
}

TEST(MonocularInitialisation, SidewaysMotionInitialisesAfterEnoughParallax) {
  Map map;
  const TrackerRun run = runTracker(map, sidewaysPoses(25));
  const int initialised = firstInitialisedFrame(run);
  ASSERT_GT(initialised, 1) << "initialised before any parallax";
  std::printf("  initialised at frame %d; refusals before:", initialised);
  for (int k = 1; k < initialised; ++k) std::printf(" %s;", std::string(toString(run.refusals[k])).c_str());
  std::printf("\n");
  EXPECT_EQ(run.refusals[initialised - 1], TwoViewRefusal::LowParallax);
  int trackedAfter = 0;
  for (std::size_t k = initialised; k < run.states.size(); ++k) trackedAfter += run.states[k] == TrackingState::Ok;
  std::printf("  frames tracked after initialisation: %d of %zu\n", trackedAfter, run.states.size() - initialised);

  std::vector<KeyFrame*> keyFrames = map.keyFrames();
  ASSERT_GE(keyFrames.size(), 2u);
  std::sort(keyFrames.begin(), keyFrames.end(), [](auto* a, auto* b) { return a->frameIndex < b->frameIndex; });
  const KeyFrame* first = keyFrames[0];
  const KeyFrame* second = keyFrames[1];
  EXPECT_EQ(first->frameIndex, 0u);
  EXPECT_EQ(second->frameIndex, std::uint64_t(initialised));
  EXPECT_TRUE(first->Tcw().translation().isZero(0));
  // Median depth 1 in the first keyframe.
  std::vector<double> depths;
  for (const MapPoint* p : first->goodPoints()) depths.push_back((first->Tcw() * p->position()).z());
  ASSERT_GE(depths.size(), 100u);
  std::nth_element(depths.begin(), depths.begin() + long(depths.size() / 2), depths.end());
  EXPECT_NEAR(depths[depths.size() / 2], 1.0, 1e-6);
  // The motion between the keyframes against the truth (the first camera is the world origin).
  const SE3d truthRelative = run.truth[std::size_t(initialised)] * run.truth[0].inverse();
  const SE3d estimatedRelative = second->Tcw() * first->Tcw().inverse();
  const double rotationError = Eigen::AngleAxisd(estimatedRelative.rotationMatrix() *
                                                 truthRelative.rotationMatrix().transpose()).angle() / kDeg;
  const double directionError =
      std::acos(std::clamp(estimatedRelative.translation().normalized().dot(truthRelative.translation().normalized()),
                           -1.0, 1.0)) / kDeg;
  std::printf("  %zu points; rotation error %.3f deg, translation direction error %.3f deg\n", depths.size(),
              rotationError, directionError);
  EXPECT_LT(rotationError, 0.5);
  EXPECT_LT(directionError, 1.0);
}

TEST(MonocularInitialisation, PureRotationNeverInitialises) {
  std::vector<SE3d> poses;
  for (int k = 0; k < 20; ++k)
    poses.push_back(SE3d(Eigen::AngleAxisd(0.4 * k * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                         Eigen::Vector3d::Zero()));
  Map map;
  const TrackerRun run = runTracker(map, poses);
  EXPECT_EQ(firstInitialisedFrame(run), -1);
  EXPECT_EQ(run.refusals.back(), TwoViewRefusal::LowParallax) << toString(run.refusals.back());
  EXPECT_TRUE(map.keyFrames().empty());
}

TEST(MonocularInitialisation, StaticCameraNeverInitialises) {
  Map map;
  const TrackerRun run = runTracker(map, std::vector<SE3d>(15, SE3d()));
  EXPECT_EQ(firstInitialisedFrame(run), -1);
  EXPECT_EQ(run.refusals.back(), TwoViewRefusal::LowParallax) << toString(run.refusals.back());
  EXPECT_TRUE(map.keyFrames().empty());
}

TEST(MonocularInitialisation, SameFramesGiveTheSameMap) {
  Map a, b;
  runTracker(a, sidewaysPoses(12));
  runTracker(b, sidewaysPoses(12));
  const auto kfA = a.keyFrames(), kfB = b.keyFrames();
  ASSERT_EQ(kfA.size(), kfB.size());
  ASSERT_FALSE(kfA.empty());
  for (std::size_t i = 0; i < kfA.size(); ++i) EXPECT_EQ(kfA[i]->Tcw().matrix(), kfB[i]->Tcw().matrix());
  const auto pA = a.mapPoints(), pB = b.mapPoints();
  ASSERT_EQ(pA.size(), pB.size());
  for (std::size_t i = 0; i < pA.size(); ++i) EXPECT_EQ(pA[i]->position(), pB[i]->position());
}

// The named counter of a logged frame event (-1 when absent).
double frameCounter(const StageEvent& event, const std::string& name) {
  for (const auto& [key, value] : event.values)
    if (key == name) return value;
  return -1;
}

TEST(MonocularMerge, SimilarityMoveRescalesMotionModelAndTrajectory) {
  // The loop thread's merge moves the tracker's map into another's frame by a similarity; here
  // scale 0.02 (exaggerated so that an unscaled motion model misses every match in its search
  // window) and the other map is an empty one.
  const std::vector<SE3d> poses = sidewaysPoses(26);
  const std::vector<Landmark> landmarks = makeLandmarks(3);
  std::mt19937 rng(3);
  Map map;
  StageTimer timer;
  timer.enableEvents(true);
  Tracker<Monocular> tracker(map, vocabulary(), nullptr, TrackerOptions{}, &timer);
  const std::size_t mergeAt = 25;
  for (std::size_t k = 0; k < mergeAt; ++k) tracker.track(makeFrame(k, observe(landmarks, poses[k], rng)));
  ASSERT_EQ(tracker.state(), TrackingState::Ok);
  ASSERT_TRUE(tracker.motionModel());
  const double stepBefore = tracker.motionModel()->translation().norm();
  std::vector<SE3d> posesBefore;
  for (const TrackedFrame& f : tracker.trackedFrames()) posesBefore.push_back(Tracker<Monocular>::worldPose(f));
  ASSERT_GE(posesBefore.size(), 10u);

  const Sim3d S(0.02, Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix(),
                Eigen::Vector3d(1, -2, 0.5));
  const auto moved = [&](const SE3d& Tcw) {
    const Sim3d Scw = Sim3d(Tcw) * S.inverse();
    return SE3d(Scw.so3(), Scw.translation() / Scw.scale());
  };
  {
    std::lock_guard lock(map.mutex());
    const std::uint32_t kept = map.startNewMap(mergeAt);
    for (MapPoint* p : map.mapPoints(0)) p->setPosition(S * p->position());
    for (KeyFrame* kf : map.keyFrames(0)) kf->setPose(moved(kf->Tcw()));
    for (MapPoint* p : map.mapPoints(0)) p->updateNormalAndDepth();
    map.mergeInto(0, kept, S.scale());
  }
  const TrackResult r = tracker.track(makeFrame(mergeAt, observe(landmarks, poses[mergeAt], rng)));
  ASSERT_EQ(r.state, TrackingState::Ok);

  // Every frame tracked before the merge moved with its map.
  ASSERT_GE(tracker.trackedFrames().size(), posesBefore.size() + 1);
  double worstCentre = 0, worstRotation = 0;
  for (std::size_t i = 0; i < posesBefore.size(); ++i) {
    const SE3d expected = moved(posesBefore[i]);
    const SE3d now = Tracker<Monocular>::worldPose(tracker.trackedFrames()[i]);
    worstCentre = std::max(worstCentre, (now.inverse().translation() - expected.inverse().translation()).norm());
    worstRotation = std::max(worstRotation, (now.rotationMatrix() - expected.rotationMatrix()).norm());
  }
  std::printf("  after the merge: kept frames off by %.2e (centre), %.2e (rotation)\n", worstCentre, worstRotation);
  EXPECT_LT(worstCentre, 1e-9);
  EXPECT_LT(worstRotation, 1e-9);
  // The motion model predicted the frame after the merge (its matches found by projection).
  const std::vector<StageEvent> events = timer.events();
  ASSERT_GE(events.size(), 2u);
  const double matchesBefore = frameCounter(events[events.size() - 2], "motion_matches");
  const double matchesAfter = frameCounter(events.back(), "motion_matches");
  std::printf("  motion-model matches: %.0f before the merge, %.0f after\n", matchesBefore, matchesAfter);
  ASSERT_GT(matchesBefore, 50);
  EXPECT_GT(matchesAfter, 0.8 * matchesBefore);
  // And it goes on in the merged map's unit.
  ASSERT_TRUE(tracker.motionModel());
  EXPECT_NEAR(tracker.motionModel()->translation().norm() / stepBefore, S.scale(), 0.3 * S.scale());
}

}  // namespace
}  // namespace orbis
