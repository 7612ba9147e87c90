// Every input in tests/fuzz/corpus/<harness>/ (the seeds, and every input a fuzzer ever found
// crashing, once fixed) replayed through its harness: refused with orbis::Error or read, never
// another exception or a crash. Runs in the ordinary suite, without clang.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "harnesses.hpp"
#include "orbis/util/error.hpp"

namespace orbis::fuzz {
// Test names and failure messages show the harness's name.
void PrintTo(const Harness& harness, std::ostream* out) { *out << harness.name; }
}  // namespace orbis::fuzz

namespace {

namespace fs = std::filesystem;

fs::path corpusDir() { return fs::path(ORBIS_SOURCE_DIR) / "tests" / "fuzz" / "corpus"; }

std::vector<std::uint8_t> readBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

class CorpusReplay : public ::testing::TestWithParam<orbis::fuzz::Harness> {};

TEST_P(CorpusReplay, EveryInputIsReadOrRefusedWithAnOrbisError) {
  const orbis::fuzz::Harness& harness = GetParam();
  const fs::path dir = corpusDir() / std::string(harness.name);
  ASSERT_TRUE(fs::is_directory(dir)) << dir << ": every harness needs a seed corpus";
  std::size_t inputs = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::vector<std::uint8_t> bytes = readBytes(entry.path());
    ++inputs;
    try {
      harness.run(bytes.data(), bytes.size());
    } catch (const orbis::Error&) {
      // refused, naming the file: what a bad input should get
    } catch (const std::exception& e) {
      ADD_FAILURE() << entry.path() << ": " << typeid(e).name() << ": " << e.what();
    }
  }
  EXPECT_GT(inputs, 0u) << dir;
}

// The seeds are well-formed files: each must be read, not refused (a harness that refuses its
// own seeds fuzzes nothing past the first check). Files named crash-* or bad-* are exempt.
TEST_P(CorpusReplay, SeedsAreAccepted) {
  const orbis::fuzz::Harness& harness = GetParam();
  for (const auto& entry : fs::directory_iterator(corpusDir() / std::string(harness.name))) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("crash-", 0) == 0 || name.rfind("bad-", 0) == 0) continue;
    const std::vector<std::uint8_t> bytes = readBytes(entry.path());
    EXPECT_NO_THROW(harness.run(bytes.data(), bytes.size())) << entry.path();
  }
}

INSTANTIATE_TEST_SUITE_P(Parsers, CorpusReplay, ::testing::ValuesIn(orbis::fuzz::harnesses()),
                         [](const ::testing::TestParamInfo<orbis::fuzz::Harness>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
