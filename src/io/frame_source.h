#pragma once

// Where the frames of a stream come from, for the code that recognises them: files named one by one, a folder being
// filled, a camera or a recording. The recognizer's front ends (the CLI's --sequence) take any of them; sources that
// need other libraries (camera/: OpenNI2) implement it there, so that this library does not depend on them.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "io/frame_io.h"

namespace ecv {

/// A stream of RGB-D frames in order.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// Moves to the next frame and returns its name (a file, "FILE.oni frame 3"); nothing at the end. Throws InputError
  /// when the source itself fails (a camera that stops sending): the stream cannot go on.
  virtual std::optional<std::string> Next() = 0;

  /// The frame Next moved to. Throws InputError when that frame cannot be read; the stream may go on with the next.
  virtual LoadedFrame Load() = 0;

  /// Progress before a frame's report: "[3/10] " when the number of frames is known, "[3] " otherwise.
  virtual std::string Counter() const = 0;

  /// Frames passed over just before the one Next moved to (a live feed that keeps only the newest; 0 for others).
  virtual int Skipped() const { return 0; }
};

/// Opens the sources a front end knows beyond files (a camera, a recording): a source for `sequence`, or nullptr when
/// it names none of them. `intrinsics` is --camera "fx,fy,cx,cy" when given.
using FrameSourceOpener = std::function<std::unique_ptr<FrameSource>(const std::string& sequence,
                                                                     const std::optional<std::string>& intrinsics)>;

}  // namespace ecv
