// Place recognition on real frames: TUM fr3 teddy (first 200 frames) with the shipped
// vocabulary. Ground truth decides which frames see the same place (camera centres within
// 0.3 m and optical axes within 30 degrees). Each frame queries a database of the frames at
// least 20 frames away; precision@1 and recall@1 are printed, only a loose floor is asserted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "orbis/bow/keyframe_database.hpp"
#include "orbis/bow/vocabulary.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "orbis/io/trajectory.hpp"
#include "test_data.hpp"

namespace orbis::bow {
namespace {

constexpr double kSamePlaceMetres = 0.3;
constexpr double kSamePlaceDegrees = 30.0;
constexpr std::size_t kMinFrameGap = 20;

struct Frame {
  std::string image;
  Eigen::Vector3d centre, axis;  // camera centre and optical axis in the world
};

bool samePlace(const Frame& a, const Frame& b) {
  const double angle = std::acos(std::clamp(a.axis.dot(b.axis), -1.0, 1.0)) * 180.0 / M_PI;
  return (a.centre - b.centre).norm() <= kSamePlaceMetres && angle <= kSamePlaceDegrees;
}

TEST(PlaceRecognition, TumTeddyPrecisionAndRecallAtOne) {
  ORBIS_REQUIRE_DATASET(root, "tum_fr3_teddy_200");
  // ORBIS_VOCABULARY evaluates another vocabulary (e.g. one trained without these frames).
  const char* env = std::getenv("ORBIS_VOCABULARY");
  const auto vocabularyPath = env && *env ? std::filesystem::path(env)
                                          : test::sourceDir() / "vocabulary" / "orbis_orb_k10_L5.bin";
  ASSERT_TRUE(std::filesystem::exists(vocabularyPath)) << vocabularyPath;
  const OrbVocabulary vocabulary = OrbVocabulary::load(vocabularyPath);

  std::vector<double> imageTimes;
  std::vector<std::string> imageFiles;
  forEachTextRow(root / "rgb.txt", [&](const TextRow& row) {
    imageTimes.push_back(parseDouble(row.fields[0], root / "rgb.txt", row.line));
    imageFiles.emplace_back(row.fields[1]);
  });
  const Trajectory truth = readTrajectory(root / "groundtruth.txt", TrajectoryFormat::Tum);
  std::vector<double> truthTimes;
  for (const StampedPose& p : truth) truthTimes.push_back(p.t);
  std::vector<Frame> frames;
  for (const auto& [i, j] : associateTimestamps(imageTimes, truthTimes, 0.02)) {
    const SE3d& pose = truth[j].pose;
    frames.push_back({imageFiles[i], pose.translation(), pose.rotationMatrix().col(2)});
  }
  ASSERT_GT(frames.size(), 150u);

  OrbExtractor extractor;
  std::vector<Keypoint> keypoints;
  std::vector<OrbDescriptor> descriptors;
  std::vector<BowVector> bows;
  KeyframeDatabase database;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat image = cv::imread((root / frames[i].image).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << frames[i].image;
    extractor.extract(image, keypoints, descriptors);
    bows.push_back(vocabulary.transform(descriptors));
    database.add(i, bows.back());
  }

  std::size_t answered = 0, correct = 0, answerable = 0;
  for (std::size_t q = 0; q < frames.size(); ++q) {
    const auto farEnough = [&](KeyframeId id) { return (id > q ? id - q : q - id) >= kMinFrameGap; };
    bool hasTrueMatch = false;
    for (std::size_t j = 0; j < frames.size(); ++j) hasTrueMatch |= farEnough(j) && samePlace(frames[q], frames[j]);
    answerable += hasTrueMatch ? 1 : 0;
    const auto best = database.query(bows[q], 1, farEnough);
    if (best.empty()) continue;
    ++answered;
    correct += samePlace(frames[q], frames[static_cast<std::size_t>(best[0].keyframe)]) ? 1 : 0;
  }
  const double precision = answered ? static_cast<double>(correct) / static_cast<double>(answered) : 0.0;
  const double recall = answerable ? static_cast<double>(correct) / static_cast<double>(answerable) : 0.0;
  std::printf("[place recognition] tum_fr3_teddy_200: %zu frames, %zu with a true match >= %zu frames away; "
              "precision@1 %.3f (%zu/%zu), recall@1 %.3f (%zu/%zu)\n",
              frames.size(), answerable, kMinFrameGap, precision, correct, answered, recall, correct, answerable);
  // The same protocol through ORB-SLAM's relocalisation query, with frames within 5 of each
  // other standing in for the covisibility graph; its first candidate is the answer.
  struct Neighbours {
    std::size_t count;
    std::vector<KeyframeId> connectedKeyframes(KeyframeId id) const { return bestCovisibleKeyframes(id, 10); }
    std::vector<KeyframeId> bestCovisibleKeyframes(KeyframeId id, std::size_t n) const {
      std::vector<KeyframeId> out;
      for (KeyframeId step = 1; step <= 5 && out.size() < n; ++step) {
        if (id + step < count) out.push_back(id + step);
        if (id >= step && out.size() < n) out.push_back(id - step);
      }
      return out;
    }
  } neighbours{frames.size()};
  std::size_t relocAnswered = 0, relocCorrect = 0;
  for (std::size_t q = 0; q < frames.size(); ++q) {
    KeyframeDatabase far;
    for (std::size_t j = 0; j < frames.size(); ++j)
      if ((j > q ? j - q : q - j) >= kMinFrameGap) far.add(j, bows[j]);
    const auto candidates = far.detectRelocalisationCandidates(bows[q], neighbours);
    if (candidates.empty()) continue;
    ++relocAnswered;
    relocCorrect += samePlace(frames[q], frames[static_cast<std::size_t>(candidates[0].keyframe)]) ? 1 : 0;
  }
  const double relocPrecision = relocAnswered ? static_cast<double>(relocCorrect) / static_cast<double>(relocAnswered) : 0.0;
  const double relocRecall = answerable ? static_cast<double>(relocCorrect) / static_cast<double>(answerable) : 0.0;
  std::printf("[place recognition] relocalisation query: precision@1 %.3f (%zu/%zu), recall@1 %.3f (%zu/%zu)\n",
              relocPrecision, relocCorrect, relocAnswered, relocRecall, relocCorrect, answerable);
  EXPECT_GT(relocPrecision, 0.4);
  EXPECT_GT(relocRecall, 0.4);
  RecordProperty("precision_at_1", std::to_string(precision));
  RecordProperty("recall_at_1", std::to_string(recall));
  EXPECT_GT(answerable, 20u);
  EXPECT_GT(precision, 0.4);
  EXPECT_GT(recall, 0.4);
}

}  // namespace
}  // namespace orbis::bow
