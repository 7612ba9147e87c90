// Systematic corruption of the two binary formats, a small real map file and a vocabulary file:
// each is truncated at a few hundred offsets and has a few hundred random bits flipped (fixed
// seed). Every damaged file must be refused with an orbis::Error naming the file — never a crash,
// a hang, another exception or an allocation the file's size cannot justify.
//
// Each damage is tried twice: as it is (the size and checksum checks must catch it), and
// "resealed" — the declared size and checksum trailer recomputed over the damaged bytes, as a
// crafted file would have them — so the structure checks behind the checksum meet it too. A
// resealed bit flip may land in a value every bit pattern of which is valid (a descriptor bit, a
// coordinate's last digit); such a file is loaded, which is right, and is counted, not failed.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <string>
#include <vector>

#include "orbis/bow/vocabulary.hpp"
#include "orbis/bow/vocabulary_training.hpp"
#include "orbis/io/map_file.hpp"
#include "orbis/util/error.hpp"
#include "map_file_bytes.hpp"

namespace {

namespace fs = std::filesystem;
using namespace orbis;
using Bytes = std::vector<char>;

constexpr std::size_t kOffsets = 300, kFlips = 300;

MapIntrinsics smallCamera() {
  MapIntrinsics K;
  K.fx = K.fy = 250;
  K.cx = 160;
  K.cy = 120;
  K.bf = 25;
  K.closeDepth = 4;
  K.maxX = 320;
  K.maxY = 240;
  return K;
}

constexpr std::uint64_t kVocabularyChecksum = 0x1234abcd5678ef00ull;
MapFileInfo expectation() { return {SensorKind::Rgbd, smallCamera(), kVocabularyChecksum, 0, 0}; }

// Three keyframes of 12 keypoints, 10 points seen by two or three of them, a spanning-tree chain
// and a loop edge: every section of the format has something in it. (The same map is the fuzz
// seed tests/fuzz/corpus/map_file/small.map.)
Bytes smallMapFile(const fs::path& file) {
  Map map;
  std::lock_guard lock(map.mutex());
  std::mt19937_64 rng(7);
  std::vector<KeyFrame*> kfs;
  for (int k = 0; k < 3; ++k) {
    auto f = std::make_shared<FrameFeatures>();
    f->scales = ScaleLevels(3, 1.2f);
    f->closeDepth = 4;
    for (int i = 0; i < 12; ++i) {
      const Keypoint kp{float(rng() % 320), float(rng() % 240), float(rng() % 360), 10.f, int(rng() % 3)};
      f->keypoints.push_back(kp);
      f->keypointsUn.push_back(kp);
      OrbDescriptor d;
      for (auto& w : d.words) w = rng();
      f->descriptors.push_back(d);
      const float z = i % 4 == 0 ? -1.f : 1.f + float(rng() % 5);
      f->depth.push_back(z);
      f->uRight.push_back(z > 0 ? kp.u - 25.f / z : -1.f);
    }
    f->grid.build(f->keypointsUn, 0, 320, 0, 240);
    std::vector<bow::WordEntry> words;
    std::vector<std::pair<bow::NodeId, std::uint32_t>> groups;
    for (std::uint32_t w = 0; w < 4; ++w) words.push_back({static_cast<bow::WordId>(rng() % 100), 0.25});
    for (std::uint32_t i = 0; i < 12; ++i) groups.emplace_back(static_cast<bow::NodeId>(rng() % 5), i);
    const SE3d Tcw = SE3d::exp((SE3d::Tangent() << -0.3 * k, 0.01 * k, 0, 0.02 * k, -0.01, 0.005 * k).finished());
    kfs.push_back(map.createKeyFrame(10 * k, 1.0 + k, Tcw, f, smallCamera(), bow::BowVector::fromUnsorted(words, true),
                                     bow::FeatureVector::fromPairs(groups)));
  }
  for (int p = 0; p < 10; ++p) {
    MapPoint* point = map.createMapPoint(Eigen::Vector3d(0.1 * p - 0.5, 0.05 * (p % 3), 3 + 0.1 * p), kfs[p % 2],
                                         kfs[p % 2]->frameIndex);
    for (std::size_t k = p % 2; k < 3; ++k) {
      point->addObservation(kfs[k], p);
      kfs[k]->setPoint(p, point);
    }
    point->computeDistinctiveDescriptor();
    point->updateNormalAndDepth();
    point->increaseVisible(p);
    point->increaseFound(p / 2);
  }
  for (KeyFrame* kf : kfs) kf->updateConnections();
  kfs[1]->changeParent(kfs[0]);
  kfs[2]->changeParent(kfs[1]);
  kfs[2]->addLoopEdge(kfs[0]);
  kfs[0]->addLoopEdge(kfs[2]);
  writeMapFile(file, map, expectation());
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void writeBytes(const fs::path& f, const Bytes& b) {
  std::ofstream out(f, std::ios::binary | std::ios::trunc);
  out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

std::uint64_t checksumOf(const Bytes& b, std::size_t end) { return bow::checksum64(b.data(), end); }

Bytes resealMap(Bytes b) {
  test::resealMapFile(b);
  return b;
}

// The vocabulary format: checksum of header and payload in the last 8 bytes (the sizes are
// derived from the header's counts, so a resealed truncation is still a truncation).
Bytes resealVocabulary(Bytes b) {
  if (b.size() < 72) return b;
  const std::uint64_t sum = checksumOf(b, b.size() - 8);
  std::memcpy(b.data() + b.size() - 8, &sum, sizeof sum);
  return b;
}

// Offsets to cut at: every one of the first 200 bytes (the headers), then spread over the rest.
std::vector<std::size_t> cutOffsets(std::size_t size) {
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < std::min<std::size_t>(200, size); ++i) offsets.push_back(i);
  for (std::size_t i = 0; i < kOffsets - 200; ++i) offsets.push_back(200 + (size - 201) * i / (kOffsets - 201));
  return offsets;
}

long maxRssKb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

struct Outcome {
  std::size_t refused = 0, loaded = 0;
};

class BinaryCorruption : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("orbis_corruption_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    rssBefore_ = maxRssKb();
  }
  void TearDown() override {
    fs::remove_all(dir_);
    // A corrupt count that slipped past the size checks would allocate (and zero) gigabytes.
    EXPECT_LT(maxRssKb() - rssBefore_, 200 * 1024) << "peak resident memory grew by more than 200 MB";
  }

  // Loads `bytes` from a file with `load`; a refusal must be an orbis::Error naming the file and,
  // when `mustRefuse`, contain `fragment`.
  template <class Load>
  void tryLoad(const Bytes& bytes, Load load, bool mustRefuse, const std::string& fragment, const std::string& label,
               Outcome& outcome) {
    const fs::path file = dir_ / "damaged.bin";
    writeBytes(file, bytes);
    try {
      load(file);
      ++outcome.loaded;
      if (mustRefuse) ADD_FAILURE() << label << ": loaded without error";
    } catch (const Error& e) {
      ++outcome.refused;
      const std::string message = e.what();
      EXPECT_NE(message.find(file.string()), std::string::npos) << label << ": " << message;
      if (mustRefuse) EXPECT_NE(message.find(fragment), std::string::npos) << label << ": " << message;
    } catch (const std::exception& e) {
      ADD_FAILURE() << label << ": " << typeid(e).name() << ": " << e.what();
    }
  }

  // Cuts `good` at every offset of cutOffsets: refused as it is (with "truncated") and resealed.
  template <class Load, class Reseal>
  void truncations(const Bytes& good, Load load, Reseal reseal) {
    Outcome plain, resealed;
    for (std::size_t keep : cutOffsets(good.size())) {
      const Bytes cut(good.begin(), good.begin() + static_cast<long>(keep));
      tryLoad(cut, load, true, "truncated", "cut at " + std::to_string(keep), plain);
      // Resealed: the parser meets the end of the data inside a record, or leftover bytes.
      tryLoad(reseal(cut), load, true, "", "resealed cut at " + std::to_string(keep), resealed);
    }
    EXPECT_EQ(plain.refused, kOffsets);
    EXPECT_EQ(resealed.refused, kOffsets);
  }

  // Flips kFlips random bits (fixed seed), one at a time: refused as it is, with the fragment
  // `plainError(bit)` names; resealed, loaded or refused. Returns the resealed outcome.
  template <class Load, class Reseal, class PlainError>
  Outcome bitFlips(const Bytes& good, Load load, Reseal reseal, PlainError plainError) {
    std::mt19937_64 rng(19);
    Outcome plain, resealed;
    for (std::size_t i = 0; i < kFlips; ++i) {
      const std::size_t bit = rng() % (good.size() * 8);
      Bytes bad = good;
      bad[bit / 8] = static_cast<char>(bad[bit / 8] ^ (1 << (bit % 8)));
      const std::string label = "bit " + std::to_string(bit);
      tryLoad(bad, load, true, plainError(bit), label, plain);
      tryLoad(reseal(bad), load, false, "", "resealed " + label, resealed);
    }
    EXPECT_EQ(plain.refused, kFlips);
    return resealed;
  }

  fs::path dir_;
  long rssBefore_ = 0;
};

void loadMap(const fs::path& file) {
  Map map;
  std::lock_guard lock(map.mutex());
  readMapFile(file, map, expectation());
  if (map.createdKeyFrames() == 0) throw Error(file.string(), "", "test: nothing loaded");
}

void loadVocabulary(const fs::path& file) { (void)bow::OrbVocabulary::load(file); }

Bytes smallVocabularyFile(const fs::path& file) {
  bow::randomVocabulary<OrbDescriptor, HammingDistance>(4, 3, 9).save(file);
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST_F(BinaryCorruption, MapFileTruncatedAtEveryHeaderByteAndAcrossTheBody) {
  const Bytes good = smallMapFile(dir_ / "good.map");
  ASSERT_GT(good.size(), 2000u);
  truncations(good, loadMap, resealMap);
}

TEST_F(BinaryCorruption, MapFileWithRandomBitFlips) {
  const Bytes good = smallMapFile(dir_ / "good.map");
  // Bytes 0-7 are the magic, 8-11 the version, 16-23 the declared size; the rest is the checksum's.
  const Outcome resealed = bitFlips(good, loadMap, resealMap, [](std::size_t bit) {
    return bit < 64 ? "not an orbis map file" : bit < 96 ? "format version"
                    : bit >= 128 && bit < 192 ? "the header declares" : "checksum mismatch";
  });
  // Most flips land in descriptors, coordinates and scores, which any bit pattern of is a valid
  // map; the structure checks refuse the rest. Printed for the record.
  std::printf("map file, %zu resealed bit flips: %zu refused, %zu loaded\n", kFlips, resealed.refused, resealed.loaded);
}

TEST_F(BinaryCorruption, VocabularyTruncatedAtEveryHeaderByteAndAcrossTheBody) {
  const Bytes good = smallVocabularyFile(dir_ / "good.bin");
  ASSERT_GT(good.size(), 2000u);
  truncations(good, loadVocabulary, resealVocabulary);
}

TEST_F(BinaryCorruption, VocabularyWithRandomBitFlips) {
  const Bytes good = smallVocabularyFile(dir_ / "good.bin");
  const Outcome resealed = bitFlips(good, loadVocabulary, resealVocabulary, [](std::size_t) { return ""; });
  std::printf("vocabulary, %zu resealed bit flips: %zu refused, %zu loaded\n", kFlips, resealed.refused,
              resealed.loaded);
}

}  // namespace
