// python/src/arrays.hpp — NumPy arrays to and from the library's types.
//
// Contract: images come in as views, not copies, whenever their rows are laid out the way
// cv::Mat can describe (pixels of a row contiguous, any positive row stride); anything else
// (negative or interleaved strides) is copied once into a C-contiguous array that the returned
// ImageView keeps alive. An argument of the wrong kind or dtype raises TypeError, one of the
// wrong shape ValueError, naming the argument; nothing here can crash on user input. Arrays
// handed back to Python own their memory or share it with a cv::Mat through a capsule.
// Trajectories cross as N x 8 float64 arrays of TUM rows (t, x, y, z, qx, qy, qz, qw),
// camera-to-world; poses as 4 x 4 float64 matrices.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <opencv2/core.hpp>
#include <vector>

#include "orbis/io/trajectory.hpp"

namespace orbis::python {

namespace py = pybind11;

// A cv::Mat over a NumPy array's memory; `owner` keeps that memory alive as long as the view.
struct ImageView {
  cv::Mat mat;
  py::object owner;
};

// uint8 H x W (grey) or H x W x 3 (BGR) / H x W x 4 (BGRA).
ImageView imageView(const py::handle& array, const char* argument);
// uint16 H x W (raw, divided by the camera's depth scale) or float32 H x W (metres).
ImageView depthView(const py::handle& array, const char* argument);
// uint8 N x 32 (ORB descriptors, one per row).
ImageView descriptorView(const py::handle& array, const char* argument);

// A NumPy array sharing the cv::Mat's memory (None when the Mat is empty).
py::object matToArray(const cv::Mat& mat);

py::array_t<double> poseToArray(const SE3d& pose);

py::array_t<double> trajectoryToArray(const Trajectory& trajectory);
Trajectory trajectoryFromArray(const py::handle& rows, const char* argument);
// A path (str or os.PathLike: read with the library's reader, format detected or given) or an
// N x 8 array.
Trajectory trajectoryArgument(const py::handle& value, const char* argument, const std::string& format = "",
                              const std::string& kittiTimes = "");

py::array_t<double> vectorToArray(const std::vector<double>& values);

}  // namespace orbis::python
