// python/src/vocabulary.cpp — orbis.Vocabulary (bag-of-words tree over ORB) and orbis.extract_orb.
//
// Contract: Vocabulary.load(path) maps an orbis binary vocabulary; Vocabulary.default() loads
// the shipped one, found by default_path(): $ORBIS_VOCABULARY, else the copy inside the installed
// package (orbis/data/), else the source tree or install prefix the library was built for.
// Vocabulary.train(images, ...) builds a tree from NumPy descriptor arrays (one uint8 N x 32
// array per training image) exactly as `orbis vocab train` does from the same descriptors.
// extract_orb(image, ...) runs the pipeline's ORB extractor: keypoints as an N x 5 float32 array
// (u, v, angle in degrees, response, octave) and descriptors as N x 32 uint8. All release the GIL.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdlib>
#include <cstring>

#include "arrays.hpp"
#include "bindings.hpp"
#include "errors.hpp"
#include "orbis/bow/vocabulary_training.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/tracking/tracker.hpp"

namespace orbis::python {

using namespace pybind11::literals;
namespace fs = std::filesystem;

namespace {

constexpr const char* kShippedVocabulary = "orbis_orb_k10_L5.bin";

fs::path defaultVocabularyFile() {
  if (const char* env = std::getenv("ORBIS_VOCABULARY"); env && *env) return env;
  const fs::path package = py::module_::import("orbis").attr("__file__").cast<std::string>();
  if (const fs::path bundled = package.parent_path() / "data" / kShippedVocabulary; fs::exists(bundled))
    return bundled;
  return defaultVocabularyPath();
}

std::shared_ptr<OrbVocabulary> loadVocabulary(const fs::path& path) {
  requireFile(path);
  py::gil_scoped_release release;
  return std::make_shared<OrbVocabulary>(OrbVocabulary::load(path));
}

std::vector<OrbDescriptor> descriptorsFrom(const py::handle& array, const char* argument) {
  const ImageView view = descriptorView(array, argument);
  std::vector<OrbDescriptor> out(static_cast<std::size_t>(view.mat.rows));
  for (int r = 0; r < view.mat.rows; ++r) std::memcpy(out[static_cast<std::size_t>(r)].bytes(), view.mat.ptr(r), 32);
  return out;
}

py::array_t<std::uint8_t> descriptorsToArray(const std::vector<OrbDescriptor>& descriptors) {
  py::array_t<std::uint8_t> out({static_cast<py::ssize_t>(descriptors.size()), py::ssize_t{32}});
  if (!descriptors.empty()) std::memcpy(out.mutable_data(), descriptors.data(), descriptors.size() * 32);
  return out;
}

std::shared_ptr<OrbVocabulary> train(const py::iterable& images, std::uint32_t k, std::uint32_t L,
                                     std::uint64_t seed, unsigned threads, const std::string& weighting) {
  bow::TrainingParams params;
  const auto w = bow::parseWeighting(weighting);
  if (!w) throw py::value_error("weighting: expected 'tf-idf', 'tf', 'idf' or 'binary', got '" + weighting + "'");
  params.weighting = *w;
  params.branching = k;
  params.depth = L;
  params.seed = seed;
  params.threads = threads;
  std::vector<std::vector<OrbDescriptor>> documents;
  for (const py::handle image : images) documents.push_back(descriptorsFrom(image, "images[i]"));
  py::gil_scoped_release release;
  return std::make_shared<OrbVocabulary>(bow::trainVocabulary<OrbDescriptor, HammingDistance>(documents, params));
}

py::array_t<std::uint32_t> wordsOf(const OrbVocabulary& v, const py::handle& descriptors) {
  const std::vector<OrbDescriptor> d = descriptorsFrom(descriptors, "descriptors");
  py::array_t<std::uint32_t> out(static_cast<py::ssize_t>(d.size()));
  std::uint32_t* word = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (const OrbDescriptor& one : d) *word++ = v.wordOf(one);
  }
  return out;
}

py::dict bowVectorOf(const OrbVocabulary& v, const py::handle& descriptors) {
  const std::vector<OrbDescriptor> d = descriptorsFrom(descriptors, "descriptors");
  bow::BowVector bow;
  {
    py::gil_scoped_release release;
    bow = v.transform(d);
  }
  py::dict out;
  for (const auto& entry : bow) out[py::int_(entry.word)] = entry.weight;
  return out;
}

py::tuple extractOrb(const py::handle& image, const OrbParams& params) {
  const ImageView view = imageView(image, "image");
  std::vector<Keypoint> keypoints;
  std::vector<OrbDescriptor> descriptors;
  {
    py::gil_scoped_release release;
    OrbExtractor extractor(params);
    extractor.extract(view.mat, keypoints, descriptors);
  }
  py::array_t<float> points({static_cast<py::ssize_t>(keypoints.size()), py::ssize_t{5}});
  auto rows = points.mutable_unchecked<2>();
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const Keypoint& kp = keypoints[i];
    const float values[5] = {kp.u, kp.v, kp.angle, kp.response, static_cast<float>(kp.octave)};
    for (py::ssize_t c = 0; c < 5; ++c) rows(static_cast<py::ssize_t>(i), c) = values[c];
  }
  return py::make_tuple(points, descriptorsToArray(descriptors));
}

}  // namespace

std::shared_ptr<OrbVocabulary> defaultVocabulary() { return loadVocabulary(defaultVocabularyFile()); }

void bindVocabulary(py::module_& m) {
  py::class_<OrbVocabulary, std::shared_ptr<OrbVocabulary>>(
      m, "Vocabulary", "A bag-of-words vocabulary tree over 256-bit ORB descriptors (TF-IDF, L1 score).")
      .def_static("load", &loadVocabulary, "path"_a, "Loads an orbis binary vocabulary (memory-mapped, checksummed).")
      .def_static("default_path", &defaultVocabularyFile,
                  "Where the shipped vocabulary is: $ORBIS_VOCABULARY, the package's data/ folder, or the\n"
                  "source tree / install prefix. Raises orbis.Error when there is none.")
      .def_static(
          "default", &defaultVocabulary,
          "Loads the shipped vocabulary (k=10, L=5, 79,599 words).")
      .def_static("train", &train, "images"_a, "k"_a = 10, "L"_a = 5, "seed"_a = 1, "threads"_a = 1,
                  "weighting"_a = "tf-idf",
                  "Trains a tree by hierarchical k-medians from an iterable of uint8 (N, 32) descriptor\n"
                  "arrays, one per training image (each image is one document for the IDF weights).\n"
                  "Deterministic for a given seed at any thread count.")
      .def(
          "save", [](const OrbVocabulary& v, const fs::path& path) {
            py::gil_scoped_release release;
            v.save(path);
          },
          "path"_a, "Writes the orbis binary format.")
      .def_property_readonly("k", &OrbVocabulary::branching, "Branching factor.")
      .def_property_readonly("L", &OrbVocabulary::depth, "Depth.")
      .def_property_readonly("word_count", &OrbVocabulary::wordCount)
      .def_property_readonly("node_count", &OrbVocabulary::nodeCount)
      .def_property_readonly("weighting", [](const OrbVocabulary& v) { return std::string(bow::weightingName(v.weighting())); })
      .def("words", &wordsOf, "descriptors"_a, "The word id of each descriptor row (uint32 array).")
      .def("transform", &bowVectorOf, "descriptors"_a,
           "The L1-normalised bag-of-words vector {word id: weight} of a set of descriptors.")
      .def("__repr__", [](const OrbVocabulary& v) {
        return "Vocabulary(k=" + std::to_string(v.branching()) + ", L=" + std::to_string(v.depth()) +
               ", words=" + std::to_string(v.wordCount()) + ")";
      });
  m.def("extract_orb", &extractOrb, "image"_a, "params"_a = OrbParams{},
        "ORB keypoints and descriptors of a uint8 grey or BGR image, by the pipeline's extractor:\n"
        "(keypoints float32 (N, 5): u, v, angle [deg], response, octave; descriptors uint8 (N, 32)).");
}

}  // namespace orbis::python
