// RunOptions::realtime (orbis run --realtime): frames are fed at their timestamps, as from a live
// camera, and pacing changes nothing but when each frame is tracked.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "orbis/synth/writers.hpp"
#include "orbis/system/dataset_runner.hpp"

namespace {

using namespace orbis;
namespace fs = std::filesystem;

std::string readFile(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

RunReport runTenFrames(const fs::path& sequence, const fs::path& out, bool realtime) {
  auto dataset = openDataset(DatasetKind::TumRgbd, sequence);
  RunOptions options;
  options.settings = sequence / "settings.yaml";
  options.vocabulary = defaultVocabularyPath();
  options.outDir = out;
  options.deterministic = true;  // the same trajectory paced or not
  options.progress = false;
  options.realtime = realtime;
  return runDataset(*dataset, options);
}

TEST(RealtimePacing, TenFramesAtTenHertzTakeNineTenthsOfASecond) {
  const fs::path dir = fs::temp_directory_path() / "orbis_realtime_pacing";
  fs::remove_all(dir);
  synth::SynthOptions o;
  o.frames = 10;
  o.fps = 10;  // timestamps 0.1 s apart: the last frame is due 0.9 s after the first
  o.width = 320;
  o.height = 240;
  o.fx = 250;
  o.seed = 3;
  o.threads = 2;
  synth::SyntheticSequence sequence(o);
  synth::writeSynthSequence(sequence, synth::SynthLayout::Tum, dir / "sequence");

  const RunReport paced = runTenFrames(dir / "sequence", dir / "paced", true);
  EXPECT_EQ(paced.stats.frames, 10u);
  // Only a lower bound: a loaded machine may take longer, never shorter.
  EXPECT_GE(paced.seconds, 0.85);
  const RunReport unpaced = runTenFrames(dir / "sequence", dir / "unpaced", false);
  EXPECT_EQ(unpaced.stats.frames, 10u);
  EXPECT_EQ(readFile(dir / "paced" / "trajectory.txt"), readFile(dir / "unpaced" / "trajectory.txt"));
  fs::remove_all(dir);
}

}  // namespace
