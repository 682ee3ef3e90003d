#pragma once

// What ecvpose-view shows of one frame: the recognizer's JSON line read into a struct, and the window's picture (the
// recognizer's own detection drawing, unchanged, above a panel of text).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace ecv::view {

/// One detection as the panel lists it.
struct ShownDetection {
  std::string model;
  double score = 0.0;      ///< verification score, 0..1
  bool tracked = false;    ///< followed from the previous frame without a search
  bool confirmed = false;  ///< a later search found the track again
  bool ppf = false;        ///< the pose came from point pair features (shape alone)
};

/// One line of `ecvpose recognize --sequence ... --out-json - --overlay DIR`.
struct ShownFrame {
  std::string frame;    ///< the frame's name in the sequence
  std::string overlay;  ///< the PNG of its detection drawing; empty when the frame failed
  std::string error;    ///< why the recognizer skipped the frame; empty when it did not
  std::vector<ShownDetection> detections;
  double recognizer_ms = 0.0;  ///< the recognizer's time on the frame ("timings_ms"."total"), milliseconds
};

/// The frame of a JSON line. Throws std::runtime_error naming the field and what was expected when the line is not
/// the recognizer's.
ShownFrame ParseRecognitionLine(const std::string& line);

/// "tracked, confirmed", "tracked" or "searched" (found by a search in this frame).
std::string TrackState(const ShownDetection& detection);

/// One line of text for the frame: "<frame>: <model> <score> <state>; ..." (printed and drawn).
std::string DescribeFrame(const ShownFrame& frame);

/// The window's picture: `drawing` (BGR, the recognizer's detection drawing) at the top left, unchanged, above a dark
/// panel with `status` (frame number, frames per second, ...) and one line per detection.
cv::Mat ComposeView(const cv::Mat& drawing, const ShownFrame& frame, const std::string& status);

}  // namespace ecv::view
