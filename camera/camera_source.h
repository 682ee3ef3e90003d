#pragma once

// OpenNI2 cameras and recordings as a FrameSource: what `ecvpose recognize --sequence openni2://` reads.

#include <memory>
#include <optional>
#include <string>

#include "camera/openni_camera.h"
#include "io/frame_source.h"

namespace ecv {

/// The frames of an OpenNiCamera, one FrameSource among the file sequences.
class CameraFrameSource : public FrameSource {
 public:
  /// Opens the camera or recording (InputError as OpenNiCamera's).
  explicit CameraFrameSource(const CameraOptions& options);

  std::optional<std::string> Next() override;
  LoadedFrame Load() override;
  std::string Counter() const override;

  const OpenNiCamera& camera() const { return camera_; }

 private:
  OpenNiCamera camera_;
  std::optional<LoadedFrame> frame_;
};

}  // namespace ecv
