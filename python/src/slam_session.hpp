// python/src/slam_session.hpp — one Python Slam object: orbis::Slam<Sensor> plus what the
// binding must guard (a mutex, the shutdown flag, the last timestamp, the camera's image size).
//
// Contract: track() is called with the GIL held, checks the input against the camera, then
// releases the GIL, locks the session and tracks; locked(fn) runs any other query or command the
// same way, and keeps each call's C++ time (trackTimes). The destructor joins the mapping threads without the GIL. Input errors raise
// ValueError (size, timestamp); tracking after shutdown() raises orbis.Error.
#pragma once

#include <pybind11/pybind11.h>

#include <array>
#include <chrono>
#include <cmath>
#include <concepts>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "orbis/camera/rectification.hpp"
#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/system/slam.hpp"
#include "orbis/util/error.hpp"

namespace orbis::python {

namespace py = pybind11;

inline std::vector<const cv::Mat*> inputImages(const StereoInput& in) { return {&in.left, &in.right}; }
inline std::vector<const cv::Mat*> inputImages(const RgbdInput& in) { return {&in.image, &in.depth}; }
inline std::vector<const cv::Mat*> inputImages(const MonocularInput& in) { return {&in.image}; }

// What a sensor's images still carry: radial-tangential distortion (Monocular; zero for the
// rectified stereo and RGB-D images), or the Kannala-Brandt lens of MonocularFisheye.
template <class Sensor>
struct SessionLens {
  using type = RadTanDistortion<double>;
};
template <>
struct SessionLens<MonocularFisheye> {
  using type = KannalaBrandtCamera<double>;
};

template <class Sensor>
class SlamSession {
 public:
  using Camera = typename Sensor::Camera;
  using Lens = typename SessionLens<Sensor>::type;

  // lens: the distortion still in a monocular camera's images (stereo and RGB-D images arrive
  // rectified), or the fisheye lens of MonocularFisheye.
  SlamSession(const Camera& camera, const OrbParams& orb, std::shared_ptr<const OrbVocabulary> vocabulary,
              const SlamOptions& options, const Lens& lens = {})
      : camera_(camera), localisationOnly_(options.localisationOnly), slam_(makeSlam(camera, orb, lens, std::move(vocabulary), options)) {}

  ~SlamSession() {
    if (PyGILState_Check()) {
      py::gil_scoped_release release;  // joining the mapping threads needs no Python
      slam_.reset();
    }
  }

  // Called with the GIL held; validates, then tracks without it.
  py::tuple track(const typename Sensor::Input& input) {
    checkSize(input);
    TrackResult result;
    {
      py::gil_scoped_release release;
      std::lock_guard lock(mutex_);
      if (shutDown_) throw Error("slam", "", "track() after shutdown()");
      if (!std::isfinite(input.timestamp) || !(input.timestamp > lastTimestamp_))
        throw py::value_error("timestamp " + std::to_string(input.timestamp) + " does not increase (last " +
                              std::to_string(lastTimestamp_) + ")");
      lastTimestamp_ = input.timestamp;
      const auto start = std::chrono::steady_clock::now();
      result = slam_->track(input);
      trackMs_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    py::object pose = py::none();
    if (result.state == TrackingState::Ok) pose = poseToArray(result.Tcw.inverse());
    return py::make_tuple(result.state, pose);
  }

  // Runs fn(slam) with the GIL released and the session locked; returns what it returns.
  template <class Fn>
  auto locked(Fn&& fn) {
    py::gil_scoped_release release;
    std::lock_guard lock(mutex_);
    return fn(*slam_);
  }

  void shutdown() {
    locked([](Slam<Sensor>& s) { s.shutdown(); });
    shutDown_ = true;
  }
  void setLocalisationOnly(bool on) {
    locked([on](Slam<Sensor>& s) { s.setLocalisationOnly(on); });
    localisationOnly_ = on;
  }
  bool localisationOnly() const { return localisationOnly_; }
  // Wall time of each track() call's C++ part (Slam::track), ms: the binding's cost is a call's
  // time seen from Python minus this.
  std::vector<double> trackTimes() {
    return locked([this](Slam<Sensor>&) { return trackMs_; });
  }
  const Camera& camera() const { return camera_; }

  // Stereo from settings with LEFT./RIGHT. blocks: raw pairs are rectified on load, as `orbis run`
  // does for frames without a calibration of their own.
  void setRectification(StereoRectification rectification) { rectification_ = std::move(rectification); }
  // A raw input as the pipeline takes it: a stereo pair rectified when the settings say how.
  typename Sensor::Input raw(const typename Sensor::Input& input) const {
    if constexpr (Sensor::kKind == SensorKind::Stereo) {
      if (rectification_ && !input.left.empty() && !input.right.empty()) {
        const RectificationBlock& block = rectification_->left;
        if (input.left.cols != block.width || input.left.rows != block.height)
          throw py::value_error("image of " + std::to_string(input.left.cols) + " x " + std::to_string(input.left.rows) +
                                " pixels; the settings rectify " + std::to_string(block.width) + " x " +
                                std::to_string(block.height));
        StereoRectification::Images rectified = rectification_->rectify(input.left, input.right);
        return {input.timestamp, rectified.left, rectified.right};
      }
    }
    return input;
  }

 private:
  static std::unique_ptr<Slam<Sensor>> makeSlam(const Camera& camera, const OrbParams& orb, const Lens& lens,
                                                std::shared_ptr<const OrbVocabulary> vocabulary, const SlamOptions& options) {
    // A pinhole monocular camera's builder undistorts with the lens; a fisheye camera carries its own.
    if constexpr (std::constructible_from<typename Sensor::FeatureBuilder, const Camera&, const OrbParams&, const Lens&>)
      return std::make_unique<Slam<Sensor>>(camera, orb, lens, std::move(vocabulary), options);
    else return std::make_unique<Slam<Sensor>>(camera, orb, std::move(vocabulary), options);
  }

  void checkSize(const typename Sensor::Input& input) const {
    const cv::Size expected(pinholeOf(camera_).width, pinholeOf(camera_).height);
    for (const cv::Mat* image : inputImages(input)) {
      if (expected.width > 0 && expected.height > 0 && image->size() != expected)
        throw py::value_error("image of " + std::to_string(image->cols) + " x " + std::to_string(image->rows) +
                              " pixels; the camera is " + std::to_string(expected.width) + " x " +
                              std::to_string(expected.height));
      if (image->size() != inputImages(input)[0]->size())
        throw py::value_error("the two images of a frame differ in size");
    }
  }

  Camera camera_;
  std::optional<StereoRectification> rectification_;
  bool localisationOnly_;
  std::unique_ptr<Slam<Sensor>> slam_;
  std::mutex mutex_;
  double lastTimestamp_ = -std::numeric_limits<double>::infinity();
  bool shutDown_ = false;
  std::vector<double> trackMs_;
};

}  // namespace orbis::python
