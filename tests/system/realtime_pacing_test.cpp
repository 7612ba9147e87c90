// RunOptions::realtime (orbis run --realtime): frames are fed at their timestamps, as from a live
// camera, and pacing changes nothing but when each frame is tracked.
#include <gtest/gtest.h>

#include <filesystem>

#include "orbis/synth/writers.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "slam_test_util.hpp"
#include "test_data.hpp"

namespace {

using namespace orbis;
namespace fs = std::filesystem;

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
  synth::SynthOptions o = test::loopSequence(3);
  o.frames = 10;
  o.fps = 10;  // timestamps 0.1 s apart: the last frame is due 0.9 s after the first
  synth::SyntheticSequence sequence(o);
  synth::writeSynthSequence(sequence, synth::SynthLayout::Tum, dir / "sequence");

  const RunReport paced = runTenFrames(dir / "sequence", dir / "paced", true);
  EXPECT_EQ(paced.stats.frames, 10u);
  // Only a lower bound: a loaded machine may take longer, never shorter.
  EXPECT_GE(paced.seconds, 0.85);
  const RunReport unpaced = runTenFrames(dir / "sequence", dir / "unpaced", false);
  EXPECT_EQ(unpaced.stats.frames, 10u);
  EXPECT_EQ(test::fileBytes(dir / "paced" / "trajectory.txt"), test::fileBytes(dir / "unpaced" / "trajectory.txt"));
  fs::remove_all(dir);
}

}  // namespace
