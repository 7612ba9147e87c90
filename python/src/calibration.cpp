// python/src/calibration.cpp — orbis.calibrate: `orbis calibrate images` from Python.
//
// Contract: calibrate(folder, pattern, model='pinhole', out=None, report=None, min_views=6,
// max_views=40, max_blur=4.0, fps=30.0, right=None) detects the pattern in every image of the folder,
// calibrates (orbis/calibration/calibrate.hpp), writes the settings file when `out` is given and
// the report folder when `report` is, and returns the JSON object `orbis calibrate --json`
// prints, as a dict. Bad input raises orbis.Error with the same message as the program; the GIL
// is released while it works. With `right` (the right camera's folder, images pairing up in name
// order) it calibrates a stereo rig as `orbis calibrate images LEFT --right RIGHT` does
// (orbis/calibration/stereo_calibrate.hpp) and returns that program's stereo JSON.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <opencv2/imgcodecs.hpp>

#include "bindings.hpp"
#include "orbis/calibration/calibrate.hpp"
#include "orbis/calibration/calibration_output.hpp"
#include "orbis/calibration/stereo_calibrate.hpp"

namespace orbis::python {

using namespace pybind11::literals;
namespace fs = std::filesystem;

void bindCalibration(py::module_& m) {
  m.def(
      "calibrate",
      [](const fs::path& folder, const std::string& patternText, const std::string& model,
         const std::optional<fs::path>& out, const std::optional<fs::path>& report, int minViews, int maxViews,
         double maxBlur, double fps, const std::optional<fs::path>& right) {
        std::string json;
        {
          py::gil_scoped_release release;
          const calibration::CalibrationPattern pattern = calibration::parsePattern(patternText, "pattern");
          calibration::CalibrationOptions options;
          options.model = calibration::parseLensModel(model, "model");
          options.minViews = minViews;
          options.maxViews = maxViews;
          options.maxEdgeWidth = maxBlur;
          if (right) {
            const calibration::StereoCalibrationResult result = calibration::calibrateStereo(
                calibration::detectInFolder(folder, pattern), calibration::detectInFolder(*right, pattern), pattern,
                options, folder.string() + " + " + right->string());
            if (out) calibration::writeStereoCalibrationSettings(*out, result, fps);
            if (report) {
              cv::Mat leftImage, rightImage;
              for (std::size_t i = 0; i < result.pairs.size() && leftImage.empty(); ++i)
                if (result.pairs[i].used) {
                  leftImage = cv::imread((folder / result.left.views[i].name).string(), cv::IMREAD_UNCHANGED);
                  rightImage = cv::imread((*right / result.right.views[i].name).string(), cv::IMREAD_UNCHANGED);
                }
              calibration::writeStereoCalibrationReport(*report, result, pattern, leftImage, rightImage);
            }
            json = calibration::stereoCalibrationJson(result, pattern, out.value_or(fs::path()));
          } else {
            const calibration::CalibrationResult result =
                calibration::calibrate(calibration::detectInFolder(folder, pattern), pattern, options, folder.string());
            if (out) calibration::writeCalibrationSettings(*out, result.camera, fps);
            if (report) {
              const cv::Mat preview = result.usedNames.empty()
                                          ? cv::Mat()
                                          : cv::imread((folder / result.usedNames.front()).string(), cv::IMREAD_UNCHANGED);
              calibration::writeCalibrationReport(*report, result, pattern, preview);
            }
            json = calibration::calibrationJson(result, pattern, out.value_or(fs::path()));
          }
        }
        return py::module_::import("json").attr("loads")(json);
      },
      "folder"_a, "pattern"_a, "model"_a = "pinhole", "out"_a = py::none(), "report"_a = py::none(),
      "min_views"_a = 6, "max_views"_a = 40, "max_blur"_a = 4.0, "fps"_a = 30.0, "right"_a = py::none(),
      "Calibrates a camera from a folder of images of a chessboard or ChArUco board, as\n"
      "`orbis calibrate images`: pattern 'chessboard:9x6:0.025' or 'charuco:8x6:0.04:0.03[:DICT]',\n"
      "model 'pinhole' or 'fisheye'; writes the settings YAML to `out` and the report into `report`\n"
      "when given. Returns a dict: fx, fy, cx, cy, distortion, rms, views_used, model, parameters\n"
      "(value and std of each), views (per image), outliers, warnings. right: the right camera's\n"
      "folder of a stereo rig: the left camera's keys, plus right, baseline, baseline_std, stereo_rms,\n"
      "rectified, pairs; `out` gets the rectified stereo settings.");
}

}  // namespace orbis::python
