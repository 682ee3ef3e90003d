// The Python module's open_camera: frames of an OpenNI2 camera or an .oni recording, as Frame objects.

#include <memory>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "arrays.h"
#include "bindings.h"
#include "camera/openni_camera.h"
#include "core/error.h"

namespace ecv::python {
namespace {

// fx, fy, cx, cy of a 3x3 K given as any array-like.
std::array<double, 4> Intrinsics(const py::object& k) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(k);
  if (!array || array.ndim() != 2 || array.shape(0) != 3 || array.shape(1) != 3) {
    ThrowInputError("open_camera", "K", "a 3x3 intrinsic matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]");
  }
  const auto m = array.unchecked<2>();
  return {m(0, 0), m(1, 1), m(0, 2), m(1, 2)};
}

std::unique_ptr<OpenNiCamera> OpenCamera(const std::string& source, const py::object& k, double timeout) {
  CameraOptions options;
  options.source = source;
  options.frame_timeout_s = timeout;
  if (!k.is_none()) options.intrinsics = Intrinsics(k);
  py::gil_scoped_release release;
  return std::make_unique<OpenNiCamera>(options);
}

std::optional<LoadedFrame> NextFrame(OpenNiCamera& camera) {
  py::gil_scoped_release release;
  return camera.Next();
}

}  // namespace

void BindCamera(py::module_& m) {
  py::class_<OpenNiCamera>(m, "Camera",
                           "An OpenNI2 camera or .oni recording; iterating yields Frame objects (a recording ends, "
                           "a camera goes on).")
      .def("__iter__", [](OpenNiCamera& camera) -> OpenNiCamera& { return camera; })
      .def("__next__",
           [](OpenNiCamera& camera) {
             std::optional<LoadedFrame> frame = NextFrame(camera);
             if (!frame) throw py::stop_iteration();
             return *frame;
           })
      .def_property_readonly(
          "K", [](const OpenNiCamera& camera) { return KArray(camera.camera()); }, "3x3 float64, the colour camera's")
      .def_property_readonly("intrinsics_source", &OpenNiCamera::intrinsics_source,
                             "Where K came from: \"given\" (the K argument), FILE.oni.json, or \"fields of view\" "
                             "(principal point at the image centre)")
      .def_property_readonly("num_frames", &OpenNiCamera::num_frames, "Frames of a recording; -1 for a camera");
  m.def("open_camera", &OpenCamera, py::arg("source"), py::kw_only(), py::arg("K") = py::none(),
        py::arg("timeout") = 5.0,
        "Opens \"openni2://\" (the first device), \"openni2://URI\" or a FILE.oni recording: frames with colour "
        "(RGB), depth registered to it (metres) and K: the given one, else FILE.oni.json beside a recording, else "
        "from the fields of view. timeout: seconds to wait for a frame. No device, a bad URI or a broken file raise "
        "InputError naming it.");
}

}  // namespace ecv::python
