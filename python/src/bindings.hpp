// python/src/bindings.hpp — the pieces of the _orbis extension module, one function per area.
//
// Contract: each bind* function adds its classes and functions to the flat `_orbis` module;
// module.cpp calls them in dependency order (errors first: the others' docstrings and
// signatures name its types). The Python package orbis/ re-exports and groups them
// (orbis.datasets, orbis.eval, orbis.ba). Every function that does C++ work on more than a
// few values releases the GIL while it runs.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <optional>
#include <string>

#include "orbis/io/settings.hpp"
#include "orbis/tracking/tracker.hpp"

namespace orbis::python {

namespace py = pybind11;

void bindErrors(py::module_& m);      // orbis.Error, orbis.MissingFileError (errors.cpp)
void bindSettings(py::module_& m);    // Settings, OrbParams (settings.cpp)
void bindVocabulary(py::module_& m);  // Vocabulary: load, default, train, transform (vocabulary.cpp)
void bindSlam(py::module_& m);        // TrackingState, StereoSlam, RgbdSlam, MonocularSlam (slam.cpp)
void bindDatasets(py::module_& m);    // Dataset, Frame, open_dataset (datasets.cpp)
void bindTrajectories(py::module_& m);  // read_trajectory, write_trajectory (trajectories.cpp)
void bindEvaluation(py::module_& m);  // ate, rpe, kitti_metric (evaluation.cpp)
void bindBundleAdjustment(py::module_& m);  // BalProblem, solve_bal (bundle_adjustment.cpp)
void bindCalibration(py::module_& m);  // calibrate (calibration.cpp)
void bindSources(py::module_& m);     // sources: video, images, camera (sources.cpp)

// Shared by the bindings: a sensor name ('mono', 'stereo', 'rgbd'; ValueError otherwise), and a
// camera as a dict of its model and parameters (settings.cpp).
SensorKind sensorArgument(const std::string& name);
py::dict describeCamera(const CameraVariant& camera);
// A trajectory format name: '' for None (detect), else 'tum', 'kitti' or 'euroc' (ValueError
// otherwise) (trajectories.cpp).
std::string formatArgument(const std::optional<std::string>& format);
// The shipped vocabulary (vocabulary.cpp: Vocabulary.default()).
std::shared_ptr<OrbVocabulary> defaultVocabulary();

}  // namespace orbis::python
