// python/src/module.cpp — the _orbis extension module: orbis's C++ library for Python.
//
// Contract: defines `_orbis` with __version__ (orbis::versionString(), include/orbis/version.hpp)
// and every binding of bindings.hpp; the Python package orbis/ is its public face.
#include "bindings.hpp"
#include "orbis/version.hpp"

PYBIND11_MODULE(_orbis, m) {
  using namespace orbis::python;
  m.doc() = "orbis: ORB-SLAM2 visual SLAM (monocular, stereo, RGB-D) from Python; see the orbis package.";
  m.attr("__version__") = orbis::versionString();
  bindErrors(m);
  bindSettings(m);
  bindVocabulary(m);
  bindDatasets(m);
  bindTrajectories(m);
  bindSources(m);
  bindSlam(m);
  bindEvaluation(m);
  bindBundleAdjustment(m);
  bindCalibration(m);
}
