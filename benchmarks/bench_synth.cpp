// Rendering cost of the synthetic sequences. The reference is cv::remap of a VGA float image
// (one bilinear fetch per pixel: the floor of any warp-based renderer); read the renderer's
// figures as multiples of it. The budget is 300 VGA frames in a minute on one core,
// i.e. 200 ms per frame: BM_SequenceFrameVga (left image + depth, what the TUM layout writes)
// reports s_per_300_frames directly. On a shared machine read the CPU column.
#include <benchmark/benchmark.h>

#include <opencv2/imgproc.hpp>

#include "orbis/synth/loop_trajectory.hpp"
#include "orbis/synth/renderer.hpp"
#include "orbis/synth/scene.hpp"
#include "orbis/synth/sequence.hpp"

namespace {

using namespace orbis;
using namespace orbis::synth;

const Scene& roomScene() {
  static const Scene scene = makeRoomScene(RoomParams{}, 1);
  return scene;
}

PinholeCamera<double> vga() { return PinholeCamera<double>{500.0, 500.0, 320.0, 240.0, 640, 480}; }

void BM_RemapReferenceVga(benchmark::State& state) {
  cv::Mat source(1024, 1024, CV_32FC1);
  cv::randu(source, 0.0, 255.0);
  cv::Mat mapX(480, 640, CV_32FC1), mapY(480, 640, CV_32FC1), out;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      mapX.at<float>(y, x) = 100.0f + 1.3f * x + 0.2f * y;
      mapY.at<float>(y, x) = 50.0f + 0.1f * x + 1.2f * y;
    }
  for (auto _ : state) {
    cv::remap(source, out, mapX, mapY, cv::INTER_LINEAR);
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_RemapReferenceVga)->Unit(benchmark::kMillisecond);

// Arg: supersampling factor (rays per pixel along each axis).
void BM_RenderVga(benchmark::State& state) {
  Renderer renderer(RenderOptions{static_cast<int>(state.range(0)), 0.0, 1});
  cv::Mat gray, depth;
  int frame = 0;
  for (auto _ : state) {
    renderer.render(roomScene(), vga(), loopPose(LoopTrajectoryParams{}, (frame++ % 300) / 300.0), gray, &depth);
    benchmark::DoNotOptimize(gray.data);
  }
}
BENCHMARK(BM_RenderVga)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

// One frame of the default sequence as `orbis synth --layout tum` renders it, on one thread.
void BM_SequenceFrameVga(benchmark::State& state) {
  SynthOptions options;
  options.noiseSigma = 2.0;
  SyntheticSequence sequence(options);
  int frame = 0;
  for (auto _ : state) {
    const SynthFrame f = sequence.render(frame++ % options.frames, false, true);
    benchmark::DoNotOptimize(f.left.data);
  }
  // Seconds (CPU, as the Time/CPU columns) per 300-frame sequence: the budget is 60.
  state.counters["s_per_300_frames"] = benchmark::Counter(
      static_cast<double>(state.iterations()) / 300.0, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SequenceFrameVga)->Unit(benchmark::kMillisecond);

void BM_BuildRoomScene(benchmark::State& state) {
  std::uint64_t seed = 1;
  for (auto _ : state) {
    const Scene scene = makeRoomScene(RoomParams{}, seed++);
    benchmark::DoNotOptimize(scene.rects().data());
  }
}
BENCHMARK(BM_BuildRoomScene)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
