#include "camera/camera_source.h"

namespace ecv {

CameraFrameSource::CameraFrameSource(const CameraOptions& options) : camera_(options) {}

std::optional<std::string> CameraFrameSource::Next() {
  frame_ = camera_.Next();
  if (!frame_) return std::nullopt;
  return frame_->rgbd.name;
}

LoadedFrame CameraFrameSource::Load() {
  return *frame_;
}

std::string CameraFrameSource::Counter() const {
  const int total = camera_.num_frames();
  return "[" + std::to_string(camera_.frames_read()) + (total >= 0 ? "/" + std::to_string(total) : "") + "] ";
}

}  // namespace ecv
