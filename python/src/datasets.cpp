// python/src/datasets.cpp — the dataset readers (TUM RGB-D, EuRoC, KITTI) as Python sequences.
//
// Contract: open_dataset(kind, path, ...) is orbis::openDataset: only the text files are read
// up front; a Dataset is a sized, indexable (negative indices too), iterable sequence of Frame
// objects, each loaded when asked for, with the GIL released while its images are read. A
// Frame's images are NumPy arrays sharing the decoded cv::Mat's memory (no copy): `image`/`left`
// uint8 grey or BGR, `right` (stereo) and `depth` (RGB-D, raw uint16; metres = raw /
// camera["depth_scale"]) or None. Ground truth is an N x 8 array of TUM rows, camera-to-world.
// Bad paths raise MissingFileError, malformed files orbis.Error naming file and line.
#include <pybind11/stl.h>
#include <variant>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "errors.hpp"
#include "orbis/adapters/dataset.hpp"

namespace orbis::python {

using namespace pybind11::literals;

namespace {

// Iteration state of one `for frame in dataset` loop (independent of DatasetReader::next()).
struct FrameIterator {
  const DatasetReader* reader;
  std::size_t next = 0;
};

DatasetFrame loadFrame(const DatasetReader& reader, std::size_t index) {
  py::gil_scoped_release release;
  return reader.frame(index);
}

std::unique_ptr<DatasetReader> openDatasetArgument(const std::string& kind, const std::filesystem::path& path,
                                                   std::optional<std::string> sensor, const std::string& sequence,
                                                   std::optional<double> depthScale, double maxDepthDt,
                                                   bool rectify, bool strict, bool tolerateBadFrames) {
  if (kind != "tum" && kind != "euroc" && kind != "kitti")
    throw py::value_error("kind: expected 'tum', 'euroc' or 'kitti', got '" + kind + "'");
  requireFile(path);
  DatasetOptions options;
  if (sensor) options.sensor = sensorArgument(*sensor);
  options.kittiSequence = sequence;
  options.tumDepthScale = depthScale;
  options.maxDepthDt = maxDepthDt;
  options.rectify = rectify;
  options.strict = strict;
  options.tolerateBadFrames = tolerateBadFrames;
  py::gil_scoped_release release;
  return openDataset(parseDatasetKind(kind), path, options);
}

void bindFrame(py::module_& m) {
  py::class_<DatasetFrame>(m, "Frame", "One frame of a dataset: timestamp and images as NumPy arrays.")
      .def_readonly("index", &DatasetFrame::index, "Position in the dataset.")
      .def_readonly("timestamp", &DatasetFrame::timestamp, "Seconds.")
      .def_property_readonly("image", [](const DatasetFrame& f) { return matToArray(f.left); },
                             "The left / colour image: uint8 (H, W) grey or (H, W, 3) BGR.")
      .def_property_readonly("left", [](const DatasetFrame& f) { return matToArray(f.left); }, "Same as image.")
      .def_property_readonly("right", [](const DatasetFrame& f) { return matToArray(f.right); },
                             "Stereo: the right image, or None when missing or not stereo.")
      .def_property_readonly("depth", [](const DatasetFrame& f) { return matToArray(f.depth); },
                             "RGB-D: raw uint16 depth (metres = raw / camera['depth_scale']), or None.")
      .def_readonly("warnings", &DatasetFrame::warnings, "What was missing (e.g. no depth within max_depth_dt).")
      .def("__repr__", [](const DatasetFrame& f) {
        return "Frame(index=" + std::to_string(f.index) + ", timestamp=" + std::to_string(f.timestamp) + ")";
      });
}

std::size_t checkedIndex(const DatasetReader& reader, py::ssize_t index) {
  const auto size = static_cast<py::ssize_t>(reader.size());
  if (index < 0) index += size;
  if (index < 0 || index >= size) throw py::index_error("frame index out of range");
  return static_cast<std::size_t>(index);
}

}  // namespace

void bindDatasets(py::module_& m) {
  bindFrame(m);
  py::class_<FrameIterator>(m, "FrameIterator")
      .def("__iter__", [](FrameIterator& it) -> FrameIterator& { return it; })
      .def("__next__", [](FrameIterator& it) {
        if (it.next >= it.reader->size()) throw py::stop_iteration();
        return loadFrame(*it.reader, it.next++);
      });
  py::class_<DatasetReader>(m, "Dataset", "A benchmark sequence read frame by frame (see orbis.datasets).")
      .def("__len__", &DatasetReader::size)
      .def("__getitem__", [](const DatasetReader& d, py::ssize_t i) { return loadFrame(d, checkedIndex(d, i)); })
      .def("__iter__", [](const DatasetReader& d) { return FrameIterator{&d}; }, py::keep_alive<0, 1>())
      .def_property_readonly("kind", [](const DatasetReader& d) { return std::string(toString(d.kind())); })
      .def_property_readonly("sensor", [](const DatasetReader& d) { return std::string(toString(d.sensor())); })
      .def_property_readonly("root", &DatasetReader::root)
      .def_property_readonly("camera", [](const DatasetReader& d) {
                               return describeCamera(std::visit([](const auto& c) -> CameraVariant { return c; }, d.camera()));
                             },
                             "The dataset's own calibration, as Settings.camera describes one.")
      .def_property_readonly("ground_truth", [](const DatasetReader& d) { return trajectoryToArray(d.groundTruth()); },
                             "(N, 8) float64 TUM rows t x y z qx qy qz qw, camera-to-world (empty when none).")
      .def_property_readonly(
          "timestamps",
          [](const DatasetReader& d) {
            std::vector<double> t(d.size());
            for (std::size_t i = 0; i < t.size(); ++i) t[i] = d.timestamp(i);
            return vectorToArray(t);
          },
          "Every frame's timestamp in seconds, without loading images.")
      .def_property_readonly("warnings", &DatasetReader::warnings, "What was found wrong and survived while opening.")
      .def("__repr__", [](const DatasetReader& d) {
        return "Dataset(kind='" + std::string(toString(d.kind())) + "', root='" + d.root().string() +
               "', frames=" + std::to_string(d.size()) + ")";
      });
  m.def("open_dataset", &openDatasetArgument, "kind"_a, "path"_a, "sensor"_a = py::none(), "sequence"_a = "",
        "depth_scale"_a = py::none(), "max_depth_dt"_a = 0.02, "rectify"_a = true, "strict"_a = false,
        "tolerate_bad_frames"_a = true,
        "Opens a sequence in its own layout: kind 'tum', 'euroc' or 'kitti' (see orbis.datasets).");
}

}  // namespace orbis::python
