// The Python module's Frame, load_frame, Detection and Recognizer.

#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <variant>

#include <pybind11/stl.h>

#include "arrays.h"
#include "bindings.h"
#include "core/error.h"
#include "io/frame_io.h"
#include "library.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"
#include "recognize/recognizer_settings.h"

namespace ecv::python {
namespace {

// A Recognizer with its library and its stream of frames: one call at a time (the renderer is not shared).
class StreamRecognizer {
 public:
  // With search_beside, the recognizer tracks on its share of the threads, and the stream's searcher, on its own
  // thread, takes the rest (ShareThreads).
  StreamRecognizer(std::shared_ptr<Library> library, const RecognizerSettings& settings)
      : library_(std::move(library)),
        settings_(settings),
        threads_(ShareThreads(settings.options, settings.stream)),
        recognizer_(library_->library(), threads_.track),
        stream_(recognizer_, settings.stream, MakeRecognizerFactory(library_->library(), threads_.search)) {}

  RecognitionResult Recognize(const RgbdFrame& frame) {
    const std::lock_guard<std::mutex> lock(mutex_);
    RecognitionResult result = stream_.Next(frame);
    last_timings_ms_ = result.timings_ms;
    last_searched_frames_ago_ = result.searched_frames_ago;
    return result;
  }

  // BOP's localisation task on one frame (Recognizer::RecognizeTargets); the stream's tracks are left as they are.
  RecognitionResult RecognizeTargets(const RgbdFrame& frame, const std::map<std::string, int>& targets) {
    const std::lock_guard<std::mutex> lock(mutex_);
    RecognitionResult result = recognizer_.RecognizeTargets(frame, targets);
    last_timings_ms_ = result.timings_ms;
    return result;
  }

  void Reset() {
    const std::lock_guard<std::mutex> lock(mutex_);
    stream_.Reset();
  }

  std::map<std::string, double> last_timings_ms() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return last_timings_ms_;
  }

  std::optional<int> last_searched_frames_ago() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (last_searched_frames_ago_ < 0) return std::nullopt;
    return last_searched_frames_ago_;
  }

  cv::Mat Draw(const RgbdFrame& frame, const std::vector<Detection>& detections) {
    const std::lock_guard<std::mutex> lock(mutex_);
    return recognizer_.DrawDetections(frame, detections);
  }

  std::vector<std::string> PointPairWarnings() const { return recognizer_.PointPairWarnings(); }

  const RecognizerSettings& settings() const { return settings_; }

 private:
  std::shared_ptr<Library> library_;  // the recognizer reads it
  RecognizerSettings settings_;
  StreamRecognizerOptions threads_;  // the tracker's and the searcher's options, the threads shared out
  Recognizer recognizer_;
  RecognitionStream stream_;
  std::mutex mutex_;
  std::map<std::string, double> last_timings_ms_;
  int last_searched_frames_ago_ = -1;
};

// The Python Recognizer's default thread count (the CLI's: every core); the other defaults are the table's.
constexpr int kPythonThreads = 2;

std::unique_ptr<StreamRecognizer> MakeRecognizer(std::shared_ptr<Library> library, const RecognizerSettings& settings) {
  CheckSettings(settings);
  RequireModels(library->library(), library->path());
  py::gil_scoped_release release;  // the meshes are loaded and uploaded: about a second
  return std::make_unique<StreamRecognizer>(std::move(library), settings);
}

template <typename T>
T Cast(const std::string& key, const py::handle& value, const char* expected) {
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    ThrowInputError(key, "", expected, py::repr(value).cast<std::string>());
  }
}

// One keyword argument of Recognizer: the setting of the table with that keyword (the recognize flag with
// underscores), checked by the table.
void SetKeyword(const std::string& key, const py::handle& value, RecognizerSettings* settings) {
  const Setting* setting = FindSetting(key);
  if (setting == nullptr || setting->Keyword() != key) {
    ThrowInputError("Recognizer", key, "a keyword of the recognize flags (see help(ecvpose.Recognizer))",
                    "an unknown keyword");
  }
  SettingValue typed;
  switch (setting->type) {
    case SettingType::kCount: typed = Cast<int64_t>(key, value, "a whole number"); break;
    case SettingType::kNumber: typed = Cast<double>(key, value, "a number"); break;
    case SettingType::kFlag: typed = Cast<bool>(key, value, "True or False"); break;
    case SettingType::kChoice: typed = Cast<std::string>(key, value, "a string"); break;
  }
  setting->Set(typed, key, settings);
}

// The settings as keyword -> value (what Recognizer.settings shows).
py::dict SettingsDict(const RecognizerSettings& settings) {
  py::dict values;
  for (const Setting& setting : RecognizerSettingTable()) {
    std::visit([&](const auto& value) { values[py::str(setting.Keyword())] = value; }, setting.get(settings));
  }
  return values;
}

// help(ecvpose.Recognizer): the keywords with their defaults and help, from the table.
std::string RecognizerDoc() {
  RecognizerSettings defaults;
  defaults.options.threads = kPythonThreads;
  std::ostringstream doc;
  doc << kRecognizerDoc
      << "\n\nKeywords (the flags of `ecvpose recognize` with underscores; default, then what it "
         "does):\n";
  for (const Setting& setting : RecognizerSettingTable()) {
    std::string help = setting.help;
    std::replace(help.begin(), help.end(), '\n', ' ');
    const SettingValue value = setting.get(defaults);
    doc << setting.Keyword() << '=';
    if (setting.type == SettingType::kFlag) {
      doc << (std::get<bool>(value) ? "True" : "False") << (setting.negated ? " (False: " : " (True: ");
    } else if (setting.type == SettingType::kChoice) {
      doc << '"' << setting.Format(value) << "\" (" << setting.Expected() << "): ";
    } else {
      doc << setting.Format(value) << " (" << setting.Expected() << "): ";
    }
    doc << help << (setting.type == SettingType::kFlag ? ")" : "") << "\n";
  }
  return doc.str();
}

py::list DetectionList(const RecognitionResult& result) {
  py::list detections;
  for (const Detection& detection : result.detections) detections.append(detection);
  return detections;
}

// A frame of the caller's arrays, checked; `name` (the method) leads the messages about it.
RgbdFrame FrameFromArrays(const py::array& color, const py::array& depth, const py::object& k,
                          const py::object& depth_scale, const std::string& name) {
  RgbdFrame frame;
  frame.name = name;
  frame.color = ColorImage(color, "color");
  frame.depth = DepthImage(depth, depth_scale, "depth");
  frame.camera = CameraFromK(k, frame.color.cols, frame.color.rows, "K");
  py::gil_scoped_release release;
  frame.Check();
  return frame;
}

py::list RecognizeArrays(StreamRecognizer& recognizer, const py::array& color, const py::array& depth,
                         const py::object& k, const py::object& depth_scale) {
  const RgbdFrame frame = FrameFromArrays(color, depth, k, depth_scale, "Recognizer.recognize");
  RecognitionResult result;
  {
    py::gil_scoped_release release;
    result = recognizer.Recognize(frame);
  }
  return DetectionList(result);
}

py::list GroundTruthList(const LoadedFrame& frame) {
  py::list truth;
  for (const GroundTruth& object : frame.ground_truth) {
    truth.append(py::make_tuple(object.object_name, PoseArray(object.camera_from_object)));
  }
  return truth;
}

LoadedFrame LoadFrameSpec(const std::optional<std::string>& spec, const std::optional<std::string>& color,
                          const std::optional<std::string>& depth, std::optional<double> depth_scale,
                          const std::optional<std::string>& camera) {
  FrameSpec frame;
  frame.positional = spec.value_or("");
  frame.color_path = color.value_or("");
  frame.depth_path = depth.value_or("");
  frame.depth_scale = depth_scale;
  frame.camera = camera;
  if (frame.positional.empty() && (frame.color_path.empty() || frame.depth_path.empty())) {
    ThrowInputError("load_frame", "spec",
                    "a FRAME (frame JSON, YCB-Video prefix, BOP SCENE_DIR:IMAGE_ID or .pcd), "
                    "or color= and depth= (with depth_scale= and camera=)");
  }
  py::gil_scoped_release release;
  return LoadFrame(frame);
}

void BindDetection(py::module_& m) {
  py::class_<Detection>(m, "Detection", "One recognised object.")
      .def_readonly("model", &Detection::model)
      .def_readonly("score", &Detection::score, "0..1, higher is surer")
      .def_property_readonly(
          "camera_from_object", [](const Detection& d) { return PoseArray(d.camera_from_object); },
          "4x4 float64: x_camera = R x_object + t, metres")
      .def_readonly("inlier_fraction", &Detection::inlier_fraction)
      .def_readonly("fit_error_m", &Detection::fit_error_m)
      .def_readonly("view", &Detection::view)
      .def_readonly("depth_agreement", &Detection::depth_agreement)
      .def_readonly("color_agreement", &Detection::color_agreement)
      .def_readonly("surface_error_m", &Detection::surface_error_m)
      .def_readonly("contour_agreement", &Detection::contour_agreement)
      .def_readonly("continuation", &Detection::continuation)
      .def_readonly("visible_fraction", &Detection::visible_fraction)
      .def_readonly("edge_agreement", &Detection::edge_agreement)
      .def_readonly("edge_pixels", &Detection::edge_pixels)
      .def_readonly("explained_surface", &Detection::explained_surface)
      .def_readonly("free_space_violation", &Detection::free_space_violation)
      .def_readonly("occluding_contour", &Detection::occluding_contour)
      .def_readonly("creased_contour", &Detection::creased_contour)
      .def_readonly("acceptance", &Detection::acceptance,
                    "the learned acceptance's probability that it is right (-1: not used)")
      .def_readonly("tracked", &Detection::tracked)
      .def_readonly("accepted", &Detection::accepted,
                    "False for a target's best pose that the acceptance rejected (recognize_targets)")
      .def_readonly("frames_followed", &Detection::frames_followed)
      .def_readonly("confirmed", &Detection::confirmed)
      .def_property_readonly("hypothesis", [](const Detection& d) { return HypothesisSourceName(d.hypothesis_source); })
      .def("__repr__", [](const Detection& d) {
        const Eigen::Vector3d t = d.camera_from_object.translation();
        return "<ecvpose.Detection " + d.model + " score " + std::to_string(d.score) + " at (" + std::to_string(t.x()) +
               ", " + std::to_string(t.y()) + ", " + std::to_string(t.z()) + ") m" + (d.tracked ? ", tracked>" : ">");
      });
}

void BindFrame(py::module_& m) {
  py::class_<LoadedFrame>(m, "Frame", "An RGB-D frame read from files, with its ground truth if it has one.")
      .def_property_readonly(
          "color", [](const LoadedFrame& f) { return ImageArray(f.rgbd.color); }, "HxWx3 uint8, RGB")
      .def_property_readonly(
          "depth", [](const LoadedFrame& f) { return ImageArray(f.rgbd.depth); },
          "HxW float32, metres, 0 where missing")
      .def_property_readonly(
          "K", [](const LoadedFrame& f) { return KArray(f.rgbd.camera); }, "3x3 float64")
      .def_property_readonly("name", [](const LoadedFrame& f) { return f.rgbd.name; })
      .def_property_readonly("ground_truth", &GroundTruthList, "[(model, camera_from_object 4x4)]")
      .def("__repr__", [](const LoadedFrame& f) {
        return "<ecvpose.Frame " + f.rgbd.name + ", " + std::to_string(f.rgbd.color.cols) + "x" +
               std::to_string(f.rgbd.color.rows) + ">";
      });

  m.def("load_frame", &LoadFrameSpec, py::arg("spec") = py::none(), py::kw_only(), py::arg("color") = py::none(),
        py::arg("depth") = py::none(), py::arg("depth_scale") = py::none(), py::arg("camera") = py::none(),
        "Reads a frame as the CLI names it: `spec` a frame JSON, a YCB-Video prefix (.../0001/000001), a BOP "
        "image SCENE_DIR:IMAGE_ID or an organized .pcd; or color= and depth= (16-bit PNG) with depth_scale= (units "
        "per metre) and camera= (\"fx,fy,cx,cy\").");
  m.def("list_frames", &ListSequenceFrames, py::arg("sequence"), py::call_guard<py::gil_scoped_release>(),
        "The frames of a sequence in order, each a spec for load_frame: a BOP scene folder, a YCB-Video video folder, "
        "a folder of frame JSONs, or a text file with one FRAME per line.");
  m.def(
      "write_image",
      [](const std::string& path, const py::array& color) {
        const cv::Mat image = ColorImage(color, "color");
        py::gil_scoped_release release;
        WriteColorImage(path, image);
      },
      py::arg("path"), py::arg("color"), "Writes an HxWx3 uint8 RGB array as a PNG or JPG file.");
}

}  // namespace

void BindRecognizer(py::module_& m) {
  static const std::string doc = RecognizerDoc();  // pybind11 keeps the pointer
  BindDetection(m);
  BindFrame(m);
  py::class_<StreamRecognizer>(m, "Recognizer", "Finds a library's models in RGB-D frames.")
      .def(py::init([](std::shared_ptr<Library> library, const py::kwargs& options) {
             RecognizerSettings settings;
             settings.options.threads = kPythonThreads;
             for (const auto& [key, value] : options) SetKeyword(key.cast<std::string>(), value, &settings);
             return MakeRecognizer(std::move(library), settings);
           }),
           py::arg("library"), doc.c_str())
      .def("recognize", &RecognizeArrays, py::arg("color"), py::arg("depth"), py::arg("K"),
           py::arg("depth_scale") = py::none(),
           "Detections in one frame, best score first. color: HxWx3 uint8 RGB; depth: HxW float32 metres (0: "
           "missing), or uint16 with depth_scale (units per metre); K: 3x3 intrinsics. The arrays are read in "
           "place where their layout allows. With track=True, the frame continues the stream of earlier calls.")
      .def(
          "recognize_frame",
          [](StreamRecognizer& recognizer, const LoadedFrame& frame) {
            RecognitionResult result;
            {
              py::gil_scoped_release release;
              result = recognizer.Recognize(frame.rgbd);
            }
            return DetectionList(result);
          },
          py::arg("frame"), "recognize() on a Frame from load_frame.")
      .def(
          "recognize_targets",
          [](StreamRecognizer& recognizer, const LoadedFrame& frame, const std::map<std::string, int>& targets) {
            RecognitionResult result;
            {
              py::gil_scoped_release release;
              result = recognizer.RecognizeTargets(frame.rgbd, targets);
            }
            return DetectionList(result);
          },
          py::arg("frame"), py::arg("targets"),
          "BOP's localisation task on a Frame from load_frame: only the models of `targets` ({name: instances}) are "
          "looked for, each reporting up to that many poses, the best by score, without a threshold (a pose the "
          "acceptance rejected has accepted False).")
      .def(
          "draw",
          [](StreamRecognizer& recognizer, const py::array& color, const py::array& depth, const py::object& k,
             const std::vector<Detection>& detections, const py::object& depth_scale) {
            RgbdFrame frame = FrameFromArrays(color, depth, k, depth_scale, "Recognizer.draw");
            cv::Mat drawn;
            {
              py::gil_scoped_release release;
              drawn = recognizer.Draw(frame, detections);
            }
            return ImageArray(drawn);
          },
          py::arg("color"), py::arg("depth"), py::arg("K"), py::arg("detections"), py::arg("depth_scale") = py::none(),
          "A copy of `color` with each detection's model rendered at its pose in red, outlined, with its name and "
          "score; scene surfaces in front of a model (by `depth`) hide it.")
      .def("reset", &StreamRecognizer::Reset, py::call_guard<py::gil_scoped_release>(),
           "Forgets the tracks: the next frame searches every model (a new video).")
      .def_property_readonly("last_timings_ms", &StreamRecognizer::last_timings_ms,
                             "Time per stage of the last frame, milliseconds (\"total\": the whole call in C++).")
      .def_property_readonly("last_searched_frames_ago", &StreamRecognizer::last_searched_frames_ago,
                             "With search_beside: when a finished search's detections joined the last frame, how many "
                             "frames before it the searched frame came; else None.")
      .def_property_readonly(
          "settings", [](const StreamRecognizer& recognizer) { return SettingsDict(recognizer.settings()); },
          "The keywords' values this recognizer runs with, {keyword: value}.")
      .def_property_readonly("point_pair_warnings", &StreamRecognizer::PointPairWarnings,
                             "Models without a point pair table, and why (with hypotheses \"ppf\" or \"both\").");
}

}  // namespace ecv::python
