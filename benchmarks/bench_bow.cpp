// Bag-of-words benchmarks, each against its reference in the same run; ratios printed after
// the Google Benchmark table:
//  - vocabulary load: the shipped vocabulary; a generated 1M-word tree (k=10, L=6) from the
//    orbis binary file vs the same tree parsed from DBoW2's text format, by our parser
//    (from_chars over one buffer) and by a DBoW2-style parser (getline + stringstream per line,
//    what ORB-SLAM2 does). Wall-clock time: loading is page-cache and memory bound.
//  - transform of one keyframe's 1,000 descriptors (shipped tree vs the 1M-word tree).
//  - keyframe database: relocalisation and loop queries with 1,000 and 10,000 keyframes.
//  - 1,000 ORB descriptors matched against a 50,000-descriptor set: FLANN (hierarchical
//    clustering at several search efforts, and LSH) vs exhaustive Hamming, with recall.
// Data: ORBIS_DATA or ../shared/datasets (TUM teddy images for the matching benchmark; absent
// data skips it). Scratch files go to $TMPDIR.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include "orbis/bow/dbow2_text.hpp"
#include "orbis/bow/flann_index.hpp"
#include "orbis/bow/keyframe_database.hpp"
#include "orbis/bow/vocabulary.hpp"
#include "orbis/bow/vocabulary_training.hpp"
#include "orbis/features/orb_extractor.hpp"

namespace fs = std::filesystem;
using namespace orbis;
using namespace orbis::bow;

namespace {

fs::path dataRoot() {
  if (const char* env = std::getenv("ORBIS_DATA"); env && *env) return env;
  return ORBIS_DEFAULT_DATA_DIR;
}
// ORBIS_VOCABULARY, else the shipped one: ORBIS_DEFAULT_DATA_DIR is "<source>/../shared/datasets".
fs::path shippedVocabulary() {
  if (const char* env = std::getenv("ORBIS_VOCABULARY"); env && *env) return env;
  const std::string data = ORBIS_DEFAULT_DATA_DIR, suffix = "/../shared/datasets";
  const std::string source = data.ends_with(suffix) ? data.substr(0, data.size() - suffix.size()) : ".";
  return fs::path(source) / "vocabulary" / "orbis_orb_k10_L5.bin";
}

struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("orbis_bench_bow_" + std::to_string(::getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() { fs::remove_all(dir); }
};
Scratch& scratch() {
  static Scratch s;
  return s;
}

// The 1M-word tree, written once in both formats.
const fs::path& bigBinary() {
  static const fs::path p = [] {
    const fs::path bin = scratch().dir / "k10L6.bin";
    const auto v = randomVocabulary<OrbDescriptor, HammingDistance>(10, 6, 1);
    v.save(bin);
    writeDbow2Text(v, scratch().dir / "k10L6.txt");
    return bin;
  }();
  return p;
}
fs::path bigText() { return bigBinary().parent_path() / "k10L6.txt"; }

// ORB-SLAM2's way of reading DBoW2 text: a stream, one stringstream per line. Builds the same
// per-node data (parent, leaf flag, descriptor, weight) that DBoW2 keeps.
struct TextNode {
  int parent, leaf;
  OrbDescriptor descriptor;
  double weight;
};
std::vector<TextNode> parseTextIostream(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  int k, L, scoring, weighting;
  std::stringstream(line) >> k >> L >> scoring >> weighting;
  std::vector<TextNode> nodes;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    TextNode n{};
    ss >> n.parent >> n.leaf;
    for (int b = 0; b < 32; ++b) {
      int v;
      ss >> v;
      n.descriptor.bytes()[b] = static_cast<std::uint8_t>(v);
    }
    ss >> n.weight;
    nodes.push_back(n);
  }
  return nodes;
}

void BM_LoadShipped(benchmark::State& state) {
  if (!fs::exists(shippedVocabulary())) {
    state.SkipWithError("vocabulary/orbis_orb_k10_L5.bin not found");
    return;
  }
  std::size_t words = 0;
  for (auto _ : state) words = OrbVocabulary::load(shippedVocabulary()).wordCount();
  state.counters["words"] = static_cast<double>(words);
}

void BM_Load1M_Binary(benchmark::State& state) {
  bigBinary();  // generated outside the timed loop
  std::size_t words = 0;
  for (auto _ : state) words = OrbVocabulary::load(bigBinary()).wordCount();
  state.counters["words"] = static_cast<double>(words);
}

void BM_Load1M_TextOrbis(benchmark::State& state) {
  bigBinary();
  std::size_t words = 0;
  for (auto _ : state) words = readDbow2Text<OrbVocabulary>(bigText()).wordCount();
  state.counters["words"] = static_cast<double>(words);
}

void BM_Load1M_TextIostream(benchmark::State& state) {
  bigBinary();
  std::size_t nodes = 0;
  for (auto _ : state) nodes = parseTextIostream(bigText()).size();
  state.counters["nodes"] = static_cast<double>(nodes);
}

// ---- keyframe database ---------------------------------------------------------------------
// A synthetic corridor: keyframe i sees prototypes [50 i, 50 i + 1000) with 0-8 flipped bits,
// so neighbours within ~20 keyframes overlap; queries sit between keyframes.
constexpr int kStride = 50, kFeatures = 1000, kQueries = 64;

struct Corridor {
  OrbVocabulary vocabulary;
  std::vector<BowVector> keyframes, queries;
  std::vector<std::size_t> queryNear;  // the keyframe each query sits beside
};

const OrbVocabulary& databaseVocabulary() {
  static const OrbVocabulary v = fs::exists(shippedVocabulary())
                                     ? OrbVocabulary::load(shippedVocabulary())
                                     : randomVocabulary<OrbDescriptor, HammingDistance>(10, 5, 3);
  return v;
}

const Corridor& corridor(std::size_t keyframes) {
  static std::map<std::size_t, Corridor> cache;
  auto [it, fresh] = cache.try_emplace(keyframes);
  if (!fresh) return it->second;
  Corridor& c = it->second;
  const OrbVocabulary& v = databaseVocabulary();
  bow::detail::SplitMix64 rng{keyframes};
  std::vector<OrbDescriptor> prototypes(keyframes * kStride + kFeatures);
  for (auto& p : prototypes)
    for (auto& w : p.words) w = rng.next();
  auto view = [&](std::size_t start) {
    std::vector<OrbDescriptor> d(kFeatures);
    for (int f = 0; f < kFeatures; ++f) {
      d[static_cast<std::size_t>(f)] = prototypes[start + static_cast<std::size_t>(f)];
      for (int flips = static_cast<int>(rng.below(9)); flips > 0; --flips) {
        const int bit = static_cast<int>(rng.below(256));
        d[static_cast<std::size_t>(f)].setBit(bit, !d[static_cast<std::size_t>(f)].bit(bit));
      }
    }
    return v.transform(d);
  };
  for (std::size_t i = 0; i < keyframes; ++i) c.keyframes.push_back(view(i * kStride));
  for (int q = 0; q < kQueries; ++q) {
    const std::size_t near = rng.below(keyframes - 1);
    c.queryNear.push_back(near);
    c.queries.push_back(view(near * kStride + kStride / 2));
  }
  return c;
}

struct ChainGraph {
  std::size_t size;
  std::vector<KeyframeId> connectedKeyframes(KeyframeId id) const { return bestCovisibleKeyframes(id, 20); }
  std::vector<KeyframeId> bestCovisibleKeyframes(KeyframeId id, std::size_t n) const {
    std::vector<KeyframeId> out;
    for (std::size_t step = 1; out.size() < n && step <= 10; ++step) {
      if (id + step < size) out.push_back(id + step);
      if (id >= step && out.size() < n) out.push_back(id - step);
    }
    return out;
  }
};

void BM_DatabaseQuery(benchmark::State& state, bool loop) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Corridor& c = corridor(n);
  KeyframeDatabase db;
  for (std::size_t i = 0; i < n; ++i) db.add(i, c.keyframes[i]);
  const ChainGraph graph{n};
  std::size_t q = 0, candidates = 0, hits = 0, queries = 0;
  for (auto _ : state) {
    const std::size_t near = c.queryNear[q];
    // A loop query stands for a new keyframe id (>= n) whose covisibles are near-15 .. near-5,
    // so the true place (near, near+1) is not excluded.
    struct Shifted {
      const ChainGraph& g;
      std::size_t near;
      std::vector<KeyframeId> connectedKeyframes(KeyframeId id) const {
        if (id < g.size) return g.connectedKeyframes(id);
        std::vector<KeyframeId> out;
        for (std::size_t k = near >= 15 ? near - 15 : 0; k + 5 <= near; ++k) out.push_back(k);
        return out;
      }
      std::vector<KeyframeId> bestCovisibleKeyframes(KeyframeId id, std::size_t m) const {
        return g.bestCovisibleKeyframes(id, m);
      }
    } shifted{graph, near};
    const auto result = loop ? db.detectLoopCandidates(n + 1, c.queries[q], shifted)
                             : db.detectRelocalisationCandidates(c.queries[q], graph);
    benchmark::DoNotOptimize(result.data());
    candidates += result.size();
    for (const auto& r : result) hits += (r.keyframe + 3 >= near && r.keyframe <= near + 4) ? 1 : 0;
    ++queries;
    q = (q + 1) % c.queries.size();
  }
  state.counters["candidates"] = static_cast<double>(candidates) / static_cast<double>(queries);
  state.counters["near_share"] = candidates ? static_cast<double>(hits) / static_cast<double>(candidates) : 0.0;
}

// ---- descriptor matching -------------------------------------------------------------------
struct MatchData {
  std::vector<OrbDescriptor> indexed, queries;
  std::vector<DescriptorMatch> exact;
};

const MatchData* matchData() {
  static const std::unique_ptr<MatchData> data = []() -> std::unique_ptr<MatchData> {
    const fs::path rgb = dataRoot() / "tum_fr3_teddy_200" / "rgb";
    if (!fs::exists(rgb)) return nullptr;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(rgb)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    auto d = std::make_unique<MatchData>();
    OrbExtractor extractor;
    std::vector<Keypoint> kps;
    std::vector<OrbDescriptor> desc;
    // Indexed: even frames until 50,000 descriptors; queries: 1,000 from odd frames among them.
    for (std::size_t i = 0; i < files.size() && d->indexed.size() < 50000; i += 2) {
      extractor.extract(cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE), kps, desc);
      d->indexed.insert(d->indexed.end(), desc.begin(), desc.end());
      if (i + 1 < files.size() && d->queries.size() < 1000) {
        extractor.extract(cv::imread(files[i + 1].string(), cv::IMREAD_GRAYSCALE), kps, desc);
        for (std::size_t j = 0; j < desc.size() && d->queries.size() < 1000; j += 20) d->queries.push_back(desc[j]);
      }
    }
    d->indexed.resize(std::min<std::size_t>(d->indexed.size(), 50000));
    d->exact = bruteForceNearest(d->indexed, d->queries);
    return d;
  }();
  return data.get();
}

// Recall over queries whose exact nearest neighbour is a plausible match (distance <= 50, the
// threshold ORB-SLAM's matchers accept): found at the exact distance.
double recall(const MatchData& d, const std::vector<DescriptorMatch>& got) {
  int relevant = 0, found = 0;
  for (std::size_t i = 0; i < d.queries.size(); ++i) {
    if (d.exact[i].distance > 50) continue;
    ++relevant;
    found += got[i].index >= 0 && got[i].distance == d.exact[i].distance ? 1 : 0;
  }
  return relevant ? static_cast<double>(found) / relevant : 0.0;
}

void BM_MatchBruteForce(benchmark::State& state) {
  const MatchData* d = matchData();
  if (!d) return state.SkipWithError("tum_fr3_teddy_200 not found");
  std::vector<DescriptorMatch> got;
  for (auto _ : state) got = bruteForceNearest(d->indexed, d->queries);
  state.counters["recall"] = recall(*d, got);
  state.counters["indexed"] = static_cast<double>(d->indexed.size());
}

void BM_MatchFlann(benchmark::State& state, BinaryIndexParams::Algorithm algorithm) {
  const MatchData* d = matchData();
  if (!d) return state.SkipWithError("tum_fr3_teddy_200 not found");
  BinaryIndexParams p;
  p.algorithm = algorithm;
  if (state.range(1) > 0) p.trees = static_cast<int>(state.range(1));
  const auto t0 = std::chrono::steady_clock::now();
  const BinaryDescriptorIndex index(d->indexed, p);
  state.counters["build_ms"] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const int checks = static_cast<int>(state.range(0));
  std::vector<DescriptorMatch> got;
  for (auto _ : state) got = index.nearest(d->queries, checks);
  state.counters["recall"] = recall(*d, got);
}

// One keyframe's transform (1,000 real ORB descriptors) through the shipped tree and through
// the 1M-word tree: the cost per keyframe ORB-SLAM pays for BoW, and how it grows with L.
void BM_Transform(benchmark::State& state, bool big) {
  const MatchData* d = matchData();
  if (!d) return state.SkipWithError("tum_fr3_teddy_200 not found");
  if (!big && !fs::exists(shippedVocabulary())) return state.SkipWithError("shipped vocabulary not found");
  const OrbVocabulary v = big ? OrbVocabulary::load(bigBinary()) : OrbVocabulary::load(shippedVocabulary());
  BowVector bow;
  FeatureVector features;
  for (auto _ : state) {
    v.transform(d->queries, bow, features, 3);
    benchmark::DoNotOptimize(bow.entries().data());
  }
  state.counters["words"] = static_cast<double>(bow.size());
}

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration && r.iterations > 0 && !r.error_occurred) {
        real[r.benchmark_name()] = r.GetAdjustedRealTime();
        cpu[r.benchmark_name()] = r.GetAdjustedCPUTime();
      }
    ConsoleReporter::ReportRuns(runs);
  }
  // "wall x (cpu y)": CPU time (user + system of the thread) is the steadier figure on a busy machine.
  std::string ratio(const std::string& a, const std::string& b) const {
    const auto ra = real.find(a), rb = real.find(b), ca = cpu.find(a), cb = cpu.find(b);
    if (ra == real.end() || rb == real.end()) return "n/a";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%8.2fx wall, %8.2fx CPU", ra->second / rb->second, ca->second / cb->second);
    return buf;
  }
  std::map<std::string, double> real, cpu;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::RegisterBenchmark("Load/shipped", BM_LoadShipped)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("Load/1M/binary", BM_Load1M_Binary)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("Load/1M/text_orbis", BM_Load1M_TextOrbis)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("Load/1M/text_iostream", BM_Load1M_TextIostream)
      ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
  benchmark::RegisterBenchmark("Transform/shipped", BM_Transform, false)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("Transform/1M", BM_Transform, true)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("Database/reloc", BM_DatabaseQuery, false)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("Database/loop", BM_DatabaseQuery, true)->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("Match/bruteforce", BM_MatchBruteForce)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Match/flann_hc", BM_MatchFlann, BinaryIndexParams::Algorithm::HierarchicalClustering)
      ->ArgNames({"checks", "trees"})
      ->Args({32, 4})->Args({64, 4})->Args({128, 4})->Args({256, 4})->Args({512, 4})
      ->Args({256, 1})->Args({512, 1})->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Match/flann_lsh", BM_MatchFlann, BinaryIndexParams::Algorithm::Lsh)
      ->Args({0, 0})->Unit(benchmark::kMillisecond);
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\nRatios (same run)\n");
  const auto line = [&](const std::string& what, const std::string& a, const std::string& b) {
    std::printf("  %-62s %s\n", what.c_str(), reporter.ratio(a, b).c_str());
  };
  line("1M-word load, text (orbis parser) / binary:", "Load/1M/text_orbis/real_time", "Load/1M/binary/real_time");
  line("1M-word load, text (DBoW2 iostream) / binary:", "Load/1M/text_iostream/iterations:2/real_time",
       "Load/1M/binary/real_time");
  line("transform of 1,000 descriptors, 1M / shipped:", "Transform/1M", "Transform/shipped");
  line("database reloc query, 10k / 1k keyframes:", "Database/reloc/10000", "Database/reloc/1000");
  line("database loop query, 10k / 1k keyframes:", "Database/loop/10000", "Database/loop/1000");
  for (const auto [checks, trees] : {std::pair{32, 4}, {64, 4}, {128, 4}, {256, 4}, {512, 4}, {256, 1}, {512, 1}})
      line("brute force / FLANN hierarchical, " + std::to_string(trees) + " tree(s), checks " + std::to_string(checks) + ":",
           "Match/bruteforce", "Match/flann_hc/checks:" + std::to_string(checks) + "/trees:" + std::to_string(trees));
  line("brute force / FLANN LSH:", "Match/bruteforce", "Match/flann_lsh/0/0");
  benchmark::Shutdown();
  return 0;
}
