#include "arrays.h"

#include <cmath>
#include <cstring>
#include <sstream>

#include "core/error.h"
#include "core/pose.h"

namespace ecv::python {
namespace {

// "float64 array of shape (480, 640)", for messages.
std::string Describe(const py::array& array) {
  std::ostringstream text;
  text << py::str(array.dtype()).cast<std::string>() << " array of shape (";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) text << (i > 0 ? ", " : "") << array.shape(i);
  text << (array.ndim() == 1 ? ",)" : ")");
  return text.str();
}

// `object` as an array of doubles (lists and integer arrays converted), or an InputError naming it.
py::array_t<double> DoubleArray(const py::object& object, const std::string& name, const std::string& expected) {
  py::array_t<double, py::array::c_style | py::array::forcecast> array;
  try {
    array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  } catch (const py::error_already_set&) {
  }
  if (!array) ThrowInputError(name, "", expected, py::str(py::type::of(object)).cast<std::string>());
  return array;
}

// The array's pixels as an image of `type` (HxW, or HxWxC for C channels): a view of its memory where its pixels are
// packed (any row stride, a crop of a wider image say), else one packed copy (a reversed axis, every other column).
cv::Mat PixelsOf(const py::array& array, int type) {
  const int rows = static_cast<int>(array.shape(0)), cols = static_cast<int>(array.shape(1));
  const auto pixel = static_cast<py::ssize_t>(CV_ELEM_SIZE(type)), item = static_cast<py::ssize_t>(CV_ELEM_SIZE1(type));
  const int channels = CV_MAT_CN(type);
  const bool packed =
      array.strides(1) == pixel && (channels == 1 || array.strides(2) == item) && array.strides(0) >= pixel * cols;
  if (packed) return cv::Mat(rows, cols, type, const_cast<void*>(array.data()), static_cast<size_t>(array.strides(0)));
  cv::Mat copy(rows, cols, type);
  const char* base = static_cast<const char*>(array.data());
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      for (int c = 0; c < channels; ++c) {
        const char* from =
            base + v * array.strides(0) + u * array.strides(1) + (channels > 1 ? c * array.strides(2) : 0);
        std::memcpy(copy.ptr(v) + u * pixel + c * item, from, static_cast<size_t>(item));
      }
    }
  }
  return copy;
}

}  // namespace

cv::Mat ColorImage(const py::array& array, const std::string& name) {
  constexpr const char* kExpected = "an HxWx3 uint8 array (RGB)";
  if (!py::isinstance<py::array_t<uint8_t>>(array) || array.ndim() != 3 || array.shape(2) != 3 || array.size() == 0) {
    ThrowInputError(name, "", kExpected, Describe(array));
  }
  return PixelsOf(array, CV_8UC3);
}

cv::Mat DepthImage(const py::array& array, const py::object& depth_scale, const std::string& name) {
  const bool metres = py::isinstance<py::array_t<float>>(array);
  const bool units = py::isinstance<py::array_t<uint16_t>>(array);
  if (!(metres || units) || array.ndim() != 2 || array.size() == 0) {
    ThrowInputError(name, "", "an HxW float32 array in metres, or uint16 with depth_scale", Describe(array));
  }
  if (metres && !depth_scale.is_none()) {
    ThrowInputError("depth_scale", "", "None with float32 depth in metres (it is for uint16 depth)",
                    py::str(depth_scale).cast<std::string>());
  }
  const cv::Mat pixels = PixelsOf(array, metres ? CV_32FC1 : CV_16UC1);
  if (metres) return pixels;
  double scale = 0.0;
  try {
    scale = depth_scale.is_none() ? 0.0 : depth_scale.cast<double>();
  } catch (const py::cast_error&) {
    scale = std::nan("");
  }
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    ThrowInputError("depth_scale", "", "a finite number > 0 (depth units per metre) with uint16 depth",
                    py::str(depth_scale).cast<std::string>());
  }
  cv::Mat depth;
  pixels.convertTo(depth, CV_32FC1, 1.0 / scale);
  return depth;
}

PinholeCamera CameraFromK(const py::object& k, int width, int height, const std::string& name) {
  constexpr const char* kExpected = "a 3x3 intrinsic matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]";
  const py::array_t<double> array = DoubleArray(k, name, kExpected);
  if (array.ndim() != 2 || array.shape(0) != 3 || array.shape(1) != 3) {
    ThrowInputError(name, "shape", kExpected, Describe(array));
  }
  const auto m = array.unchecked<2>();
  for (py::ssize_t r = 0; r < 3; ++r) {
    for (py::ssize_t c = 0; c < 3; ++c) {
      if (!std::isfinite(m(r, c))) ThrowInputError(name, "entries", "finite numbers", std::to_string(m(r, c)));
    }
  }
  if (m(0, 1) != 0.0 || m(1, 0) != 0.0 || m(2, 0) != 0.0 || m(2, 1) != 0.0 || m(2, 2) != 1.0) {
    ThrowInputError(name, "entries", std::string(kExpected) + " (no skew)", "other entries");
  }
  PinholeCamera camera;
  camera.fx = m(0, 0), camera.fy = m(1, 1), camera.cx = m(0, 2), camera.cy = m(1, 2);
  camera.width = width, camera.height = height;
  camera.Check(name);
  return camera;
}

Eigen::Isometry3d PoseFromArray(const py::object& pose, const std::string& name) {
  const py::array_t<double> array = DoubleArray(pose, name, "a 4x4 rigid transform");
  if (array.ndim() != 2 || array.shape(0) != 4 || array.shape(1) != 4) {
    ThrowInputError(name, "shape", "a 4x4 rigid transform", Describe(array));
  }
  Eigen::Matrix4d matrix;
  const auto m = array.unchecked<2>();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) matrix(r, c) = m(r, c);
  }
  return RigidFromMatrix(matrix, name, "value");
}

py::array_t<double> KArray(const PinholeCamera& camera) {
  py::array_t<double> k({3, 3});
  auto m = k.mutable_unchecked<2>();
  const Eigen::Matrix3d matrix = camera.K();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = matrix(r, c);
  }
  return k;
}

py::array_t<double> PoseArray(const Eigen::Isometry3d& pose) {
  py::array_t<double> array({4, 4});
  auto m = array.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = pose.matrix()(r, c);
  }
  return array;
}

py::array ImageArray(const cv::Mat& image) {
  auto* owner = new cv::Mat(image);  // shares the pixels; the capsule releases them with the array
  const py::capsule release(owner, [](void* mat) { delete static_cast<cv::Mat*>(mat); });
  const auto rows = static_cast<py::ssize_t>(image.rows), cols = static_cast<py::ssize_t>(image.cols);
  const auto step = static_cast<py::ssize_t>(image.step[0]);
  if (image.type() == CV_8UC3) {
    return py::array_t<uint8_t>({rows, cols, py::ssize_t{3}}, {step, py::ssize_t{3}, py::ssize_t{1}}, image.data,
                                release);
  }
  return py::array_t<float>({rows, cols}, {step, py::ssize_t{sizeof(float)}},
                            reinterpret_cast<const float*>(image.data), release);
}

}  // namespace ecv::python
