#include "orbis/bow/vocabulary_file.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "bow/bow_test_util.hpp"
#include "orbis/bow/dbow2_text.hpp"
#include "orbis/util/error.hpp"

namespace orbis::bow {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("orbis_bow_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

std::string readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void writeBytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The error message of loading `p`, or "" when it loads.
std::string loadError(const fs::path& p) {
  try {
    OrbVocabulary::load(p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(VocabularyFile, BinaryRoundTripIsByteExactAndTransformsAlike) {
  TempDir dir;
  const OrbVocabulary v = test::trainSmall();
  v.save(dir.path / "v.bin");
  const OrbVocabulary w = OrbVocabulary::load(dir.path / "v.bin");
  const auto a = v.blob().bytes(), b = w.blob().bytes();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size()), 0);
  EXPECT_EQ(w.wordCount(), v.wordCount());
  EXPECT_EQ(w.weighting(), Weighting::TfIdf);
  const auto images = test::syntheticImages(5, 3, 100, 300, 12);
  for (const auto& image : images) EXPECT_EQ(v.transform(image), w.transform(image));
}

TEST(VocabularyFile, Dbow2TextRoundTripReproducesTheBinary) {
  TempDir dir;
  const OrbVocabulary v = test::trainSmall();
  writeDbow2Text(v, dir.path / "v.txt");
  const OrbVocabulary t = readDbow2Text<OrbVocabulary>(dir.path / "v.txt");
  const auto a = v.blob().bytes(), b = t.blob().bytes();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size()), 0);
}

// A hand-written DBoW2 file, k=2 L=2, nodes deliberately not in breadth-first order.
TEST(VocabularyFile, Dbow2TextParsesAnyTreeOrderAndRenumbersBreadthFirst) {
  TempDir dir;
  std::string zeros, ones;
  for (int i = 0; i < 32; ++i) zeros += " 0", ones += " 255";
  std::string mixed;  // first 16 bytes 255, rest 0
  for (int i = 0; i < 32; ++i) mixed += i < 16 ? " 255" : " 0";
  // file ids: 1 = inner (zeros side), 2 = leaf of 1 (zeros), 3 = inner (ones side),
  //           4 = leaf of 3 (ones), 5 = leaf of 1 (mixed), 6 = leaf of 3 (mixed)
  const std::string text = "2 2 0 0\n"
                           "0 0" + zeros + " 0\n"
                           "1 1" + zeros + " 0.5\n"
                           "0 0" + ones + " 0\n"
                           "3 1" + ones + " 1.5\n"
                           "1 1" + mixed + " 2.5\n"
                           "3 1" + mixed + " 3.5\n";
  writeBytes(dir.path / "tiny.txt", text);
  const OrbVocabulary v = readDbow2Text<OrbVocabulary>(dir.path / "tiny.txt");
  EXPECT_EQ(v.branching(), 2u);
  EXPECT_EQ(v.depth(), 2u);
  ASSERT_EQ(v.nodeCount(), 7u);
  ASSERT_EQ(v.wordCount(), 4u);
  // Breadth-first: root, {file 1, file 3}, {file 2, file 5}, {file 4, file 6}.
  EXPECT_EQ(v.node(0).firstChild, 1u);
  EXPECT_EQ(v.node(1).firstChild, 3u);
  EXPECT_EQ(v.node(2).firstChild, 5u);
  EXPECT_FLOAT_EQ(v.wordWeight(0), 0.5f);
  EXPECT_FLOAT_EQ(v.wordWeight(1), 2.5f);
  EXPECT_FLOAT_EQ(v.wordWeight(2), 1.5f);
  EXPECT_FLOAT_EQ(v.wordWeight(3), 3.5f);
  OrbDescriptor allOnes;
  for (auto& w : allOnes.words) w = ~0ull;
  EXPECT_EQ(v.wordOf(OrbDescriptor{}), 0u);
  EXPECT_EQ(v.wordOf(allOnes), 2u);
}

TEST(VocabularyFile, Dbow2TextDefectsNameTheLine) {
  TempDir dir;
  std::string bytes;
  for (int i = 0; i < 32; ++i) bytes += " 7";
  const auto errorOf = [&](const std::string& text) -> std::string {
    writeBytes(dir.path / "bad.txt", text);
    try {
      readDbow2Text<OrbVocabulary>(dir.path / "bad.txt");
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(errorOf("10 6 0 0\n0 1" + bytes + " 0.5\n0 1 7 7\n").find("line 3"), std::string::npos);
  EXPECT_NE(errorOf("10 6 0 0\n0 1" + bytes + " 0.5\n5 1" + bytes + " 1\n").find("line 3"), std::string::npos);
  EXPECT_NE(errorOf("10 6 0 0\n0 1" + bytes + " 0.5\n1 1" + bytes + " 1\n").find("is a leaf"), std::string::npos);
  EXPECT_NE(errorOf("10 6 1 0\n0 1" + bytes + " 0.5\n").find("line 1"), std::string::npos);
  EXPECT_NE(errorOf("10 6 0 0\n0 0" + bytes + " 0\n").find("without children"), std::string::npos);
  EXPECT_NE(errorOf("").find("empty"), std::string::npos);
  EXPECT_EQ(errorOf("10 6 0 0\n0 1" + bytes + " 0.5\n"), "");
}

TEST(VocabularyFile, EveryTruncationIsAClearError) {
  TempDir dir;
  test::trainSmall().save(dir.path / "v.bin");
  const std::string good = readBytes(dir.path / "v.bin");
  for (std::size_t keep : {std::size_t{0}, std::size_t{10}, std::size_t{63}, std::size_t{64}, good.size() / 2,
                           good.size() - 9, good.size() - 1}) {
    writeBytes(dir.path / "cut.bin", good.substr(0, keep));
    const std::string error = loadError(dir.path / "cut.bin");
    EXPECT_NE(error.find("truncated"), std::string::npos) << keep << ": " << error;
    EXPECT_NE(error.find("cut.bin"), std::string::npos) << error;
  }
  writeBytes(dir.path / "long.bin", good + "x");
  EXPECT_NE(loadError(dir.path / "long.bin").find("unexpected bytes"), std::string::npos);
}

TEST(VocabularyFile, EveryFlippedBitIsDetected) {
  TempDir dir;
  test::trainSmall().save(dir.path / "v.bin");
  const std::string good = readBytes(dir.path / "v.bin");
  detail::SplitMix64 rng{3};
  // Every third header bit, then random bits across payload and checksum.
  std::vector<std::size_t> bits;
  for (std::size_t b = 0; b < 64 * 8; b += 3) bits.push_back(b);
  for (int i = 0; i < 150; ++i) bits.push_back(rng.below(good.size() * 8));
  for (std::size_t bit : bits) {
    std::string bad = good;
    bad[bit / 8] = static_cast<char>(bad[bit / 8] ^ (1 << (bit % 8)));
    writeBytes(dir.path / "flip.bin", bad);
    const std::string error = loadError(dir.path / "flip.bin");
    ASSERT_FALSE(error.empty()) << "bit " << bit << " flipped went unnoticed";
    EXPECT_NE(error.find("flip.bin"), std::string::npos) << error;
  }
}

TEST(VocabularyFile, ForeignFilesAreRejectedWithAReason) {
  TempDir dir;
  writeBytes(dir.path / "text.bin", std::string("10 6 0 0\n") + std::string(200, '1'));
  EXPECT_NE(loadError(dir.path / "text.bin").find("bad magic"), std::string::npos);
  EXPECT_NE(loadError(dir.path / "missing.bin").find("cannot open"), std::string::npos);
}

TEST(VocabularyFile, ChecksumDependsOnEveryByte) {
  std::string data(1000, 'a');
  const auto base = checksum64(data.data(), data.size());
  for (std::size_t i = 0; i < data.size(); i += 37) {
    std::string changed = data;
    changed[i] = 'b';
    EXPECT_NE(checksum64(changed.data(), changed.size()), base) << i;
  }
  EXPECT_NE(checksum64(data.data(), 999), base);
}

}  // namespace
}  // namespace orbis::bow

namespace orbis::bow {
namespace {

TEST(VocabularyFile, RandomCompleteTreeRoundTripsThroughBothFormats) {
  TempDir dir;
  const OrbVocabulary v = randomVocabulary<OrbDescriptor, HammingDistance>(4, 3, 9);
  EXPECT_EQ(v.wordCount(), 64u);
  EXPECT_EQ(v.nodeCount(), 85u);
  writeDbow2Text(v, dir.path / "r.txt");
  const OrbVocabulary t = readDbow2Text<OrbVocabulary>(dir.path / "r.txt");
  const auto a = v.blob().bytes(), b = t.blob().bytes();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size()), 0);
  // Same tree, same words: lookups agree.
  detail::SplitMix64 rng{4};
  for (int i = 0; i < 100; ++i) {
    const OrbDescriptor d = test::randomDescriptor(rng);
    EXPECT_EQ(v.wordOf(d), t.wordOf(d));
    EXPECT_LT(v.wordOf(d), 64u);
  }
}

}  // namespace
}  // namespace orbis::bow
