// Map files: a hand-built map survives the round trip field by field, and every kind of fault
// (truncation, a flipped bit, another vocabulary, sensor or camera) is a clear orbis::Error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

#include "orbis/bow/vocabulary_training.hpp"
#include "orbis/io/map_file.hpp"
#include "orbis/util/error.hpp"
#include "map_file_bytes.hpp"

namespace {

namespace fs = std::filesystem;
using namespace orbis;

MapIntrinsics camera() {
  MapIntrinsics K;
  K.fx = 500;
  K.fy = 501;
  K.cx = 320;
  K.cy = 240;
  K.bf = 50;
  K.closeDepth = 4;
  K.maxX = 640;
  K.maxY = 480;
  return K;
}

std::shared_ptr<const FrameFeatures> randomFeatures(std::mt19937_64& rng, std::size_t n) {
  auto f = std::make_shared<FrameFeatures>();
  f->scales = ScaleLevels(8, 1.2f);
  f->closeDepth = 4;
  std::uniform_real_distribution<float> u(0, 640), v(0, 480), angle(0, 360), depth(0.5f, 6.f);
  for (std::size_t i = 0; i < n; ++i) {
    const Keypoint k{u(rng), v(rng), angle(rng), static_cast<float>(rng() % 100), static_cast<int>(rng() % 8)};
    f->keypoints.push_back(k);
    f->keypointsUn.push_back(k);
    OrbDescriptor d;
    for (auto& w : d.words) w = rng();
    f->descriptors.push_back(d);
    const float z = i % 4 == 0 ? -1.f : depth(rng);
    f->depth.push_back(z);
    f->uRight.push_back(z > 0 ? k.u - 50.f / z : -1.f);
  }
  f->grid.build(f->keypointsUn, 0, 640, 0, 480);
  return f;
}

// Five keyframes along x, points seen by two or three of them, a culled keyframe and point, and
// a loop edge: every part of the file has something in it.
void buildMap(Map& map) {
  std::mt19937_64 rng(5);
  constexpr std::size_t kKeypoints = 80;
  std::vector<KeyFrame*> kfs;
  for (int k = 0; k < 5; ++k) {
    const SE3d Tcw = SE3d::exp((SE3d::Tangent() << -0.3 * k, 0.01 * k, 0, 0.02 * k, -0.01, 0.005 * k).finished());
    std::vector<bow::WordEntry> words;
    std::vector<std::pair<bow::NodeId, std::uint32_t>> groups;
    for (std::uint32_t w = 0; w < 20; ++w) words.push_back({static_cast<bow::WordId>(rng() % 1000), 0.05});
    for (std::uint32_t i = 0; i < kKeypoints; ++i) groups.emplace_back(static_cast<bow::NodeId>(rng() % 30), i);
    kfs.push_back(map.createKeyFrame(10 * k, 1.0 + k, Tcw, randomFeatures(rng, kKeypoints), camera(),
                                     bow::BowVector::fromUnsorted(words, true), bow::FeatureVector::fromPairs(groups)));
  }
  for (int p = 0; p < 60; ++p) {
    const Eigen::Vector3d position(0.1 * p - 3, 0.05 * (p % 7), 3 + 0.02 * p);
    const std::size_t first = static_cast<std::size_t>(p) % 4;
    MapPoint* point = map.createMapPoint(position, kfs[first], kfs[first]->frameIndex);
    for (std::size_t k = first; k < std::min<std::size_t>(first + 2 + p % 2, kfs.size()); ++k) {
      const std::size_t slot = static_cast<std::size_t>(p);
      point->addObservation(kfs[k], slot);
      kfs[k]->setPoint(slot, point);
    }
    point->computeDistinctiveDescriptor();
    point->updateNormalAndDepth();
    point->increaseVisible(p);
    point->increaseFound(p / 2);
  }
  for (KeyFrame* kf : kfs) kf->updateConnections();
  // A chain for the spanning tree, as keyframes inserted in order would form.
  for (std::size_t k = 1; k < kfs.size(); ++k) kfs[k]->changeParent(kfs[k - 1]);
  kfs[4]->addLoopEdge(kfs[0]);
  kfs[0]->addLoopEdge(kfs[4]);
  map.mapPoint(7)->setBad();
  kfs[2]->setBad();
  for (MapPoint* p : map.mapPoints()) p->updateNormalAndDepth();  // as mapping would after culling
}

fs::path tempFile(const std::string& name) {
  return fs::temp_directory_path() / ("orbis_mapfile_" + std::to_string(::getpid()) + "_" + name);
}

constexpr std::uint64_t kVocabulary = 0x1234abcd5678ef00ull;

MapFileInfo expectation() { return {SensorKind::Rgbd, camera(), kVocabulary, 0, 0}; }

fs::path savedMap(const std::string& name) {
  Map map;
  buildMap(map);
  const fs::path file = tempFile(name);
  writeMapFile(file, map, expectation());
  return file;
}

std::vector<char> readBytes(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void writeBytes(const fs::path& f, const std::vector<char>& b) {
  std::ofstream out(f, std::ios::binary | std::ios::trunc);
  out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

// Loading must fail with an orbis::Error naming the file and containing `expected`, and leave the
// map empty.
void expectLoadError(const fs::path& file, const MapFileInfo& expected, const std::string& fragment) {
  Map map;
  try {
    readMapFile(file, map, expected);
    ADD_FAILURE() << "loaded without error; expected: " << fragment;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
  EXPECT_EQ(map.createdKeyFrames(), 0u);
  EXPECT_EQ(map.createdMapPoints(), 0u);
}

TEST(MapFile, RoundTripKeepsEveryField) {
  Map original;
  buildMap(original);
  const fs::path file = tempFile("roundtrip.map");
  writeMapFile(file, original, expectation());
  Map loaded;
  const MapFileInfo info = readMapFile(file, loaded, expectation());
  const auto a = original.keyFrames(), b = loaded.keyFrames();
  ASSERT_EQ(a.size(), 4u);  // one of five culled
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(info.keyFrames, a.size());
  EXPECT_EQ(info.mapPoints, original.mapPointCount());
  ASSERT_EQ(loaded.mapPointCount(), original.mapPointCount());
  // Ids are renumbered in order: map original ids to loaded keyframes by position.
  std::map<KeyFrameId, KeyFrame*> toLoaded;
  for (std::size_t k = 0; k < a.size(); ++k) toLoaded[a[k]->id] = b[k];
  for (std::size_t k = 0; k < a.size(); ++k) {
    const KeyFrame& x = *a[k];
    const KeyFrame& y = *b[k];
    EXPECT_EQ(x.frameIndex, y.frameIndex);
    EXPECT_EQ(x.timestamp, y.timestamp);
    // The rotation is stored as its quaternion and re-normalised on load: equal to rounding.
    EXPECT_TRUE(x.Tcw().matrix().isApprox(y.Tcw().matrix(), 1e-14));
    const FrameFeatures &fx = x.features(), &fy = y.features();
    ASSERT_EQ(fx.size(), fy.size());
    for (std::size_t i = 0; i < fx.size(); ++i) {
      EXPECT_EQ(fx.keypointsUn[i].u, fy.keypointsUn[i].u);
      EXPECT_EQ(fx.keypoints[i].octave, fy.keypoints[i].octave);
      EXPECT_EQ(fx.keypoints[i].angle, fy.keypoints[i].angle);
      EXPECT_EQ(fx.descriptors[i], fy.descriptors[i]);
      EXPECT_EQ(fx.uRight[i], fy.uRight[i]);
      EXPECT_EQ(fx.depth[i], fy.depth[i]);
    }
    EXPECT_EQ(fx.scales.sigma2, fy.scales.sigma2);
    EXPECT_EQ(x.featuresInArea(320, 240, 100), y.featuresInArea(320, 240, 100));  // grid rebuilt
    EXPECT_EQ(x.bowVector(), y.bowVector());
    EXPECT_EQ(x.featureVector(), y.featureVector());
    ASSERT_EQ(x.covisibles().size(), y.covisibles().size());
    for (std::size_t c = 0; c < x.covisibles().size(); ++c) {
      EXPECT_EQ(toLoaded.at(x.covisibles()[c]->id), y.covisibles()[c]);
      EXPECT_EQ(x.weight(x.covisibles()[c]), y.weight(y.covisibles()[c]));
    }
    if (x.parent()) EXPECT_EQ(toLoaded.at(x.parent()->id), y.parent());
    else EXPECT_EQ(y.parent(), nullptr);
    EXPECT_EQ(x.loopEdges().size(), y.loopEdges().size());
    for (std::size_t i = 0; i < x.size(); ++i) EXPECT_EQ(x.point(i) != nullptr, y.point(i) != nullptr);
  }
  EXPECT_EQ(b.front()->loopEdges().size(), 1u);
  const auto pa = original.mapPoints(), pb = loaded.mapPoints();
  for (std::size_t k = 0; k < pa.size(); ++k) {
    EXPECT_EQ(pa[k]->position(), pb[k]->position());
    EXPECT_EQ(pa[k]->descriptor(), pb[k]->descriptor());
    // Recomputed from the (re-normalised) poses and the reference keyframe (a culled one is
    // replaced by an observer, which changes the distances: compare the others).
    if (!pa[k]->reference()->isBad()) {
      EXPECT_TRUE(pa[k]->normal().isApprox(pb[k]->normal(), 1e-12));
      EXPECT_FLOAT_EQ(pa[k]->minDistanceInvariance(), pb[k]->minDistanceInvariance());
      EXPECT_FLOAT_EQ(pa[k]->maxDistanceInvariance(), pb[k]->maxDistanceInvariance());
    }
    EXPECT_EQ(pa[k]->visible(), pb[k]->visible());
    EXPECT_EQ(pa[k]->found(), pb[k]->found());
    ASSERT_EQ(pa[k]->observations().size(), pb[k]->observations().size());
    auto ia = pa[k]->observations().begin();
    for (const auto& [kf, index] : pb[k]->observations()) {
      EXPECT_EQ(toLoaded.at(ia->first->id), kf);
      EXPECT_EQ(ia->second, index);
      EXPECT_EQ(kf->point(index), pb[k]);
      ++ia;
    }
  }
  // Saving the loaded map again writes as much (nothing lost or added on the way).
  const fs::path again = tempFile("roundtrip2.map");
  writeMapFile(again, loaded, expectation());
  EXPECT_EQ(readBytes(file).size(), readBytes(again).size());
  fs::remove(file);
  fs::remove(again);
}

TEST(MapFile, TruncatedFileIsAnError) {
  const fs::path file = savedMap("truncated.map");
  std::vector<char> bytes = readBytes(file);
  for (std::size_t keep : {bytes.size() - 1, bytes.size() / 2, std::size_t{20}, std::size_t{0}}) {
    writeBytes(file, std::vector<char>(bytes.begin(), bytes.begin() + static_cast<long>(keep)));
    expectLoadError(file, expectation(), "truncated");
  }
  fs::remove(file);
}

TEST(MapFile, FlippedBitIsAnError) {
  const fs::path file = savedMap("bitflip.map");
  const std::vector<char> bytes = readBytes(file);
  for (std::size_t at : {bytes.size() / 3, bytes.size() / 2, bytes.size() - 3}) {
    std::vector<char> corrupt = bytes;
    corrupt[at] = static_cast<char>(corrupt[at] ^ 0x10);
    writeBytes(file, corrupt);
    expectLoadError(file, expectation(), "checksum mismatch");
  }
  std::vector<char> badMagic = bytes;
  badMagic[0] = 'X';
  writeBytes(file, badMagic);
  expectLoadError(file, expectation(), "not an orbis map file");
  fs::remove(file);
}

TEST(MapFile, OtherVocabularySensorOrCameraIsAnError) {
  const fs::path file = savedMap("mismatch.map");
  MapFileInfo otherVocabulary = expectation();
  otherVocabulary.vocabularyChecksum ^= 1;
  expectLoadError(file, otherVocabulary, "another vocabulary");
  MapFileInfo otherSensor = expectation();
  otherSensor.sensor = SensorKind::Stereo;
  expectLoadError(file, otherSensor, "map made with sensor rgbd, this system's sensor is stereo");
  MapFileInfo otherCamera = expectation();
  otherCamera.intrinsics.fx = 520;
  expectLoadError(file, otherCamera, "key fx");
  // Word ids (below 1000 here) beyond a vocabulary of 10 words: a corrupt id must not reach the
  // keyframe database, whose inverted index it would size.
  MapFileInfo smallVocabulary = expectation();
  smallVocabulary.vocabularyWords = 10;
  expectLoadError(file, smallVocabulary, "word id beyond this system's vocabulary");
  MapFileInfo fewNodes = expectation();
  fewNodes.vocabularyNodes = 5;
  expectLoadError(file, fewNodes, "feature vector node beyond this system's vocabulary");
  fs::remove(file);
}

TEST(MapFile, LoadsOnlyIntoAnEmptyMap) {
  const fs::path file = savedMap("nonempty.map");
  Map map;
  buildMap(map);
  EXPECT_THROW(readMapFile(file, map, expectation()), Error);
  fs::remove(file);
}

TEST(MapFile, VocabularyChecksumTellsVocabulariesApart) {
  using bow::randomVocabulary;
  const auto a = randomVocabulary<OrbDescriptor, HammingDistance>(4, 2, 1);
  const auto b = randomVocabulary<OrbDescriptor, HammingDistance>(4, 2, 2);
  const auto a2 = randomVocabulary<OrbDescriptor, HammingDistance>(4, 2, 1);
  EXPECT_EQ(vocabularyChecksum(a), vocabularyChecksum(a2));
  EXPECT_NE(vocabularyChecksum(a), vocabularyChecksum(b));
}

}  // namespace

namespace {

TEST(MapFile, InfoReadsTheHeaderAndChecksTheFile) {
  const fs::path file = savedMap("info.map");
  const MapFileInfo info = readMapFileInfo(file);
  EXPECT_EQ(info.sensor, expectation().sensor);
  EXPECT_EQ(info.vocabularyChecksum, expectation().vocabularyChecksum);
  EXPECT_EQ(info.keyFrames, 4u);
  Map map;
  EXPECT_EQ(readMapFile(file, map, info).keyFrames, 4u);  // what a reader of any map passes
  std::vector<char> bytes = readBytes(file);
  bytes[bytes.size() / 2] ^= 1;
  writeBytes(file, bytes);
  EXPECT_THROW(readMapFileInfo(file), Error);
}

}  // namespace

namespace {

// Where the header's fields sit (io/map_file.hpp): version at 8, and the scale flag (version 2)
// after the first 128 bytes.
constexpr std::size_t kVersionOffset = 8, kScaleFlagOffset = 128;
using test::resealMapFile;

MapFileInfo monocularExpectation() {
  MapFileInfo info = expectation();
  info.sensor = SensorKind::Monocular;
  info.metricScale = false;
  return info;
}

TEST(MapFile, RecordsWhetherTheScaleIsMetric) {
  Map map;
  buildMap(map);
  const fs::path file = tempFile("monocular.map");
  writeMapFile(file, map, monocularExpectation());
  EXPECT_FALSE(readMapFileInfo(file).metricScale);
  Map loaded;
  EXPECT_FALSE(readMapFile(file, loaded, monocularExpectation()).metricScale);
  MapFileInfo metric = monocularExpectation();
  metric.metricScale = true;
  expectLoadError(file, metric, "map with arbitrary scale, this system's sensor needs metric scale");
  EXPECT_TRUE(readMapFileInfo(savedMap("metric.map")).metricScale);
  fs::remove(tempFile("metric.map"));

  std::vector<char> bytes = readBytes(file);
  bytes[kScaleFlagOffset] = 2;
  resealMapFile(bytes);
  writeBytes(file, bytes);
  expectLoadError(file, monocularExpectation(), "scale flag neither metric (1) nor arbitrary (0)");
  fs::remove(file);
}

// The atlas section a version 3 file ends with (before the trailer): its length.
std::size_t atlasSectionBytes(const Map& map) {
  return 8 + 16 * map.mapRecords().size() + 4 + 5 * map.keyFrameCount();
}

// Turns a version 3 file's bytes into a version 2 file's: no atlas section.
void downgradeToVersionTwo(std::vector<char>& bytes, const Map& map) {
  ASSERT_EQ(bytes[kVersionOffset], 3);
  bytes[kVersionOffset] = 2;
  const auto trailer = bytes.end() - 8;
  bytes.erase(trailer - static_cast<std::ptrdiff_t>(atlasSectionBytes(map)), trailer);
}

// A version 1 file (before the scale flag) still loads: its scale follows from its sensor.
TEST(MapFile, VersionOneFilesLoadWithTheScaleOfTheirSensor) {
  for (const bool monocular : {false, true}) {
    Map map;
    buildMap(map);
    const fs::path file = tempFile("version1.map");
    const MapFileInfo expected = monocular ? monocularExpectation() : expectation();
    writeMapFile(file, map, expected);
    std::vector<char> bytes = readBytes(file);
    downgradeToVersionTwo(bytes, map);
    bytes[kVersionOffset] = 1;
    bytes.erase(bytes.begin() + kScaleFlagOffset, bytes.begin() + kScaleFlagOffset + 4);
    resealMapFile(bytes);
    writeBytes(file, bytes);
    Map loaded;
    const MapFileInfo info = readMapFile(file, loaded, expected);
    EXPECT_EQ(info.metricScale, !monocular);
    EXPECT_EQ(info.version, 1u);
    EXPECT_EQ(loaded.keyFrameCount(), map.keyFrameCount());
    EXPECT_EQ(loaded.mapPointCount(), map.mapPointCount());
    bytes[kVersionOffset] = 4;  // a newer format than this reader knows
    resealMapFile(bytes);
    writeBytes(file, bytes);
    expectLoadError(file, expected, "map file format version 4, this orbis reads versions 1 to 3");
    fs::remove(file);
  }
}

// A version 2 file (before the atlas) loads as one map whose first keyframe is the root.
TEST(MapFile, VersionTwoFilesLoadAsOneMap) {
  Map map;
  buildMap(map);
  const fs::path file = tempFile("version2.map");
  writeMapFile(file, map, expectation());
  std::vector<char> bytes = readBytes(file);
  downgradeToVersionTwo(bytes, map);
  resealMapFile(bytes);
  writeBytes(file, bytes);
  Map loaded;
  EXPECT_EQ(readMapFile(file, loaded, expectation()).version, 2u);
  EXPECT_EQ(loaded.keyFrameCount(), map.keyFrameCount());
  EXPECT_EQ(loaded.mapRecords().size(), 1u);
  ASSERT_FALSE(loaded.keyFrames().empty());
  EXPECT_TRUE(loaded.keyFrames().front()->isMapRoot());
  EXPECT_TRUE(loaded.keyFrames().front()->isGauge());
  for (const KeyFrame* kf : loaded.keyFrames()) EXPECT_EQ(kf->mapId(), 0u);
  fs::remove(file);
}

// An atlas of several maps (one merged away) saves and loads with its maps, roots and active map.
TEST(MapFile, AtlasOfSeveralMapsRoundTrips) {
  Map map;
  buildMap(map);
  const std::size_t firstMapKeyFrames = map.keyFrameCount();
  {
    std::lock_guard lock(map.mutex());
    map.startNewMap(40);
    map.startNewMap(50);
  }
  buildMap(map);  // into map 2
  {
    std::lock_guard lock(map.mutex());
    map.mergeInto(1, 2);  // map 1 never got a keyframe; merged all the same
  }
  const fs::path file = tempFile("atlas.map");
  writeMapFile(file, map, expectation());
  Map loaded;
  EXPECT_EQ(readMapFile(file, loaded, expectation()).version, kMapFileVersion);
  ASSERT_EQ(loaded.mapRecords().size(), 3u);
  EXPECT_EQ(loaded.activeMapId(), 2u);
  EXPECT_EQ(loaded.mapRecords()[2].startFrame, 50u);
  EXPECT_EQ(loaded.mapRecords()[1].mergedInto, std::optional<std::uint32_t>(2));
  EXPECT_EQ(loaded.keyFrameCount(0), firstMapKeyFrames);
  EXPECT_EQ(loaded.keyFrameCount(2), map.keyFrameCount(2));
  EXPECT_EQ(loaded.mapPointCount(2), map.mapPointCount(2));
  int roots = 0;
  for (const KeyFrame* kf : loaded.keyFrames()) roots += kf->isMapRoot() && kf->isGauge();
  EXPECT_EQ(roots, 2);

  std::vector<char> bytes = readBytes(file);
  bytes[bytes.size() - 8 - 1] = 7;  // the last keyframe's flags
  resealMapFile(bytes);
  writeBytes(file, bytes);
  expectLoadError(file, expectation(), "impossible keyframe map flags");
  fs::remove(file);
}

}  // namespace
