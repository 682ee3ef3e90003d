#include "camera/recording.h"

#include <memory>

#include "camera/openni_camera.h"
#include "core/error.h"

namespace ecv {
namespace {

bool SameCamera(const PinholeCamera& a, const PinholeCamera& b) {
  return a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy && a.width == b.width && a.height == b.height;
}

// The writer for a recording of frames like `first`: its size, its exact depth unit and fields of view.
std::unique_ptr<OniWriter> OpenWriter(const RecordOptions& options, const RgbdFrame& first, RecordResult* result) {
  OniWriterOptions writer;
  writer.width = first.color.cols;
  writer.height = first.color.rows;
  writer.fps = options.fps;
  writer.depth_unit = ExactDepthUnit(first.depth, &result->depth_exact);
  const std::array<double, 2> fov = FieldsOfView(first.camera);
  writer.horizontal_fov_rad = fov[0];
  writer.vertical_fov_rad = fov[1];
  result->camera = first.camera;
  result->depth_unit = writer.depth_unit;
  return std::make_unique<OniWriter>(options.out, writer);
}

// The largest change (metres) of `depth_m` once stored as `values` of `unit`.
double DepthChange(const cv::Mat& depth_m, const cv::Mat& values, OniDepthUnit unit) {
  cv::Mat back;
  values.convertTo(back, CV_32F, 1.0 / DepthValuesPerMetre(unit));
  double largest = 0.0;
  cv::minMaxLoc(cv::abs(back - depth_m), nullptr, &largest);
  return largest;
}

}  // namespace

void RecordOptions::Check() const {
  if (out.size() < 5 || out.compare(out.size() - 4, 4, ".oni") != 0) {
    ThrowInputError(out, "--out", "a file name ending in .oni");
  }
  if (max_frames < 0) ThrowInputError(out, "--frames", "0 (all) or more", std::to_string(max_frames));
  if (!(fps > 0.0)) ThrowInputError(out, "--fps", "a positive number", std::to_string(fps));
}

RecordResult RecordFrames(FrameSource& source, const RecordOptions& options,
                          const std::function<void(const std::string&, const std::string&)>& progress) {
  options.Check();
  RecordResult result;
  std::unique_ptr<OniWriter> writer;
  while (options.max_frames == 0 || result.frames < options.max_frames) {
    const std::optional<std::string> name = source.Next();
    if (!name) break;
    const RgbdFrame frame = source.Load().rgbd;
    if (!writer) writer = OpenWriter(options, frame, &result);
    if (!SameCamera(frame.camera, result.camera)) {
      ThrowInputError(*name, "camera", "the first frame's size and intrinsics (a recording holds one camera)");
    }
    const cv::Mat values = DepthValues(frame.depth, result.depth_unit, *name);
    const double change = DepthChange(frame.depth, values, result.depth_unit);
    result.depth_exact = result.depth_exact && change == 0.0;
    result.max_depth_change_m = std::max(result.max_depth_change_m, change);
    writer->Write(frame.color, values);
    ++result.frames;
    if (progress) progress(source.Counter(), *name);
  }
  if (!writer) ThrowInputError(options.out, "frames", "at least one frame to record", "the source gave none");
  writer->Finish();
  WriteCalibration(CalibrationPath(options.out), {result.camera, DepthValuesPerMetre(result.depth_unit)});
  return result;
}

}  // namespace ecv
