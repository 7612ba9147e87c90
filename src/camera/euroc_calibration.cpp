// EuRoC sensor.yaml reader; see orbis/camera/euroc_calibration.hpp.
//
// The files ASL publishes are plain YAML starting with a comment; OpenCV's FileStorage refuses
// them (it wants its own "%YAML:1.0" first line), so they are read with yaml-cpp, which also
// takes the copies that have that line added (it skips an unknown directive).
#include "orbis/camera/euroc_calibration.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "orbis/util/error.hpp"

namespace orbis {
namespace {

class SensorYaml {
 public:
  explicit SensorYaml(const std::filesystem::path& file) : path_(file.string()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) throw fileError(path_, "no such file");
    std::ifstream in(file, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    if (!in) throw fileError(path_, "cannot be read");
    if (text.str().find_first_not_of(" \t\r\n") == std::string::npos)
      throw fileError(path_, "empty file, expected a EuRoC camera description (YAML)");
    try {
      root_ = YAML::Load(text.str());
    } catch (const YAML::Exception& e) {
      throw lineError(path_, static_cast<std::size_t>(e.mark.line) + 1, "not valid YAML: " + e.msg);
    }
    if (!root_.IsMap()) throw fileError(path_, "expected a YAML map of keys at the top level");
  }

  Error error(const std::string& key, const std::string& what) const { return keyError(path_, key, what); }

  std::optional<std::string> optionalString(const std::string& key) const {
    const YAML::Node n = root_[key];
    if (!n) return std::nullopt;
    if (!n.IsScalar()) throw error(key, "expected text, found " + describe(n));
    return n.Scalar();
  }

  // A YAML sequence of numbers whose length lies in [minCount, maxCount].
  std::vector<double> reals(const std::string& key, std::size_t minCount, std::size_t maxCount) const {
    return numbers(required(root_, key), key, minCount, maxCount);
  }

  // A map with rows, cols and data (row-major), of exactly the given size.
  Eigen::MatrixXd matrix(const std::string& key, int rows, int cols) const {
    const YAML::Node n = required(root_, key);
    if (!n.IsMap()) throw error(key, "expected a matrix (a map with rows, cols and data), found " + describe(n));
    const double r = number(required(n, "rows", key), key + ".rows");
    const double c = number(required(n, "cols", key), key + ".cols");
    if (r != rows || c != cols)
      throw error(key, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix");
    const std::size_t count = static_cast<std::size_t>(rows * cols);
    const std::vector<double> data = numbers(required(n, "data", key), key + ".data", count, count);
    Eigen::MatrixXd m(rows, cols);
    for (std::size_t i = 0; i < count; ++i) m(static_cast<int>(i) / cols, static_cast<int>(i) % cols) = data[i];
    return m;
  }

 private:
  static std::string describe(const YAML::Node& n) {
    if (n.IsSequence()) return "a sequence";
    if (n.IsMap()) return "a map";
    if (n.IsNull()) return "no value";
    return "the text \"" + n.Scalar() + "\"";
  }

  YAML::Node required(const YAML::Node& parent, const std::string& key, const std::string& prefix = {}) const {
    const YAML::Node n = parent[key];
    if (!n) throw error(prefix.empty() ? key : prefix + "." + key, "missing");
    return n;
  }

  double number(const YAML::Node& n, const std::string& key) const {
    double value = 0.0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, value))
      throw error(key, "expected a number, found " + describe(n));
    if (!std::isfinite(value)) throw error(key, "expected a finite number");
    return value;
  }

  std::vector<double> numbers(const YAML::Node& n, const std::string& key, std::size_t minCount,
                              std::size_t maxCount) const {
    if (!n.IsSequence()) throw error(key, "expected a sequence of numbers, found " + describe(n));
    if (n.size() < minCount || n.size() > maxCount)
      throw error(key, "expected " + std::to_string(minCount) +
                           (maxCount != minCount ? " to " + std::to_string(maxCount) : "") + " numbers, found " +
                           std::to_string(n.size()));
    std::vector<double> values;
    for (const YAML::Node& item : n) values.push_back(number(item, key));
    return values;
  }

  std::string path_;
  YAML::Node root_;
};

}  // namespace

CameraCalibration readEurocCalibration(const std::filesystem::path& sensorYaml) {
  const SensorYaml yaml(sensorYaml);
  if (const auto model = yaml.optionalString("camera_model"); model && *model != "pinhole") {
    throw yaml.error("camera_model", "only pinhole is supported, found \"" + *model + "\"");
  }
  if (const auto model = yaml.optionalString("distortion_model"); model && *model != "radial-tangential") {
    throw yaml.error("distortion_model", "only radial-tangential is supported, found \"" + *model + "\"");
  }
  const std::vector<double> k = yaml.reals("intrinsics", 4, 4);
  const std::vector<double> d = yaml.reals("distortion_coefficients", 4, 5);
  const std::vector<double> resolution = yaml.reals("resolution", 2, 2);
  if (!(k[0] > 0 && k[1] > 0)) throw yaml.error("intrinsics", "focal lengths fu, fv must be positive");
  if (!(resolution[0] >= 1 && resolution[1] >= 1 && resolution[0] <= 1e5 && resolution[1] <= 1e5 &&
        resolution[0] == std::floor(resolution[0]) && resolution[1] == std::floor(resolution[1])))
    throw yaml.error("resolution", "expected a whole positive width and height");

  CameraCalibration c;
  c.intrinsics = {k[0], k[1], k[2], k[3], static_cast<int>(resolution[0]), static_cast<int>(resolution[1])};
  c.distortion = {d[0], d[1], d[2], d[3], d.size() == 5 ? d[4] : 0.0};
  c.bodyFromCamera = yaml.matrix("T_BS", 4, 4);
  const Eigen::Matrix3d R = c.bodyFromCamera.topLeftCorner<3, 3>();
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0 ||
      !c.bodyFromCamera.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1))) {
    throw yaml.error("T_BS", "expected a rigid transform (orthonormal rotation, last row 0 0 0 1)");
  }
  return c;
}

}  // namespace orbis
