// python/src/slam.cpp — orbis.StereoSlam, orbis.RgbdSlam and orbis.MonocularSlam over
// orbis::Slam<Stereo|Rgbd|Monocular>.
//
// Contract: a Slam object is built from Settings (its camera must be the class's sensor) or from
// a Dataset (its own calibration, with `orbis run`'s per-dataset ORB budget and frame rate), a
// vocabulary (default: the shipped one) and SlamOptions given as keywords. track() takes NumPy
// images (views, no copy), a dataset Frame or a source's SourceFrame and returns (TrackingState, 4 x 4 camera-to-world
// pose or None when not tracked); the GIL is released while C++ tracks, and calls on one object
// are serialised by its own mutex. Wrong dtype -> TypeError, wrong or mismatched shape, a
// non-increasing timestamp, a frame without its second image -> ValueError; tracking after
// shutdown() or loading a map after the first frame -> orbis.Error. Trajectories are N x 8 TUM
// rows; save_trajectory writes them with the library's writer, so a deterministic run's file is
// byte-identical to `orbis run --deterministic`'s trajectory.txt.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <limits>
#include <mutex>

#include "arrays.hpp"
#include "bindings.hpp"
#include "errors.hpp"
#include "orbis/adapters/dataset.hpp"
#include "orbis/adapters/frame_source.hpp"
#include "orbis/system/slam.hpp"
#include "orbis/util/error.hpp"
#include "slam_session.hpp"

namespace orbis::python {

using namespace pybind11::literals;
namespace fs = std::filesystem;

namespace {

py::dict statsDict(const SlamStats& s, const RelocalisationStats& r, std::size_t loadedKeyFrames) {
  return py::dict("frames"_a = s.frames, "tracked"_a = s.tracked, "lost"_a = s.lost, "keyframes"_a = s.keyFrames,
                  "map_points"_a = s.mapPoints, "loop_closures"_a = s.loopClosures,
                  "relocalisation_attempts"_a = r.attempts, "relocalisations"_a = r.successes,
                  "keyframes_loaded"_a = loadedKeyFrames, "maps"_a = s.maps, "map_merges"_a = s.mapMerges);
}

py::list timingList(const std::vector<StageStats>& stages) {
  py::list out;
  for (const StageStats& s : stages)
    out.append(py::dict("stage"_a = s.stage, "count"_a = s.count, "mean_ms"_a = s.meanMs, "median_ms"_a = s.medianMs,
                        "p95_ms"_a = s.p95Ms, "max_ms"_a = s.maxMs));
  return out;
}

template <class Sensor>
void bindQueries(py::class_<SlamSession<Sensor>>& c) {
  using Session = SlamSession<Sensor>;
  using S = Slam<Sensor>;
  c.def("trajectory", [](Session& s) { return trajectoryToArray(s.locked([](S& slam) { return slam.trajectory(); })); },
        "Every tracked frame: (N, 8) float64 rows t x y z qx qy qz qw, camera-to-world, as corrected by\n"
        "later loop closures and bundle adjustment.")
      .def("keyframe_trajectory",
           [](Session& s) { return trajectoryToArray(s.locked([](S& slam) { return slam.keyFrameTrajectory(); })); },
           "Every keyframe: (N, 8) float64 TUM rows, camera-to-world.")
      .def(
          "save_trajectory",
          [](Session& s, const fs::path& path, const std::string& format, bool keyframes) {
            const TrajectoryFormat f = parseTrajectoryFormat(format, "format");
            s.locked([&](S& slam) { writeTrajectory(path, keyframes ? slam.keyFrameTrajectory() : slam.trajectory(), f); });
          },
          "path"_a, "format"_a = "tum", "keyframes"_a = false,
          "Writes the trajectory ('tum', 'kitti' or 'euroc') with the library's writer, as `orbis run` does.")
      .def(
          "map_points",
          [](Session& s) {
            const auto cloud = s.locked([](S& slam) { return slam.mapPointCloud(); });
            py::array_t<float> out({static_cast<py::ssize_t>(cloud.size()), py::ssize_t{3}});
            auto rows = out.template mutable_unchecked<2>();
            for (std::size_t i = 0; i < cloud.size(); ++i)
              for (int k = 0; k < 3; ++k) rows(static_cast<py::ssize_t>(i), k) = cloud[i][k];
            return out;
          },
          "The map's points: (N, 3) float32 world coordinates, metres.")
      .def("timing", [](Session& s) { return timingList(s.locked([](S& slam) { return slam.timer().summary(); })); },
           "Per-stage timing: a list of dicts stage, count, mean_ms, median_ms, p95_ms, max_ms.")
      .def("track_times", [](Session& s) { return vectorToArray(s.trackTimes()); },
           "Wall time in ms of each track() call's C++ part (ORB extraction and tracking, plus mapping\n"
           "inline in deterministic mode); a call's time seen from Python minus this is the binding's.")
      .def(
          "maps",
          [](Session& s) {
            py::list out;
            for (const AtlasMapInfo& m : s.locked([](S& slam) { return slam.core().maps(); }))
              out.append(py::dict("id"_a = m.id, "keyframes"_a = m.keyFrames, "map_points"_a = m.mapPoints,
                                  "start_frame"_a = m.startFrame, "active"_a = m.active,
                                  "merged_into"_a = m.merged ? py::object(py::int_(m.mergedInto)) : py::none()));
            return out;
          },
          "The atlas: every map opened, as dicts id, keyframes, map_points, start_frame, active,\n"
          "merged_into (None, or the map it was merged into).")
      .def_property_readonly(
          "active_map", [](Session& s) { return s.locked([](S& slam) { return slam.core().activeMapId(); }); },
          "Id of the map tracking works in.")
      .def(
          "merges",
          [](Session& s) {
            py::list out;
            for (const MapMergeEvent& e : s.locked([](S& slam) { return slam.core().merges(); }))
              out.append(py::dict("frame"_a = e.frameIndex, "other_frame"_a = e.otherFrameIndex, "current_keyframe"_a = e.current,
                                  "other_keyframe"_a = e.other, "active_map"_a = e.activeMap,
                                  "other_map"_a = e.otherMap, "moved_map"_a = e.movedMap, "kept_map"_a = e.keptMap,
                                  "inliers"_a = e.inliers, "fused_points"_a = e.fusedPoints, "scale"_a = e.scale,
                                  "rotation_wxyz"_a = py::make_tuple(e.rotation[0], e.rotation[1], e.rotation[2],
                                                                     e.rotation[3]),
                                  "translation"_a = py::make_tuple(e.translation[0], e.translation[1], e.translation[2]),
                                  "ms"_a = e.milliseconds));
            return out;
          },
          "Merges of two maps so far, in order: frame, keyframes, maps, inliers, the move (x_kept =\n"
          "scale * R * x_moved + translation) and the time it took.")
      .def(
          "trajectory_maps",
          [](Session& s, bool current) {
            const auto maps = s.locked([current](S& slam) { return slam.core().trajectoryMaps(current); });
            return vectorToArray(std::vector<double>(maps.begin(), maps.end()));
          },
          "current"_a = false,
          "Per row of trajectory(): the map the frame was tracked in (current=True: the map holding it now).")
      .def_property_readonly("state", [](Session& s) { return s.locked([](S& slam) { return slam.state(); }); })
      .def_property_readonly("camera", [](const Session& s) {
        // A fisheye session's camera is described by its lens, as the settings name it.
        if constexpr (ObservesThroughLens<typename Session::Camera>) return describeCamera(s.camera().lens);
        else return describeCamera(s.camera());
      });
  c.def(
      "stats",
      [](Session& s) {
    const auto [stats, relocalisation, loaded] = s.locked([](S& slam) {
      return std::make_tuple(slam.stats(), slam.core().relocalisationStats(), slam.core().loadedKeyFrames());
    });
        return statsDict(stats, relocalisation, loaded);
      },
      "Counts as a dict: frames, tracked, lost, keyframes, map_points, loop_closures,\n"
      "relocalisation_attempts, relocalisations, keyframes_loaded.");
}

template <class Sensor>
void bindControl(py::class_<SlamSession<Sensor>>& c) {
  using Session = SlamSession<Sensor>;
  using S = Slam<Sensor>;
  c.def("shutdown", &Session::shutdown,
        "Finishes queued mapping work and joins the threads; queries stay valid, track() does not.")
      .def_property("localisation_only", &Session::localisationOnly, &Session::setLocalisationOnly,
                    "Tracking only, against the existing map (no keyframes, no map changes).")
      .def(
          "save_map", [](Session& s, const fs::path& path) { s.locked([&](S& slam) { slam.core().saveMap(path); }); },
          "path"_a, "Saves keyframes, points and graphs (with sensor, camera and vocabulary checksum).")
      .def(
          "load_map",
          [](Session& s, const fs::path& path) {
            requireFile(path);
            s.locked([&](S& slam) { slam.core().loadMap(path); });
          },
          "path"_a, "Loads a saved map before the first frame; tracking then relocalises in it.")
      .def("__enter__", [](Session& s) -> Session& { return s; })
      .def("__exit__", [](Session& s, const py::args&) { s.shutdown(); });
}

// What track() calls each sensor's two images, how the second is checked, and where a dataset
// Frame keeps it. Both inputs are aggregates {timestamp, first image, second image}.
template <class Sensor>
struct TrackArguments;

template <>
struct TrackArguments<Stereo> {
  static constexpr const char* kFirst = "left";
  static constexpr const char* kSecond = "right";
  static constexpr auto kSecondView = &imageView;
  static constexpr cv::Mat DatasetFrame::*kSecondOfFrame = &DatasetFrame::right;
};

template <>
struct TrackArguments<Rgbd> {
  static constexpr const char* kFirst = "image";
  static constexpr const char* kSecond = "depth";
  static constexpr auto kSecondView = &depthView;
  static constexpr cv::Mat DatasetFrame::*kSecondOfFrame = &DatasetFrame::depth;
};

template <class Sensor>
void bindPairTrack(py::class_<SlamSession<Sensor>>& c);

template <class Sensor>
void bindTrack(py::class_<SlamSession<Sensor>>& c) {
  if constexpr (Sensor::kKind == SensorKind::Monocular) {
    c.def(
         "track",
         [](SlamSession<Sensor>& s, const py::handle& image, double timestamp) {
           const ImageView view = imageView(image, "image");
           return s.track(MonocularInput{timestamp, view.mat});
         },
         "image"_a, "timestamp"_a,
         "Tracks one frame; returns (TrackingState, 4 x 4 float64 camera-to-world pose, or None when\n"
         "not tracked). The image is used in place when its rows are contiguous.")
        .def(
            "track", [](SlamSession<Sensor>& s, const DatasetFrame& frame) { return s.track(MonocularInput{frame.timestamp, frame.left}); },
            "frame"_a, "Tracks a dataset Frame (its image and timestamp).")
        .def(
            "track", [](SlamSession<Sensor>& s, const SourceFrame& frame) { return s.track(MonocularInput{frame.timestamp, frame.image}); },
            "frame"_a, "Tracks a frame of orbis.sources (its image and timestamp).");
  } else {
    bindPairTrack<Sensor>(c);
  }
}

template <class Sensor>
void bindPairTrack(py::class_<SlamSession<Sensor>>& c) {
  using Args = TrackArguments<Sensor>;
  using Input = typename Sensor::Input;
  c.def(
       "track",
       [](SlamSession<Sensor>& s, const py::handle& first, const py::handle& second, double timestamp) {
         const ImageView firstView = imageView(first, Args::kFirst), secondView = Args::kSecondView(second, Args::kSecond);
         return s.track(s.raw(Input{timestamp, firstView.mat, secondView.mat}));
       },
       py::arg(Args::kFirst), py::arg(Args::kSecond), "timestamp"_a,
       "Tracks one frame; returns (TrackingState, 4 x 4 float64 camera-to-world pose, or None when\n"
       "not tracked). Images are used in place when their rows are contiguous.")
      .def(
          "track",
          [](SlamSession<Sensor>& s, const DatasetFrame& frame) {
            const cv::Mat& second = frame.*Args::kSecondOfFrame;
            if (frame.left.empty() || second.empty())
              throw py::value_error("frame " + std::to_string(frame.index) + " has no " + Args::kSecond + " image");
            return s.track(Input{frame.timestamp, frame.left, second});
          },
          "frame"_a, "Tracks a dataset Frame (its images and timestamp).")
      .def(
          "track",
          [](SlamSession<Sensor>& s, const SourceFrame& frame) {
            const cv::Mat& second = Sensor::kKind == SensorKind::Stereo ? frame.right : frame.depth;
            if (frame.image.empty() || second.empty())
              throw py::value_error("frame " + std::to_string(frame.index) + " has no " + Args::kSecond + " image");
            return s.track(s.raw(Input{frame.timestamp, frame.image, second}));
          },
          "frame"_a, "Tracks a frame of orbis.sources (its images and timestamp).");
}

// `orbis run`'s ORB budget and frame rate for a sequence without a settings file
// (src/system/dataset_runner.cpp keeps the same table).
struct DatasetDefaults {
  int features;
  double fps;
};

DatasetDefaults datasetDefaults(DatasetKind kind) {
  if (kind == DatasetKind::Euroc) return {1200, 20};
  if (kind == DatasetKind::Kitti) return {2000, 10};
  return {1000, 30};
}

std::shared_ptr<const OrbVocabulary> vocabularyOrDefault(std::shared_ptr<OrbVocabulary> vocabulary) {
  if (vocabulary) return vocabulary;
  return defaultVocabulary();
}

// A session of a pinhole sensor (Monocular, Stereo, Rgbd) from settings.
template <class Sensor>
std::unique_ptr<SlamSession<Sensor>> makePinholeSession(const Settings& settings, std::shared_ptr<OrbVocabulary> vocabulary,
                                                        const SlamOptions& options, std::optional<double> fps);

template <class Sensor>
std::unique_ptr<SlamSession<Sensor>> makeSession(const Settings& settings, std::shared_ptr<OrbVocabulary> vocabulary,
                                                  const SlamOptions& options, std::optional<double> fps) {
  if constexpr (std::is_same_v<Sensor, MonocularFisheye>) {
    const auto* lens = std::get_if<KannalaBrandtCamera<double>>(&settings.camera);
    if (!lens)
      throw py::value_error("the settings describe no fisheye (Camera.type: KannalaBrandt8); use MonocularSlam");
    SlamOptions o = options;
    o.fps = fps.value_or(settings.fps);
    return std::make_unique<SlamSession<Sensor>>(MonocularFisheye::cameraOf(*lens), settings.orb,
                                                 vocabularyOrDefault(std::move(vocabulary)), o, *lens);
  } else {
    return makePinholeSession<Sensor>(settings, std::move(vocabulary), options, fps);
  }
}

template <class Sensor>
std::unique_ptr<SlamSession<Sensor>> makePinholeSession(const Settings& settings, std::shared_ptr<OrbVocabulary> vocabulary,
                                                        const SlamOptions& options, std::optional<double> fps) {
  if constexpr (Sensor::kKind == SensorKind::Monocular) {
    if (std::holds_alternative<KannalaBrandtCamera<double>>(settings.camera))
      throw py::value_error("the settings describe a fisheye (Camera.type: KannalaBrandt8): orbis.MonocularSlam runs it "
                            "as orbis.MonocularFisheyeSlam");
  }
  const auto* camera = std::get_if<typename Sensor::Camera>(&settings.camera);
  if (!camera)
    throw py::value_error("the settings describe a " + std::string(toString(settings.sensor)) + " camera; this class needs " +
                          std::string(toString(Sensor::kKind)) + " (Settings.load(path, sensor=...))");
  SlamOptions o = options;
  o.fps = fps.value_or(settings.fps);
  auto session = std::make_unique<SlamSession<Sensor>>(*camera, settings.orb, vocabularyOrDefault(std::move(vocabulary)),
                                                       o, settings.distortion);
  if constexpr (Sensor::kKind == SensorKind::Stereo)
    if (settings.rectification) session->setRectification(settings.stereoRectification());
  return session;
}

// A session of a pinhole sensor from a dataset's own calibration.
template <class Sensor>
std::unique_ptr<SlamSession<Sensor>> makeDatasetSession(const DatasetReader& dataset, std::shared_ptr<OrbVocabulary> vocabulary,
                                                        const SlamOptions& options, std::optional<double> fps);

template <class Sensor>
std::unique_ptr<SlamSession<Sensor>> makeSession(const DatasetReader& dataset, std::shared_ptr<OrbVocabulary> vocabulary,
                                                 const SlamOptions& options, std::optional<double> fps) {
  if constexpr (std::is_same_v<Sensor, MonocularFisheye>) {
    throw py::value_error("a dataset is read through a pinhole (a fisheye EuRoC is undistorted on load): use "
                          "MonocularSlam, or Settings with Camera.type: KannalaBrandt8");
  } else {
    return makeDatasetSession<Sensor>(dataset, std::move(vocabulary), options, fps);
  }
}

template <class Sensor>
std::unique_ptr<SlamSession<Sensor>> makeDatasetSession(const DatasetReader& dataset, std::shared_ptr<OrbVocabulary> vocabulary,
                                                        const SlamOptions& options, std::optional<double> fps) {
  const DatasetCamera camera = dataset.camera();
  const auto* typed = std::get_if<typename Sensor::Camera>(&camera);
  if (!typed)
    throw py::value_error("the dataset is read as " + std::string(toString(dataset.sensor())) + "; this class needs " +
                          std::string(toString(Sensor::kKind)));
  const DatasetDefaults defaults = datasetDefaults(dataset.kind());
  OrbParams orb;
  orb.features = defaults.features;
  SlamOptions o = options;
  o.fps = fps.value_or(defaults.fps);
  return std::make_unique<SlamSession<Sensor>>(*typed, orb, vocabularyOrDefault(std::move(vocabulary)), o,
                                               dataset.distortion());
}

// One constructor: from Settings or from a Dataset (makeSession), with SlamOptions as keywords.
template <class Sensor, class Source>
void bindConstructor(py::class_<SlamSession<Sensor>>& c, const char* source, const char* doc) {
  c.def(py::init([](const Source& from, std::shared_ptr<OrbVocabulary> vocabulary, bool deterministic,
                    bool localisationOnly, bool loopClosing, std::uint32_t seed, std::optional<double> fps, bool atlas,
                    int newMapAfterLostFrames, double newMapAfterLostSeconds) {
          SlamOptions o;
          o.deterministic = deterministic;
          o.localisationOnly = localisationOnly;
          o.loopClosing = loopClosing;
          o.seed = seed;
          o.atlas = atlas;
          o.newMapAfterLostFrames = newMapAfterLostFrames;
          o.newMapAfterLostSeconds = newMapAfterLostSeconds;
          return makeSession<Sensor>(from, std::move(vocabulary), o, fps);
        }),
        py::arg(source), "vocabulary"_a = py::none(), py::kw_only(), "deterministic"_a = false,
        "localisation_only"_a = false, "loop_closing"_a = true, "seed"_a = 0, "fps"_a = py::none(), "atlas"_a = true,
        "new_map_after_lost_frames"_a = 10, "new_map_after_lost_seconds"_a = 0.3, doc);
}

template <class Sensor>
void bindSlamClass(py::module_& m, const char* name, const char* doc) {
  py::class_<SlamSession<Sensor>> c(m, name, doc);
  bindConstructor<Sensor, Settings>(c, "settings",
                                    "From Settings: camera, ORB parameters and fps from the file. deterministic runs\n"
                                    "mapping and loop closing inline (same input, same trajectory); seed seeds RANSAC\n"
                                    "(0 by default, as `orbis run`); fps overrides the file's. atlas=False keeps\n"
                                    "ORB-SLAM2's single map (lost until relocalised); otherwise a new map starts once\n"
                                    "relocalisation failed new_map_after_lost_frames frames over\n"
                                    "new_map_after_lost_seconds, and maps merge when a common place is seen.");
  bindConstructor<Sensor, DatasetReader>(c, "dataset",
                                         "From a Dataset's own calibration, with `orbis run`'s ORB budget and fps for\n"
                                         "its kind (TUM 1000 / 30, EuRoC 1200 / 20, KITTI 2000 / 10).");
  bindTrack<Sensor>(c);
  bindQueries<Sensor>(c);
  bindControl<Sensor>(c);
}

}  // namespace

void bindSlam(py::module_& m) {
  py::enum_<TrackingState>(m, "TrackingState", "Tracking state of the last frame.")
      .value("NOT_INITIALISED", TrackingState::NotInitialised)
      .value("OK", TrackingState::Ok)
      .value("LOST", TrackingState::Lost);
  bindSlamClass<Stereo>(m, "StereoSlam",
                        "ORB-SLAM2 on a rectified stereo camera (orbis::Slam<orbis::Stereo>).\n"
                        "track(left, right, timestamp) or track(frame). Built from Settings with LEFT./RIGHT.\n"
                        "rectification blocks (ORB-SLAM2's EuRoC.yaml, `orbis calibrate --right`, fisheye pairs\n"
                        "included), raw pairs and sources' frames are rectified on load; a dataset's Frame comes\n"
                        "rectified by its reader and is tracked as it is.");
  bindSlamClass<Rgbd>(m, "RgbdSlam",
                      "ORB-SLAM2 on an RGB-D camera (orbis::Slam<orbis::Rgbd>).\n"
                      "track(image, depth, timestamp) or track(frame).");
  bindSlamClass<MonocularFisheye>(m, "MonocularFisheyeSlam",
                                  "ORB-SLAM2 on one Kannala-Brandt fisheye camera, on the fisheye images directly\n"
                                  "(orbis::Slam<orbis::MonocularFisheye>, docs/guide/fisheye.md): built from Settings\n"
                                  "with Camera.type: KannalaBrandt8 (orbis.MonocularSlam(settings) gives one for such\n"
                                  "settings). track(image, timestamp) or track(frame).");
  bindSlamClass<Monocular>(m, "MonocularSlam",
                           "ORB-SLAM2 on one camera (orbis::Slam<orbis::Monocular>): the map's scale is arbitrary.\n"
                           "track(image, timestamp) or track(frame). Lens distortion (Camera.k1..k3) is undistorted\n"
                           "at the keypoints, as `orbis run --sensor mono` does.");
}

}  // namespace orbis::python
