// The atlas end to end (issue 32) on the rendered corridor loop with a blackout while the camera
// moves on into ground the map has not seen (RGB-D, deterministic):
//  - with the atlas a new map starts after the blackout, the frames after it are tracked, the
//    maps merge when the camera comes back to the start, and every tracked frame then lies in
//    one frame: one SE(3) alignment fits them all;
//  - with the single-map option (ORB-SLAM2) the frames after the blackout are lost until the
//    camera comes back, and there is one map;
//  - the atlas saved and loaded keeps its maps; a loaded atlas is found again by relocalisation.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include <unistd.h>

#include "orbis/eval/metrics.hpp"
#include "orbis/synth/sequence.hpp"
#include "orbis/system/slam.hpp"
#include "slam_test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace orbis;

constexpr int kBlackStart = 100, kBlackCount = 30;

synth::SynthOptions corridorOptions() {
  synth::SynthOptions o = test::loopSequence(1);
  synth::applyScenePreset(synth::ScenePreset::Corridor, o.room, o.path);
  o.extraFrames = 75;  // back over the start: where the maps meet
  o.blackStart = kBlackStart;
  o.blackCount = kBlackCount;
  return o;
}

const std::vector<synth::SynthFrame>& corridorFrames() {
  static const std::vector<synth::SynthFrame> cache = [] {
    synth::SyntheticSequence seq(corridorOptions());
    std::vector<synth::SynthFrame> out;
    for (int i = 0; i < seq.size(); ++i) out.push_back(seq.render(i, false, true));
    return out;
  }();
  return cache;
}

struct AtlasRun {
  std::vector<TrackResult> results;
  Trajectory estimate, groundTruth;
  std::vector<AtlasMapInfo> maps;
  std::vector<MapMergeEvent> merges;
  std::vector<std::uint32_t> frameMaps;
  double ate = 0;
  int trackedAfterBlackout = 0;
};

AtlasRun runCorridor(bool atlas, const fs::path& saveMap = {}) {
  const synth::SynthOptions options = corridorOptions();
  synth::SyntheticSequence seq(options);
  SlamOptions slamOptions;
  slamOptions.deterministic = true;
  slamOptions.fps = options.fps;
  slamOptions.atlas = atlas;
  OrbParams orb;
  orb.features = 1000;
  Slam<Rgbd> slam(test::syntheticCamera<Rgbd>(seq, options.baseline), orb, test::sharedVocabulary(), slamOptions);
  AtlasRun r;
  for (const synth::SynthFrame& f : corridorFrames()) {
    const double t = seq.timestamp(f.index);
    r.groundTruth.push_back({t, f.pose});
    r.results.push_back(slam.track(test::syntheticInput<Rgbd>(f, t)));
    if (f.index >= kBlackStart + kBlackCount && r.results.back().state == TrackingState::Ok) ++r.trackedAfterBlackout;
  }
  slam.shutdown();
  r.estimate = slam.trajectory();
  r.maps = slam.core().maps();
  r.merges = slam.core().merges();
  r.frameMaps = slam.core().trajectoryMaps(true);
  r.ate = eval::computeAte(r.groundTruth, r.estimate, {eval::Alignment::SE3, 0.001}).stats.rmse;
  if (!saveMap.empty()) slam.core().saveMap(saveMap);
  return r;
}

TEST(Atlas, NewMapAfterBlackoutMergesWhenTheCameraReturns) {
  const fs::path file = fs::temp_directory_path() / ("orbis_atlas_" + std::to_string(::getpid()) + ".map");
  const AtlasRun atlas = runCorridor(true, file);
  const AtlasRun single = runCorridor(false);
  const int after = static_cast<int>(corridorFrames().size()) - (kBlackStart + kBlackCount);
  std::cout << "[atlas] corridor RGB-D, blackout " << kBlackStart << ":" << kBlackCount << ": atlas "
            << atlas.trackedAfterBlackout << " / " << after << " frames tracked after it, " << atlas.maps.size()
            << " maps, " << atlas.merges.size() << " merges"
            << (atlas.merges.empty() ? "" : " (at frame " + std::to_string(atlas.merges.front().frameIndex) + ")")
            << ", ATE " << atlas.ate * 1000 << " mm over " << atlas.estimate.size() << " frames; single map "
            << single.trackedAfterBlackout << " / " << after << ", ATE " << single.ate * 1000 << " mm over "
            << single.estimate.size() << "\n";
  // The single map: lost from the blackout until the camera is back where the map is.
  EXPECT_EQ(single.maps.size(), 1u);
  EXPECT_TRUE(single.merges.empty());
  EXPECT_LT(single.trackedAfterBlackout, after * 2 / 3);
  // The atlas: a second map started, then merged into one frame.
  ASSERT_GE(atlas.maps.size(), 2u);
  EXPECT_GE(atlas.trackedAfterBlackout, after * 9 / 10);
  ASSERT_EQ(atlas.merges.size(), 1u);
  const MapMergeEvent& merge = atlas.merges.front();
  EXPECT_NE(merge.activeMap, merge.otherMap);
  EXPECT_GE(merge.inliers, 40);
  // Every tracked frame now in the one map left, and one alignment fits them all: an unmerged or
  // misplaced map would put metres of error there (the corridor loop is 27 m).
  std::size_t live = 0;
  for (const AtlasMapInfo& m : atlas.maps) live += m.merged ? 0 : 1;
  EXPECT_EQ(live, 1u);
  for (std::uint32_t m : atlas.frameMaps) EXPECT_EQ(m, merge.keptMap);
  EXPECT_LT(atlas.ate, 0.05);
  EXPECT_GT(atlas.estimate.size(), single.estimate.size() + static_cast<std::size_t>(after) / 3);

  // The atlas file keeps the maps; a fresh system loads it and relocalises in it.
  synth::SyntheticSequence seq(corridorOptions());
  SlamOptions options;
  options.deterministic = true;
  Slam<Rgbd> loaded(test::syntheticCamera<Rgbd>(seq, corridorOptions().baseline), OrbParams{},
                    test::sharedVocabulary(), options);
  const MapFileInfo info = loaded.core().loadMap(file);
  EXPECT_EQ(info.version, kMapFileVersion);
  const std::vector<AtlasMapInfo> maps = loaded.core().maps();
  ASSERT_EQ(maps.size(), atlas.maps.size());
  for (std::size_t i = 0; i < maps.size(); ++i) {
    EXPECT_EQ(maps[i].merged, atlas.maps[i].merged);
    EXPECT_EQ(maps[i].keyFrames, atlas.maps[i].keyFrames);
  }
  EXPECT_EQ(loaded.core().activeMapId(), merge.keptMap);
  const synth::SynthFrame& first = corridorFrames().front();
  EXPECT_EQ(loaded.track(test::syntheticInput<Rgbd>(first, seq.timestamp(0))).state, TrackingState::Ok);
  loaded.shutdown();
  fs::remove(file);
}

}  // namespace
