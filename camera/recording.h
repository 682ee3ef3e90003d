#pragma once

// Recording any frame stream as an .oni file that OpenNI2 plays, with its intrinsics beside it (FILE.oni.json).

#include <functional>
#include <string>

#include "camera/oni_writer.h"
#include "core/camera.h"
#include "io/frame_source.h"

namespace ecv {

struct RecordOptions {
  std::string out;     ///< FILE.oni; its calibration goes to FILE.oni.json
  int max_frames = 0;  ///< stop after this many frames; 0: all (a camera then records until it fails)
  double fps = 30.0;   ///< frames per second of the recording's timestamps

  /// Throws InputError for an output not ending in .oni, a negative frame count or a non-positive fps.
  void Check() const;
};

struct RecordResult {
  int frames = 0;
  PinholeCamera camera;  ///< the intrinsics written beside the recording
  OniDepthUnit depth_unit = OniDepthUnit::kHundredMicrometres;
  /// Whether every depth value reads back bit for bit (true for 16-bit sources at 0.1 mm or 1 mm); else the largest
  /// change, metres (half a unit at most).
  bool depth_exact = true;
  double max_depth_change_m = 0.0;
};

/// Writes the frames of `source` to options.out (through a temporary file: nothing is left there on an error) and
/// the first frame's intrinsics to CalibrationPath(options.out). Every frame must have the first one's size and
/// intrinsics (InputError naming the frame otherwise); the depth unit is the first frame's exact one (ExactDepthUnit).
/// `progress` is called after each frame with its counter and name.
RecordResult RecordFrames(FrameSource& source, const RecordOptions& options,
                          const std::function<void(const std::string& counter, const std::string& name)>& progress);

}  // namespace ecv
