#include "camera/openni_camera.h"

#include <OpenNI.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/oni_check.h"
#include "core/error.h"
#include "io/atomic_file.h"
#include "io/image_bytes.h"

namespace ecv {
namespace {

constexpr const char* kScheme = "openni2://";

bool IsRecording(const std::string& source) {
  return source.size() > 4 && source.compare(source.size() - 4, 4, ".oni") == 0;
}

// What OpenNI2 said about its last failure, for messages.
std::string OpenNiError() {
  const std::string text = openni::OpenNI::getExtendedError();
  const size_t start = text.find_first_not_of(" \t\n");
  return start == std::string::npos ? "no reason given"
                                    : text.substr(start, text.find_last_not_of(" \t\n") - start + 1);
}

// The connected cameras, URI and name: OpenNI2's device list without the recordings this process has opened (its file
// driver lists each as a device while OpenNI2 runs).
std::vector<std::pair<std::string, std::string>> ConnectedCameras() {
  openni::Array<openni::DeviceInfo> devices;
  openni::OpenNI::enumerateDevices(&devices);
  std::vector<std::pair<std::string, std::string>> cameras;
  for (int i = 0; i < devices.getSize(); ++i) {
    const std::string uri = devices[i].getUri();
    if (!IsRecording(uri)) cameras.emplace_back(uri, devices[i].getName());
  }
  return cameras;
}

// The connected cameras for a message ("none" when there are none).
std::string ConnectedDevices() {
  std::string list;
  for (const auto& [uri, name] : ConnectedCameras()) {
    list += (list.empty() ? "" : ", ") + std::string(kScheme) + uri + " (" + name + ")";
  }
  return list.empty() ? "none" : list;
}

// Depth values per metre of a depth pixel format; 0 for a format that is no metric depth.
double DepthScaleOf(openni::PixelFormat format) {
  if (format == openni::PIXEL_FORMAT_DEPTH_1_MM) return 1000.0;
  if (format == openni::PIXEL_FORMAT_DEPTH_100_UM) return 10000.0;
  return 0.0;
}

// A frame's pixels as an image of `type` (a copy; OpenNI2 reuses its buffers).
cv::Mat FramePixels(const openni::VideoFrameRef& frame, int type, const std::string& source) {
  const int width = frame.getWidth(), height = frame.getHeight();
  const size_t row = static_cast<size_t>(width) * CV_ELEM_SIZE(type);
  if (width < 1 || height < 1 || frame.getStrideInBytes() < static_cast<int>(row) ||
      static_cast<size_t>(frame.getDataSize()) < static_cast<size_t>(frame.getStrideInBytes()) * (height - 1) + row) {
    ThrowInputError(source, "frame " + std::to_string(frame.getFrameIndex()),
                    std::to_string(width) + "x" + std::to_string(height) + " pixels of " +
                        std::to_string(CV_ELEM_SIZE(type)) + " bytes",
                    std::to_string(frame.getDataSize()) + " bytes");
  }
  return cv::Mat(height, width, type, const_cast<void*>(frame.getData()), frame.getStrideInBytes()).clone();
}

// OpenNI2 started once for the process and left running: its shutdown unloads the drivers (dlclose), which a later
// camera of the same process (Python opening a second one) loads again, and after which the sanitizers can no longer
// name the drivers' own allocations (tests/lsan.supp names them).
void InitializeOpenNi() {
  static const openni::Status status = openni::OpenNI::initialize();
  if (status != openni::STATUS_OK) {
    ThrowInputError("OpenNI2", "initialize", "a working OpenNI2 installation (libopenni2)", OpenNiError());
  }
}

}  // namespace

bool IsOpenNiSource(const std::string& source) {
  return source.rfind(kScheme, 0) == 0 || IsRecording(source);
}

std::string CalibrationPath(const std::string& recording) {
  return recording + ".json";
}

void WriteCalibration(const std::string& path, const RecordingCalibration& calibration) {
  const PinholeCamera& k = calibration.camera;
  const nlohmann::json json = {{"camera", {k.fx, k.fy, k.cx, k.cy}},
                               {"width", k.width},
                               {"height", k.height},
                               {"depth_scale", calibration.depth_scale}};
  WriteFileAtomically(path, json.dump(2) + "\n");
}

RecordingCalibration ReadCalibration(const std::string& path) {
  std::ifstream in(path);
  if (!in) ThrowInputError(path, "calibration", "a readable JSON file");
  const nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded() || !json.is_object()) ThrowInputError(path, "calibration", "a JSON object");
  const auto number = [&](const nlohmann::json& value, const std::string& field) {
    if (!value.is_number()) ThrowInputError(path, field, "a number");
    return value.get<double>();
  };
  const auto field = [&](const char* key) -> const nlohmann::json& {
    if (!json.contains(key)) ThrowInputError(path, key, "a value (fields: camera, width, height, depth_scale)");
    return json.at(key);
  };
  const nlohmann::json& camera = field("camera");
  if (!camera.is_array() || camera.size() != 4) ThrowInputError(path, "camera", "[fx, fy, cx, cy] in pixels");
  std::array<double, 4> k;
  for (size_t i = 0; i < 4; ++i) k[i] = number(camera[i], "camera");
  CheckIntrinsics(k, path, "camera");
  RecordingCalibration calibration;
  const auto pixels = [&](const char* key) {  // checked before the cast: a huge double does not fit an int
    const double value = number(field(key), key);
    if (!(value >= 1.0 && value <= 100000.0) || value != std::floor(value)) {
      ThrowInputError(path, key, "a whole number of pixels in [1, 100000]");
    }
    return static_cast<int>(value);
  };
  calibration.camera = {k[0], k[1], k[2], k[3], pixels("width"), pixels("height")};
  calibration.camera.Check(path);
  calibration.depth_scale = number(field("depth_scale"), "depth_scale");
  CheckDepthScale(calibration.depth_scale, path);
  return calibration;
}

void CameraOptions::Check() const {
  if (!IsOpenNiSource(source)) {
    ThrowInputError(source, "camera source", "openni2:// (the first device), openni2://URI or a FILE.oni recording");
  }
  if (!(frame_timeout_s > 0.0)) ThrowInputError(source, "frame timeout", "a positive number of seconds");
}

PinholeCamera CameraFromFieldsOfView(int width, int height, double horizontal_fov_rad, double vertical_fov_rad) {
  PinholeCamera camera;
  camera.fx = width / (2.0 * std::tan(horizontal_fov_rad / 2.0));
  camera.fy = height / (2.0 * std::tan(vertical_fov_rad / 2.0));
  camera.cx = (width - 1) / 2.0;
  camera.cy = (height - 1) / 2.0;
  camera.width = width;
  camera.height = height;
  return camera;
}

std::array<double, 2> FieldsOfView(const PinholeCamera& camera) {
  return {2.0 * std::atan(camera.width / (2.0 * camera.fx)), 2.0 * std::atan(camera.height / (2.0 * camera.fy))};
}

struct OpenNiCamera::Impl {
  CameraOptions options;
  bool recording = false;
  openni::Device device;
  openni::VideoStream depth, color;
  double depth_scale = 0.0;  // depth values per metre
  PinholeCamera camera;
  std::string intrinsics_source;
  int num_frames = -1;
  int frames_read = 0;

  ~Impl() {
    depth.stop();
    color.stop();
    depth.destroy();
    color.destroy();
    device.close();
  }

  void Open();
  void CreateStreams();
  void ChooseIntrinsics();
  openni::VideoFrameRef Read(openni::VideoStream& stream, const char* what);
  cv::Mat DepthInColorGeometry(const cv::Mat& depth_values, const cv::Size& color_size) const;
};

// Opens the device or the recording; no device, a bad URI or a broken file are InputErrors naming what was looked for.
void OpenNiCamera::Impl::Open() {
  const std::string& source = options.source;
  recording = IsRecording(source);
  if (recording) {
    if (!std::filesystem::is_regular_file(source)) ThrowInputError(source, "recording", "an existing .oni file");
    CheckOniFile(source);
  }
  InitializeOpenNi();
  std::string uri = recording ? source : source.substr(std::string(kScheme).size());
  const bool first_camera = uri.empty();
  if (first_camera) {
    const auto cameras = ConnectedCameras();
    if (cameras.empty()) {
      ThrowInputError(source, "device", "a connected OpenNI2 device (Kinect, Asus Xtion, Orbbec)",
                      "none connected (" + OpenNiError() + ")");
    }
    uri = cameras.front().first;
  }
  if (device.open(uri.c_str()) != openni::STATUS_OK) {
    const std::string reason = OpenNiError();
    if (recording) ThrowInputError(source, "recording", "a recording OpenNI2 can play", reason);
    ThrowInputError(source, "device",
                    first_camera ? "a connected OpenNI2 device (Kinect, Asus Xtion, Orbbec)"
                                 : "a connected OpenNI2 device with URI '" + uri + "'",
                    reason + "; connected devices: " + ConnectedDevices());
  }
  if (recording) {
    openni::PlaybackControl* playback = device.getPlaybackControl();
    playback->setRepeatEnabled(false);
    playback->setSpeed(-1.0f);  // manual: each frame is played when it is read, none dropped
  }
  CreateStreams();
  ChooseIntrinsics();
  if (depth.start() != openni::STATUS_OK || color.start() != openni::STATUS_OK) {
    ThrowInputError(source, "streams", "depth and colour streams that start", OpenNiError());
  }
}

void OpenNiCamera::Impl::CreateStreams() {
  const std::string& source = options.source;
  if (depth.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    ThrowInputError(source, "depth stream", "a depth sensor", OpenNiError());
  }
  if (color.create(device, openni::SENSOR_COLOR) != openni::STATUS_OK) {
    ThrowInputError(source, "colour stream", "a colour sensor", OpenNiError());
  }
  if (!recording) {
    // Depth in the colour camera's geometry, where the device does it; metric depth and RGB pixels.
    if (device.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
      device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
    }
    device.setDepthColorSyncEnabled(true);
    openni::VideoMode mode = color.getVideoMode();
    mode.setPixelFormat(openni::PIXEL_FORMAT_RGB888);
    color.setVideoMode(mode);
  }
  depth_scale = DepthScaleOf(depth.getVideoMode().getPixelFormat());
  if (depth_scale == 0.0) {
    ThrowInputError(source, "depth pixel format", "DEPTH_1_MM or DEPTH_100_UM",
                    std::to_string(depth.getVideoMode().getPixelFormat()));
  }
  if (color.getVideoMode().getPixelFormat() != openni::PIXEL_FORMAT_RGB888) {
    ThrowInputError(source, "colour pixel format", "RGB888", std::to_string(color.getVideoMode().getPixelFormat()));
  }
  num_frames = recording ? device.getPlaybackControl()->getNumberOfFrames(depth) : -1;
}

// K from --camera, else from the calibration file beside a recording, else from the colour stream's fields of view.
void OpenNiCamera::Impl::ChooseIntrinsics() {
  const openni::VideoMode mode = color.getVideoMode();
  const int width = mode.getResolutionX(), height = mode.getResolutionY();
  const std::string calibration_path = CalibrationPath(options.source);
  if (options.intrinsics) {
    const std::array<double, 4>& k = *options.intrinsics;
    CheckIntrinsics(k, options.source, "--camera");
    camera = {k[0], k[1], k[2], k[3], width, height};
    intrinsics_source = "given";
  } else if (recording && std::filesystem::exists(calibration_path)) {
    const RecordingCalibration calibration = ReadCalibration(calibration_path);
    if (calibration.camera.width != width || calibration.camera.height != height) {
      ThrowInputError(calibration_path, "width/height",
                      "the recording's colour size " + std::to_string(width) + "x" + std::to_string(height));
    }
    if (calibration.depth_scale != depth_scale) {
      ThrowInputError(calibration_path, "depth_scale",
                      std::to_string(depth_scale) + " as the recording's depth pixel format says",
                      std::to_string(calibration.depth_scale));
    }
    camera = calibration.camera;
    intrinsics_source = calibration_path;
  } else {
    camera = CameraFromFieldsOfView(width, height, color.getHorizontalFieldOfView(), color.getVerticalFieldOfView());
    intrinsics_source = "fields of view";
  }
  camera.Check(options.source);
}

openni::VideoFrameRef OpenNiCamera::Impl::Read(openni::VideoStream& stream, const char* what) {
  openni::VideoStream* streams[] = {&stream};
  int ready = -1;
  const int timeout_ms = static_cast<int>(std::ceil(options.frame_timeout_s * 1000.0));
  openni::VideoFrameRef frame;
  if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, timeout_ms) != openni::STATUS_OK ||
      stream.readFrame(&frame) != openni::STATUS_OK || !frame.isValid()) {
    ThrowInputError(options.source, what,
                    "a frame within " + std::to_string(options.frame_timeout_s) + " s (frame " +
                        std::to_string(frames_read + 1) + ")",
                    OpenNiError());
  }
  return frame;
}

// Depth registered to colour but of another resolution (a 320x240 depth mode with 640x480 colour): scaled to the
// colour image's size by nearest neighbour, which keeps every depth value measured. Other aspect ratios are refused.
cv::Mat OpenNiCamera::Impl::DepthInColorGeometry(const cv::Mat& depth_values, const cv::Size& color_size) const {
  if (depth_values.size() == color_size) return depth_values;
  if (depth_values.cols * color_size.height != depth_values.rows * color_size.width) {
    ThrowInputError(options.source, "depth size",
                    "the colour image's aspect ratio (" + std::to_string(color_size.width) + "x" +
                        std::to_string(color_size.height) + ")",
                    std::to_string(depth_values.cols) + "x" + std::to_string(depth_values.rows));
  }
  cv::Mat scaled;
  cv::resize(depth_values, scaled, color_size, 0.0, 0.0, cv::INTER_NEAREST);
  return scaled;
}

OpenNiCamera::OpenNiCamera(const CameraOptions& options) : impl_(std::make_unique<Impl>()) {
  options.Check();
  impl_->options = options;
  impl_->Open();
}

OpenNiCamera::~OpenNiCamera() = default;

std::optional<LoadedFrame> OpenNiCamera::Next() {
  Impl& impl = *impl_;
  if (impl.recording && impl.frames_read >= impl.num_frames) return std::nullopt;
  openni::VideoFrameRef depth = impl.Read(impl.depth, "depth stream");
  openni::VideoFrameRef color = impl.Read(impl.color, "colour stream");
  // A recording's streams hold one frame each per number; catch up the one behind.
  for (int tries = 0; impl.recording && depth.getFrameIndex() != color.getFrameIndex() && tries < 4; ++tries) {
    if (depth.getFrameIndex() < color.getFrameIndex()) depth = impl.Read(impl.depth, "depth stream");
    if (color.getFrameIndex() < depth.getFrameIndex()) color = impl.Read(impl.color, "colour stream");
  }
  ++impl.frames_read;
  const std::string name = impl.options.source + " frame " + std::to_string(depth.getFrameIndex());
  LoadedFrame loaded;
  loaded.rgbd.name = name;
  loaded.rgbd.color = FramePixels(color, CV_8UC3, impl.options.source);
  const cv::Mat values =
      impl.DepthInColorGeometry(FramePixels(depth, CV_16UC1, impl.options.source), loaded.rgbd.color.size());
  loaded.rgbd.depth = DepthImageAsMetres(values, impl.depth_scale, name);
  loaded.rgbd.camera = impl.camera;
  loaded.rgbd.Check();
  return loaded;
}

const PinholeCamera& OpenNiCamera::camera() const {
  return impl_->camera;
}
const std::string& OpenNiCamera::intrinsics_source() const {
  return impl_->intrinsics_source;
}
int OpenNiCamera::num_frames() const {
  return impl_->num_frames;
}
int OpenNiCamera::frames_read() const {
  return impl_->frames_read;
}

}  // namespace ecv
