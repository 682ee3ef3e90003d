#pragma once

// Between numpy arrays and the images, cameras and poses of the ecvpose libraries: without a copy where the array's
// layout allows, with an InputError naming the argument where it does not fit.

#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.h"

namespace ecv::python {

namespace py = pybind11;

/// An HxWx3 uint8 RGB array as a CV_8UC3 image. Shares the array's memory when its pixels are packed (any row
/// stride), else copies it.
cv::Mat ColorImage(const py::array& array, const std::string& name);

/// A depth array as CV_32FC1 metres: float32 metres (shared when its pixels are packed), or uint16 with `depth_scale`
/// (metres = value / depth_scale; converted). `depth_scale` is refused with float32 and required with uint16.
cv::Mat DepthImage(const py::array& array, const py::object& depth_scale, const std::string& name);

/// A 3x3 intrinsic matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] with finite positive focal lengths, for images of
/// `width` x `height`.
PinholeCamera CameraFromK(const py::object& k, int width, int height, const std::string& name);

/// A rigid transform as a 4x4 array: last row 0 0 0 1, rotation orthonormal up to rounding (RigidFromMatrix).
Eigen::Isometry3d PoseFromArray(const py::object& pose, const std::string& name);

/// The camera's K as a 3x3 float64 array.
py::array_t<double> KArray(const PinholeCamera& camera);

/// A pose as a 4x4 float64 array (a copy).
py::array_t<double> PoseArray(const Eigen::Isometry3d& pose);

/// A numpy view of `image` (CV_8UC3 as HxWx3 uint8, CV_32FC1 as HxW float32), which keeps the image's pixels alive.
py::array ImageArray(const cv::Mat& image);

}  // namespace ecv::python
