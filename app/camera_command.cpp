// `ecvpose record --sequence SOURCE --out FILE.oni`: records an OpenNI2 camera or any frame sequence as an .oni file,
// and opens cameras and recordings for `ecvpose recognize --sequence`.

#include <iomanip>
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "app/frame_args.h"
#include "app/sequence_io.h"
#include "camera/camera_source.h"
#include "camera/recording.h"

namespace ecv::app {
namespace {

struct RecordArgs {
  std::string sequence;
  std::string out;
  int frames = 0;
  double fps = 30.0;
  std::optional<std::string> camera;
  double timeout_s = 5.0;
};

// A camera or recording for `sequence`, with where its intrinsics come from said on stderr.
std::unique_ptr<CameraFrameSource> OpenCamera(const std::string& sequence, const std::optional<std::string>& intrinsics,
                                              double timeout_s) {
  CameraOptions options;
  options.source = sequence;
  options.frame_timeout_s = timeout_s;
  if (intrinsics) options.intrinsics = ParseIntrinsics(*intrinsics, "--camera");
  auto source = std::make_unique<CameraFrameSource>(options);
  const OpenNiCamera& camera = source->camera();
  const PinholeCamera& k = camera.camera();
  std::cerr << "camera: " << sequence << ": " << k.width << "x" << k.height
            << (camera.num_frames() >= 0 ? ", " + std::to_string(camera.num_frames()) + " frames" : "")
            << std::setprecision(6) << "; K = " << k.fx << ", " << k.fy << ", " << k.cx << ", " << k.cy << " from "
            << (camera.intrinsics_source() == "given" ? "--camera" : camera.intrinsics_source())
            << (camera.intrinsics_source() == "fields of view"
                    ? " with the principal point at the image centre (give --camera fx,fy,cx,cy, or FILE.oni.json "
                      "beside a recording, for a calibrated K)"
                    : "")
            << '\n';
  return source;
}

int RunRecord(const RecordArgs& args) {
  RecordOptions options;
  options.out = args.out;
  options.max_frames = args.frames;
  options.fps = args.fps;
  options.Check();  // before a camera is opened
  std::unique_ptr<FrameSource> source;
  if (IsOpenNiSource(args.sequence)) {
    if (args.frames == 0 && args.sequence.rfind("openni2://", 0) == 0) {
      std::cerr << "ecvpose record: a camera needs --frames N (how many frames to record)\n";
      return kExitBadUsage;
    }
    source = OpenCamera(args.sequence, args.camera, args.timeout_s);
  } else {
    if (args.camera) {
      std::cerr
          << "ecvpose record: --camera is for openni2:// cameras and .oni recordings; frame files carry their own "
             "intrinsics\n";
      return kExitBadUsage;
    }
    source = std::make_unique<FrameFeed>(args.sequence, false, 0.0);
  }
  const RecordResult result = RecordFrames(*source, options, [](const std::string& counter, const std::string& name) {
    std::cerr << "record: " << counter << name << '\n';
  });
  std::cerr << "record: " << result.frames << " frames to " << args.out << " (depth in "
            << (result.depth_unit == OniDepthUnit::kMillimetre ? "1 mm" : "0.1 mm") << " units, "
            << (result.depth_exact ? "exact"
                                   : "rounded by up to " + std::to_string(result.max_depth_change_m * 1000.0) + " mm")
            << "), intrinsics to " << CalibrationPath(args.out) << '\n';
  return kExitOk;
}

}  // namespace

std::unique_ptr<FrameSource> OpenCameraSource(const std::string& sequence,
                                              const std::optional<std::string>& intrinsics) {
  if (!IsOpenNiSource(sequence)) return nullptr;
  return OpenCamera(sequence, intrinsics, 5.0);
}

CommandAction SetupRecordCommand(CLI::App& command) {
  auto args = std::make_shared<RecordArgs>();
  command
      .add_option("--sequence", args->sequence,
                  "What to record: an OpenNI2 camera (openni2:// for the first, openni2://URI), a FILE.oni recording,\n"
                  "or any sequence `recognize --sequence` reads (a YCB-Video video folder, a BOP scene, a folder of\n"
                  "frame JSONs, a list file)")
      ->required();
  command.add_option("--out", args->out, "The recording, FILE.oni; its intrinsics go to FILE.oni.json")->required();
  command.add_option("--frames", args->frames, "Record this many frames (default: all; required for a camera)")
      ->check(NonNegative());
  command.add_option("--fps", args->fps, "Frames per second of the recording's timestamps")
      ->capture_default_str()
      ->check(Positive());
  command.add_option("--camera", args->camera,
                     "Intrinsics fx,fy,cx,cy (pixels) of a camera or recording (default: FILE.oni.json beside a\n"
                     "recording, else the fields of view)");
  command.add_option("--timeout", args->timeout_s, "Seconds to wait for a camera's next frame")
      ->capture_default_str()
      ->check(Positive());
  command.footer(
      "Examples:\n  ecvpose record --sequence ../shared/data/ycbv_subset/Example-Scenes/0001 --out video.oni\n"
      "  ecvpose record --sequence openni2:// --frames 300 --out live.oni\n"
      "  ecvpose recognize --db lib.sqlite --sequence video.oni");
  return [args] { return RunRecord(*args); };
}

}  // namespace ecv::app
