// python/src/sources.cpp — orbis.sources: videos, image folders and cameras as Python iterators.
//
// Contract: a Source is an iterator of SourceFrame (index, timestamp, image, right, depth as
// NumPy arrays sharing the decoded images' memory); iteration ends with the source, and the GIL
// is released while a frame is awaited or decoded. A live source (camera, stream, or realtime=True)
// keeps only the newest frame: `dropped` counts the ones a slow loop missed. Opening errors
// raise orbis.Error (orbis.MissingFileError for a missing file or folder) naming the input; a
// frame that cannot be decoded raises orbis.Error on that next() only. close() ends a live
// source's capture thread (also done when the object goes away).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "orbis/adapters/frame_source.hpp"

namespace orbis::python {

using namespace pybind11::literals;
namespace fs = std::filesystem;

namespace {

// The source behind a Python iterator; close() drops it (joining a capture thread).
struct PySource {
  std::unique_ptr<FrameSource> source;
  std::string name;

  FrameSource& get() {
    if (!source) throw Error(name, "", "the source is closed");
    return *source;
  }
};

SourceOptions makeOptions(std::optional<double> fps, std::optional<fs::path> times, const std::string& stereo, bool grey,
                          double stall) {
  SourceOptions o;
  if (fps) {
    if (!(*fps > 0)) throw py::value_error("fps must be positive");
    o.fps = *fps;
  }
  o.timesFile = std::move(times);
  o.stereo = parseStereoPacking(stereo, "stereo");
  o.grey = grey;
  if (!(stall > 0)) throw py::value_error("stall must be positive");
  o.stallSeconds = stall;
  return o;
}

std::unique_ptr<PySource> wrap(std::unique_ptr<FrameSource> source, bool realtime, double stall) {
  if (realtime) source = makeLiveSource(std::move(source), true, stall);
  auto out = std::make_unique<PySource>();
  out->name = source->name();
  out->source = std::move(source);
  return out;
}

}  // namespace

void bindSources(py::module_& m) {
  py::module_ s = m.def_submodule("sources", "Videos, image folders and cameras as iterators of SourceFrame.");
  py::class_<SourceFrame>(s, "SourceFrame", "One frame of a source: timestamp and images as NumPy arrays.")
      .def_readonly("index", &SourceFrame::index, "Position in the source (a live source's dropped frames count).")
      .def_readonly("timestamp", &SourceFrame::timestamp, "Seconds.")
      .def_property_readonly("image", [](const SourceFrame& f) { return matToArray(f.image); },
                             "uint8 H x W (grey) or H x W x 3 (BGR).")
      .def_property_readonly("right", [](const SourceFrame& f) { return matToArray(f.right); },
                             "The right view of a stereo source, or None.")
      .def_property_readonly("depth", [](const SourceFrame& f) { return matToArray(f.depth); },
                             "uint16 raw depth of an RGB-D source, or None.")
      .def_readonly("warnings", &SourceFrame::warnings)
      .def("__repr__", [](const SourceFrame& f) {
        return "SourceFrame(index=" + std::to_string(f.index) + ", timestamp=" + std::to_string(f.timestamp) + ")";
      });
  py::class_<PySource>(s, "Source", "Frames one after another; iterate over it.")
      .def("__iter__", [](PySource& p) -> PySource& { return p; })
      .def("__next__",
           [](PySource& p) {
             FrameSource& source = p.get();
             std::optional<SourceFrame> frame;
             {
               py::gil_scoped_release release;
               frame = source.next();
             }
             if (!frame) throw py::stop_iteration();
             return std::move(*frame);
           })
      .def("close", [](PySource& p) {
        py::gil_scoped_release release;
        p.source.reset();
      }, "Ends the source (and a live source's capture thread).")
      .def("__enter__", [](PySource& p) -> PySource& { return p; })
      .def("__exit__", [](PySource& p, const py::args&) {
        py::gil_scoped_release release;
        p.source.reset();
      })
      .def_property_readonly("name", [](const PySource& p) { return p.name; })
      .def_property_readonly("live", [](PySource& p) { return p.get().live(); })
      .def_property_readonly("sensor", [](PySource& p) { return std::string(toString(p.get().sensor())); })
      .def_property_readonly("dropped", [](PySource& p) { return p.get().dropped(); },
                             "Frames a live source captured but a slow loop never took (newest frame wins).")
      .def_property_readonly("end_reason", [](PySource& p) { return p.get().endReason(); },
                             "Why the source ended early ('' for a plain end).")
      .def_property_readonly("expected_frames", [](PySource& p) { return p.get().expectedFrames(); })
      .def_property_readonly("warnings", [](PySource& p) { return p.get().warnings(); });

  s.def(
      "video",
      [](const std::string& path, std::optional<double> fps, std::optional<fs::path> times, const std::string& stereo,
         bool grey, bool realtime, double stall) {
        return wrap(openVideoSource(path, makeOptions(fps, std::move(times), stereo, grey, stall)), realtime, stall);
      },
      "path"_a, py::kw_only(), "fps"_a = py::none(), "times"_a = py::none(), "stereo"_a = "none", "grey"_a = false,
      "realtime"_a = false, "stall"_a = 5.0,
      "A video file, URL or GStreamer pipeline. fps or a times file override the container's timestamps;\n"
      "realtime=True plays a file as a live camera would (paced, newest frame wins).");
  s.def(
      "images",
      [](const fs::path& folder, std::optional<double> fps, std::optional<fs::path> times, const std::string& stereo,
         bool grey, bool realtime, double stall) {
        return wrap(openImageFolderSource(folder, makeOptions(fps, std::move(times), stereo, grey, stall)), realtime, stall);
      },
      "folder"_a, py::kw_only(), "fps"_a = py::none(), "times"_a = py::none(), "stereo"_a = "none", "grey"_a = false,
      "realtime"_a = false, "stall"_a = 5.0,
      "A folder of images in name order; timestamps from times, times.txt/timestamps.txt, fps or the names.");
  s.def(
      "camera",
      [](const py::object& device, std::optional<double> fps, const std::string& stereo, bool grey, double stall) {
        const std::string name = py::isinstance<py::int_>(device) ? std::to_string(device.cast<int>()) : device.cast<std::string>();
        return wrap(openCameraSource(name, makeOptions(fps, std::nullopt, stereo, grey, stall)), false, stall);
      },
      "device"_a = 0, py::kw_only(), "fps"_a = py::none(), "stereo"_a = "none", "grey"_a = false, "stall"_a = 5.0,
      "A live camera: an index, '/dev/videoN' or a GStreamer pipeline; frames timed on arrival.");
}

}  // namespace orbis::python
