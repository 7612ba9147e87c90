// `orbis vocab train|info|convert|to-text|generate`: building, inspecting and converting the
// bag-of-words vocabulary (orbis/bow/vocabulary.hpp).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "command.hpp"
#include "orbis/adapters/dataset.hpp"
#include "orbis/bow/dbow2_text.hpp"
#include "orbis/bow/vocabulary.hpp"
#include "orbis/bow/vocabulary_training.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"
#include "orbis/util/progress.hpp"

namespace orbis::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

long boundedInt(const ArgParser& p, const std::string& name, long lo, long hi) {
  const long v = p.getInt(name);
  if (v < lo || v > hi)
    throw Error("argument " + name, "", "expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
  return v;
}

// One training image: where to read it from (a file, or a frame of a dataset).
struct ImageSource {
  fs::path file;
  const DatasetReader* dataset = nullptr;
  std::size_t frame = 0;
  bool right = false;  // the right image of a stereo frame
};

std::vector<fs::path> imagesInFolder(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw Error("argument --images", "", dir.string() + " is not a directory");
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".pgm" || ext == ".ppm" || ext == ".bmp")
      files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());  // directory order is not defined; the vocabulary must be
  return files;
}

// --images and --dataset may repeat; ArgParser keeps one value per option, so they are taken
// out of the argument list first (their declarations stay for --help).
std::vector<std::string> takeRepeated(std::vector<std::string>& args, const std::string& name, int values) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < args.size();) {
    if (args[i] != name) {
      ++i;
      continue;
    }
    if (i + static_cast<std::size_t>(values) >= args.size())
      throw Error("argument " + name, "", "expects " + std::to_string(values) + " value(s)");
    for (int v = 1; v <= values; ++v) out.push_back(args[i + static_cast<std::size_t>(v)]);
    args.erase(args.begin() + static_cast<std::ptrdiff_t>(i), args.begin() + static_cast<std::ptrdiff_t>(i) + values + 1);
  }
  return out;
}

int runTrain(std::vector<std::string> args) {
  const auto imageDirs = takeRepeated(args, "--images", 1);
  const auto datasets = takeRepeated(args, "--dataset", 2);
  ArgParser p("orbis vocab train OUT [--images DIR]... [--dataset tum|euroc|kitti PATH]... [options]",
              "Trains a vocabulary tree by hierarchical k-medians on ORB features (orbis OrbExtractor)\n"
              "of image folders and dataset sequences, and writes it in the orbis binary format.\n"
              "Deterministic: the same images, options and seed give the same file at any --threads.");
  p.positional("OUT", "output vocabulary file (.bin)")
      .option("--images", "DIR", "folder of images, searched recursively (repeatable)")
      .option("--dataset", "KIND PATH", "a dataset sequence: tum, euroc or kitti and its folder (repeatable)")
      .option("--every", "N", "use every N-th frame of each dataset", "1")
      .option("--features", "N", "ORB features per image", "1000")
      .option("--k", "K", "branching factor", "10")
      .option("--L", "L", "depth levels", "5")
      .option("--weighting", "W", "tf-idf, tf, idf or binary", "tf-idf")
      .option("--seed", "S", "seed of the k-means++ seeding", "1")
      .option("--threads", "N", "worker threads (feature extraction and clustering)", "1")
      .flag("--json", "print the summary as one JSON object");
  if (!p.parse(args)) return 0;
  if (imageDirs.empty() && datasets.empty()) throw Error("arguments", "", "give at least one --images or --dataset");

  bow::TrainingParams params;
  params.branching = static_cast<std::uint32_t>(boundedInt(p, "--k", 2, 255));
  params.depth = static_cast<std::uint32_t>(boundedInt(p, "--L", 1, 12));
  params.seed = static_cast<std::uint64_t>(boundedInt(p, "--seed", 0, 0x7FFFFFFFFFFFFFFFL));
  params.threads = static_cast<unsigned>(boundedInt(p, "--threads", 1, 256));
  const auto weighting = bow::parseWeighting(p.get("--weighting"));
  if (!weighting) throw Error("argument --weighting", "", "expected tf-idf, tf, idf or binary");
  params.weighting = *weighting;
  const long every = boundedInt(p, "--every", 1, 1000000);
  OrbParams orb;
  orb.features = static_cast<int>(boundedInt(p, "--features", 10, 100000));

  std::vector<ImageSource> sources;
  for (const auto& dir : imageDirs)
    for (auto& f : imagesInFolder(dir)) sources.push_back({std::move(f)});
  std::vector<std::unique_ptr<DatasetReader>> readers;
  for (std::size_t i = 0; i < datasets.size(); i += 2) {
    readers.push_back(openDataset(parseDatasetKind(datasets[i], "argument --dataset"), datasets[i + 1]));
    const DatasetReader& r = *readers.back();
    for (std::size_t f = 0; f < r.size(); f += static_cast<std::size_t>(every)) {
      sources.push_back({{}, &r, f, false});
      if (r.sensor() == SensorKind::Stereo) sources.push_back({{}, &r, f, true});
    }
  }
  if (sources.empty()) throw Error("arguments", "", "no images found");

  // Feature extraction: one extractor per thread (they keep buffers), results in source order.
  const auto t0 = Clock::now();
  std::vector<std::vector<OrbDescriptor>> images(sources.size());
  {
    ProgressBar bar("features", sources.size());
    std::atomic<std::size_t> next{0}, done{0};
    std::mutex errorMutex, barMutex;
    std::string firstError;
    auto work = [&] {
      OrbExtractor extractor(orb);
      std::vector<Keypoint> keypoints;
      for (std::size_t i; (i = next.fetch_add(1)) < sources.size();) {
        try {
          const ImageSource& s = sources[i];
          cv::Mat image;
          if (s.dataset) {
            DatasetFrame frame = s.dataset->frame(s.frame);
            image = s.right ? frame.right : frame.left;
          } else {
            image = cv::imread(s.file.string(), cv::IMREAD_GRAYSCALE);
            if (image.empty()) throw fileError(s.file.string(), "cannot read the image");
          }
          if (!image.empty()) extractor.extract(image, keypoints, images[i]);
        } catch (const std::exception& e) {
          std::lock_guard lock(errorMutex);
          if (firstError.empty()) firstError = e.what();
          next = sources.size();
        }
        std::lock_guard lock(barMutex);
        bar.update(++done);
      }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < params.threads; ++t) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
    if (!firstError.empty()) throw Error("training images", "", firstError);
  }
  std::size_t descriptorCount = 0;
  for (const auto& d : images) descriptorCount += d.size();
  const double extractMs = msSince(t0);

  const auto t1 = Clock::now();
  ProgressBar bar("clustering", 1000);
  params.progress = [&](std::size_t done, std::size_t total) { bar.update(total ? done * 1000 / total : 1000); };
  const bow::OrbVocabulary vocabulary = bow::trainVocabulary<OrbDescriptor, HammingDistance>(images, params);
  bar.finish();
  const double trainMs = msSince(t1);
  vocabulary.save(p.pos(0));

  if (p.has("--json")) {
    JsonWriter j;
    j.beginObject()
        .field("images", sources.size())
        .field("descriptors", descriptorCount)
        .field("k", static_cast<int>(vocabulary.branching()))
        .field("L", static_cast<int>(vocabulary.depth()))
        .field("words", vocabulary.wordCount())
        .field("nodes", vocabulary.nodeCount())
        .field("extract_ms", extractMs)
        .field("train_ms", trainMs)
        .field("bytes", vocabulary.blob().bytes().size())
        .endObject();
    std::printf("%s\n", j.str().c_str());
  } else {
    std::printf("%zu images, %zu descriptors (%.1f s); k=%u L=%u: %zu words, %zu nodes (%.1f s); %s, %.2f MB\n",
                sources.size(), descriptorCount, extractMs / 1000, vocabulary.branching(), vocabulary.depth(),
                vocabulary.wordCount(), vocabulary.nodeCount(), trainMs / 1000, p.pos(0).c_str(),
                static_cast<double>(vocabulary.blob().bytes().size()) / 1e6);
  }
  return 0;
}

int runInfo(const std::vector<std::string>& args) {
  ArgParser p("orbis vocab info FILE [--json]", "Loads a binary vocabulary (checking it) and prints its shape and load time.");
  p.positional("FILE", "vocabulary in the orbis binary format").flag("--json", "print one JSON object");
  if (!p.parse(args)) return 0;
  const auto t0 = Clock::now();
  const bow::OrbVocabulary v = bow::OrbVocabulary::load(p.pos(0));
  const double loadMs = msSince(t0);
  if (p.has("--json")) {
    JsonWriter j;
    j.beginObject()
        .field("k", static_cast<int>(v.branching()))
        .field("L", static_cast<int>(v.depth()))
        .field("words", v.wordCount())
        .field("nodes", v.nodeCount())
        .field("weighting", bow::weightingName(v.weighting()))
        .field("scoring", "L1")
        .field("bytes", v.blob().bytes().size())
        .field("load_ms", loadMs)
        .endObject();
    std::printf("%s\n", j.str().c_str());
  } else {
    std::printf("file:      %s (%.2f MB)\nk:         %u\nL:         %u\nwords:     %zu\nnodes:     %zu\n"
                "weighting: %s\nscoring:   L1\nload:      %.2f ms\n",
                p.pos(0).c_str(), static_cast<double>(v.blob().bytes().size()) / 1e6, v.branching(), v.depth(),
                v.wordCount(), v.nodeCount(), std::string(bow::weightingName(v.weighting())).c_str(), loadMs);
  }
  return 0;
}

int runConvert(const std::vector<std::string>& args) {
  ArgParser p("orbis vocab convert IN.txt OUT",
              "Converts a DBoW2 text vocabulary (ORB-SLAM2's ORBvoc.txt format) to the orbis binary format.");
  p.positional("IN", "DBoW2 text vocabulary").positional("OUT", "binary vocabulary to write");
  if (!p.parse(args)) return 0;
  const auto t0 = Clock::now();
  const auto v = bow::readDbow2Text<bow::OrbVocabulary>(p.pos(0));
  const double parseMs = msSince(t0);
  v.save(p.pos(1));
  std::printf("%s: k=%u L=%u, %zu words, parsed in %.1f ms -> %s\n", p.pos(0).c_str(), v.branching(), v.depth(),
              v.wordCount(), parseMs, p.pos(1).c_str());
  return 0;
}

int runToText(const std::vector<std::string>& args) {
  ArgParser p("orbis vocab to-text IN OUT.txt", "Writes a binary vocabulary in DBoW2's text format.");
  p.positional("IN", "binary vocabulary").positional("OUT", "DBoW2 text file to write");
  if (!p.parse(args)) return 0;
  bow::writeDbow2Text(bow::OrbVocabulary::load(p.pos(0)), p.pos(1));
  return 0;
}

int runGenerate(const std::vector<std::string>& args) {
  ArgParser p("orbis vocab generate OUT [--k K] [--L L] [--seed S]",
              "Writes a complete random vocabulary tree (k^L words): a size stand-in for load benchmarks,\n"
              "useless for place recognition.");
  p.positional("OUT", "binary vocabulary to write")
      .option("--k", "K", "branching factor", "10")
      .option("--L", "L", "depth levels", "6")
      .option("--seed", "S", "seed of the random descriptors and weights", "1");
  if (!p.parse(args)) return 0;
  const auto v = bow::randomVocabulary<OrbDescriptor, HammingDistance>(
      static_cast<std::uint32_t>(boundedInt(p, "--k", 2, 255)), static_cast<std::uint32_t>(boundedInt(p, "--L", 1, 12)),
      static_cast<std::uint64_t>(boundedInt(p, "--seed", 0, 0x7FFFFFFFFFFFFFFFL)));
  v.save(p.pos(0));
  std::printf("%s: %zu words, %zu nodes, %.2f MB\n", p.pos(0).c_str(), v.wordCount(), v.nodeCount(),
              static_cast<double>(v.blob().bytes().size()) / 1e6);
  return 0;
}

int runVocab(const std::vector<std::string>& args) {
  const std::string usage =
      "usage: orbis vocab <action> ...\n\n"
      "actions:\n"
      "  train OUT [--images DIR]... [--dataset KIND PATH]...  train a vocabulary on ORB features\n"
      "  info FILE [--json]                                   shape and load time of a vocabulary\n"
      "  convert IN.txt OUT                                   DBoW2 text (ORBvoc.txt) -> orbis binary\n"
      "  to-text IN OUT.txt                                   orbis binary -> DBoW2 text\n"
      "  generate OUT [--k K] [--L L]                         random complete tree, for benchmarks\n"
      "each action takes --help\n";
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(usage.c_str(), args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (args[0] == "train") return runTrain(rest);
  if (args[0] == "info") return runInfo(rest);
  if (args[0] == "convert") return runConvert(rest);
  if (args[0] == "to-text") return runToText(rest);
  if (args[0] == "generate") return runGenerate(rest);
  throw Error("argument " + args[0], "", "unknown vocab action (train, info, convert, to-text, generate)");
}

}  // namespace

ORBIS_REGISTER_COMMAND("vocab", "train, inspect and convert bag-of-words vocabularies", runVocab);

}  // namespace orbis::cli
