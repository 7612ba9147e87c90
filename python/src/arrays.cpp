// python/src/arrays.cpp — NumPy <-> cv::Mat, poses and trajectories (contract in arrays.hpp).
#include "arrays.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "errors.hpp"
#include "orbis/util/error.hpp"

namespace orbis::python {
namespace {

std::string typeName(const py::handle& value) { return py::str(py::type::of(value).attr("__name__")); }

std::string describe(const py::array& a) {
  std::string shape = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
  if (a.ndim() == 1) shape += ",";
  return std::string(py::str(a.dtype())) + " array of shape " + shape + ")";
}

py::array requireArray(const py::handle& value, const char* argument) {
  if (!py::isinstance<py::array>(value))
    throw py::type_error(std::string(argument) + ": expected a numpy.ndarray, got " + typeName(value));
  return py::reinterpret_borrow<py::array>(value);
}

// Rows of `a` that cv::Mat can describe in place: each row's pixels contiguous, a positive row
// stride that is a whole number of elements.
bool rowsViewable(const py::array& a, py::ssize_t channels) {
  const py::ssize_t item = a.itemsize();
  if (a.ndim() == 3 && a.strides(2) != item) return false;
  if (a.strides(1) != item * channels) return false;
  return a.strides(0) >= a.shape(1) * item * channels && a.strides(0) % item == 0;
}

// A cv::Mat over `a` (2-D, or 3-D with the channels last), copying into C order only when the
// layout forces it. dtype must already have been checked; `cvDepth` is its OpenCV depth.
template <class T>
ImageView viewOf(const py::array& a, int cvDepth, const char* argument) {
  const py::ssize_t channels = a.ndim() == 3 ? a.shape(2) : 1;
  if (a.shape(0) == 0 || a.shape(1) == 0) throw py::value_error(std::string(argument) + ": empty " + describe(a));
  constexpr py::ssize_t kMaxSide = std::numeric_limits<int>::max() / 8;
  if (a.shape(0) > kMaxSide || a.shape(1) > kMaxSide)
    throw py::value_error(std::string(argument) + ": too large, " + describe(a));
  py::array source = a;
  if (!rowsViewable(a, channels)) source = py::array_t<T, py::array::c_style>::ensure(a);
  if (!source) throw py::error_already_set();
  cv::Mat mat(static_cast<int>(source.shape(0)), static_cast<int>(source.shape(1)),
              CV_MAKETYPE(cvDepth, static_cast<int>(channels)), const_cast<void*>(source.data()),
              static_cast<std::size_t>(source.strides(0)));
  return {mat, source};
}

py::dtype dtypeOfDepth(int depth) {
  switch (depth) {
    case CV_8U: return py::dtype::of<std::uint8_t>();
    case CV_16U: return py::dtype::of<std::uint16_t>();
    case CV_16S: return py::dtype::of<std::int16_t>();
    case CV_32S: return py::dtype::of<std::int32_t>();
    case CV_32F: return py::dtype::of<float>();
    case CV_64F: return py::dtype::of<double>();
    default: throw Error("image", "", "unsupported OpenCV depth " + std::to_string(depth));
  }
}

bool isPath(const py::handle& value) {
  return py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__");
}

}  // namespace

ImageView imageView(const py::handle& value, const char* argument) {
  const py::array a = requireArray(value, argument);
  if (!py::isinstance<py::array_t<std::uint8_t>>(a))
    throw py::type_error(std::string(argument) + ": expected dtype uint8 (grey H x W or BGR H x W x 3), got " +
                         describe(a));
  const bool grey = a.ndim() == 2, colour = a.ndim() == 3 && (a.shape(2) == 3 || a.shape(2) == 4);
  if (!grey && !colour)
    throw py::value_error(std::string(argument) + ": expected shape (H, W) or (H, W, 3), got " + describe(a));
  return viewOf<std::uint8_t>(a, CV_8U, argument);
}

ImageView depthView(const py::handle& value, const char* argument) {
  const py::array a = requireArray(value, argument);
  const bool raw = py::isinstance<py::array_t<std::uint16_t>>(a), metres = py::isinstance<py::array_t<float>>(a);
  if (!raw && !metres)
    throw py::type_error(std::string(argument) + ": expected dtype uint16 (raw) or float32 (metres), got " +
                         describe(a));
  if (a.ndim() != 2) throw py::value_error(std::string(argument) + ": expected shape (H, W), got " + describe(a));
  return raw ? viewOf<std::uint16_t>(a, CV_16U, argument) : viewOf<float>(a, CV_32F, argument);
}

ImageView descriptorView(const py::handle& value, const char* argument) {
  const py::array a = requireArray(value, argument);
  if (!py::isinstance<py::array_t<std::uint8_t>>(a))
    throw py::type_error(std::string(argument) + ": expected dtype uint8 descriptors, got " + describe(a));
  if (a.ndim() != 2 || a.shape(1) != 32)
    throw py::value_error(std::string(argument) + ": expected shape (N, 32), got " + describe(a));
  if (a.shape(0) == 0) return {cv::Mat(0, 32, CV_8U), a};
  return viewOf<std::uint8_t>(a, CV_8U, argument);
}

py::object matToArray(const cv::Mat& mat) {
  if (mat.empty()) return py::none();
  auto* shared = new cv::Mat(mat);  // one more reference to the same pixels, owned by the capsule
  py::capsule owner(shared, [](void* p) { delete static_cast<cv::Mat*>(p); });
  const auto element = static_cast<py::ssize_t>(mat.elemSize()), channel = static_cast<py::ssize_t>(mat.elemSize1());
  std::vector<py::ssize_t> shape{mat.rows, mat.cols}, strides{static_cast<py::ssize_t>(mat.step[0]), element};
  if (mat.channels() > 1) {
    shape.push_back(mat.channels());
    strides.push_back(channel);
  }
  return py::array(dtypeOfDepth(mat.depth()), shape, strides, shared->data, owner);
}

py::array_t<double> poseToArray(const SE3d& pose) {
  py::array_t<double> out({4, 4});
  auto m = out.mutable_unchecked<2>();
  const Eigen::Matrix4d matrix = pose.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = matrix(r, c);
  return out;
}

py::array_t<double> trajectoryToArray(const Trajectory& trajectory) {
  py::array_t<double> out({static_cast<py::ssize_t>(trajectory.size()), py::ssize_t{8}});
  auto rows = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const auto r = static_cast<py::ssize_t>(i);
    const SE3d& pose = trajectory[i].pose;
    const Eigen::Quaterniond& q = pose.unitQuaternion();
    const double values[8] = {trajectory[i].t, pose.translation().x(), pose.translation().y(), pose.translation().z(),
                              q.x(), q.y(), q.z(), q.w()};
    for (py::ssize_t c = 0; c < 8; ++c) rows(r, c) = values[c];
  }
  return out;
}

Trajectory trajectoryFromArray(const py::handle& value, const char* argument) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a) throw py::type_error(std::string(argument) + ": expected a path or an N x 8 numeric array");
  if (a.ndim() != 2 || a.shape(1) != 8)
    throw py::value_error(std::string(argument) + ": expected shape (N, 8) of rows t x y z qx qy qz qw, got " +
                          describe(a));
  Trajectory trajectory;
  auto rows = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    const std::string row = std::string(argument) + ", row " + std::to_string(i) + ": ";
    for (py::ssize_t c = 0; c < 8; ++c)
      if (!std::isfinite(rows(i, c))) throw py::value_error(row + "not finite");
    Eigen::Quaterniond q(rows(i, 7), rows(i, 4), rows(i, 5), rows(i, 6));
    if (q.norm() < 1e-12) throw py::value_error(row + "zero quaternion");
    if (!trajectory.empty() && !(rows(i, 0) > trajectory.back().t))
      throw py::value_error(row + "timestamp does not increase");
    q.normalize();
    trajectory.push_back({rows(i, 0), SE3d(q, Eigen::Vector3d(rows(i, 1), rows(i, 2), rows(i, 3)))});
  }
  return trajectory;
}

Trajectory trajectoryArgument(const py::handle& value, const char* argument, const std::string& format,
                              const std::string& kittiTimes) {
  if (!isPath(value)) return trajectoryFromArray(value, argument);
  const std::filesystem::path file = py::str(py::module_::import("os").attr("fspath")(value)).cast<std::string>();
  requireFile(file);
  if (!kittiTimes.empty()) requireFile(kittiTimes);
  const TrajectoryFormat f = format.empty() ? detectTrajectoryFormat(file) : parseTrajectoryFormat(format, "format");
  return readTrajectory(file, f, kittiTimes);
}

py::array_t<double> vectorToArray(const std::vector<double>& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

}  // namespace orbis::python
