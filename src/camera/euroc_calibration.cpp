// EuRoC sensor.yaml reader; see orbis/camera/euroc_calibration.hpp.
//
// The files ASL publishes are plain YAML starting with a comment; OpenCV's FileStorage refuses
// them (it wants its own "%YAML:1.0" first line): YamlReader (yaml-cpp) takes them, and the
// copies that have that line added.
#include "orbis/camera/euroc_calibration.hpp"

#include <cmath>

#include "yaml_reader.hpp"

namespace orbis {

CameraCalibration readEurocCalibration(const std::filesystem::path& sensorYaml) {
  const detail::YamlReader yaml(sensorYaml, detail::YamlReader::Header::Optional);
  if (const auto model = yaml.optionalString("camera_model"); model && *model != "pinhole") {
    throw yaml.error("camera_model", "only pinhole is supported, found \"" + *model + "\"");
  }
  const auto model = yaml.optionalString("distortion_model");
  const bool equidistant = model && (*model == "equidistant" || *model == "fisheye" || *model == "kannala-brandt");
  if (model && !equidistant && *model != "radial-tangential" && *model != "radtan") {
    throw yaml.error("distortion_model", "expected radial-tangential or equidistant (Kannala-Brandt), found \"" +
                                             *model + "\"");
  }
  const std::vector<double> k = yaml.reals("intrinsics", 4, 4);
  const std::vector<double> d = yaml.reals("distortion_coefficients", 4, equidistant ? 4 : 5);
  const std::vector<double> resolution = yaml.reals("resolution", 2, 2);
  if (!(k[0] > 0 && k[1] > 0)) throw yaml.error("intrinsics", "focal lengths fu, fv must be positive");
  if (!(resolution[0] >= 1 && resolution[1] >= 1 && resolution[0] <= 1e5 && resolution[1] <= 1e5 &&
        resolution[0] == std::floor(resolution[0]) && resolution[1] == std::floor(resolution[1])))
    throw yaml.error("resolution", "expected a whole positive width and height");

  CameraCalibration c;
  c.intrinsics = {k[0], k[1], k[2], k[3], static_cast<int>(resolution[0]), static_cast<int>(resolution[1])};
  if (equidistant) c.fisheye = std::array<double, 4>{d[0], d[1], d[2], d[3]};
  else c.distortion = {d[0], d[1], d[2], d[3], d.size() == 5 ? d[4] : 0.0};
  c.bodyFromCamera = yaml.matrix("T_BS", 4, 4);
  const Eigen::Matrix3d R = c.bodyFromCamera.topLeftCorner<3, 3>();
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0 ||
      !c.bodyFromCamera.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1))) {
    throw yaml.error("T_BS", "expected a rigid transform (orthonormal rotation, last row 0 0 0 1)");
  }
  return c;
}

}  // namespace orbis
