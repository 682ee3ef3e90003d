#pragma once

// RGB-D frames from OpenNI2: a device (Kinect, Asus Xtion, Orbbec) or an .oni recording, through the same API.
// OpenNI2's types stay inside openni_camera.cpp.

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "core/camera.h"
#include "io/frame_io.h"

namespace ecv {

/// True for the sources OpenNiCamera opens: "openni2://" (the first device), "openni2://URI" (that device), and paths
/// ending in ".oni".
bool IsOpenNiSource(const std::string& source);

/// The calibration file beside a recording: FILE.oni.json.
std::string CalibrationPath(const std::string& recording);

/// What a recording's calibration file holds: {"camera": [fx, fy, cx, cy] (pixels), "width", "height" (pixels),
/// "depth_scale" (depth values per metre of the recording's 16-bit depth)}.
struct RecordingCalibration {
  PinholeCamera camera;
  double depth_scale = 0.0;
};

/// Writes `calibration` to `path` (atomically). Throws InputError naming `path` when it cannot.
void WriteCalibration(const std::string& path, const RecordingCalibration& calibration);

/// Reads a calibration file; throws InputError naming the file and the field that is missing or wrong.
RecordingCalibration ReadCalibration(const std::string& path);

struct CameraOptions {
  /// "openni2://", "openni2://URI" or FILE.oni.
  std::string source;
  /// Intrinsics fx, fy, cx, cy (pixels) of the colour image that override every other source (--camera).
  std::optional<std::array<double, 4>> intrinsics;
  /// Longest wait for a device's next frame, seconds: a device that stops sending is an error, not a hang.
  double frame_timeout_s = 5.0;

  /// Throws InputError for a source that is none of the above or a non-positive timeout.
  void Check() const;
};

/// An opened OpenNI2 device or recording with its depth and colour streams started, depth registered to colour
/// (IMAGE_REGISTRATION_DEPTH_TO_COLOR) where the device can. A recording plays once, every frame in order.
class OpenNiCamera {
 public:
  /// Opens the source; throws InputError naming what was looked for when there is no such device or the recording is
  /// unreadable (checked by CheckOniFile first), and when it lacks a depth or a colour stream.
  explicit OpenNiCamera(const CameraOptions& options);
  ~OpenNiCamera();
  OpenNiCamera(const OpenNiCamera&) = delete;
  OpenNiCamera& operator=(const OpenNiCamera&) = delete;

  /// The next frame (colour RGB, depth metres registered to it, the intrinsics below); nothing at the end of a
  /// recording. Throws InputError when no frame comes within frame_timeout_s or a frame is malformed.
  std::optional<LoadedFrame> Next();

  /// The colour camera's intrinsics and where they came from ("given" (CameraOptions::intrinsics), the calibration
  /// file FILE.oni.json, or "fields of view").
  const PinholeCamera& camera() const;
  const std::string& intrinsics_source() const;

  /// Frames of a recording (-1 for a device) and frames read so far.
  int num_frames() const;
  int frames_read() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The intrinsics of a `width` x `height` image with fields of view `horizontal_fov_rad`, `vertical_fov_rad`, the
/// principal point at the image centre: fx = width / (2 tan(hfov / 2)), cx = (width - 1) / 2.
PinholeCamera CameraFromFieldsOfView(int width, int height, double horizontal_fov_rad, double vertical_fov_rad);

/// Fields of view (radians) of `camera`, the inverse of CameraFromFieldsOfView: 2 atan(width / (2 fx)).
std::array<double, 2> FieldsOfView(const PinholeCamera& camera);

}  // namespace ecv
