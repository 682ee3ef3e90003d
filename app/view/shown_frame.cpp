#include "app/view/shown_frame.h"

#include <cstdio>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

namespace ecv::view {
namespace {

// The panel under the picture: text lines of kLineHeight pixels; detections beyond kDetectionLines are counted.
constexpr int kLineHeight = 22;
constexpr int kDetectionLines = 6;
constexpr int kMargin = 8;
constexpr double kFontScale = 0.5;

[[noreturn]] void ThrowBadLine(const std::string& field, const std::string& expected) {
  throw std::runtime_error("the recognizer's output: " + field + ": expected " + expected);
}

ShownDetection ParseDetection(const nlohmann::json& item, size_t index) {
  const std::string field = "detections[" + std::to_string(index) + "]";
  if (!item.is_object() || !item.contains("model") || !item["model"].is_string()) {
    ThrowBadLine(field + ".model", "a string");
  }
  if (!item.value("score", nlohmann::json(0.0)).is_number()) ThrowBadLine(field + ".score", "a number");
  ShownDetection detection;
  detection.model = item["model"].get<std::string>();
  detection.score = item.value("score", 0.0);
  detection.tracked = item.value("tracked", false);
  detection.confirmed = item.value("confirmed", false);
  detection.ppf = item.value("hypothesis", std::string()) == "ppf";
  return detection;
}

// Text line `line` (0: the status) of the panel that starts at row `panel_top`; the baseline sits 6 px above the
// line's bottom, so that no glyph reaches into the picture above.
void PutLine(cv::Mat& canvas, int panel_top, const std::string& text, int line, const cv::Scalar& colour) {
  const cv::Point at(kMargin, panel_top + kMargin / 2 + (line + 1) * kLineHeight - 6);
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, kFontScale, colour, 1, cv::LINE_AA);
}

}  // namespace

ShownFrame ParseRecognitionLine(const std::string& line) {
  const nlohmann::json json = nlohmann::json::parse(line, nullptr, false);
  if (json.is_discarded() || !json.is_object()) ThrowBadLine("line", "one JSON object, got: " + line.substr(0, 80));
  if (!json.contains("frame") || !json["frame"].is_string()) ThrowBadLine("frame", "a string");
  ShownFrame frame;
  frame.frame = json["frame"].get<std::string>();
  if (json.contains("error")) {
    frame.error = json["error"].is_string() ? json["error"].get<std::string>() : json["error"].dump();
    return frame;
  }
  if (!json.contains("overlay") || !json["overlay"].is_string()) ThrowBadLine("overlay", "a PNG path (--overlay)");
  frame.overlay = json["overlay"].get<std::string>();
  if (!json.contains("detections") || !json["detections"].is_array()) ThrowBadLine("detections", "an array");
  for (size_t i = 0; i < json["detections"].size(); ++i) {
    frame.detections.push_back(ParseDetection(json["detections"][i], i));
  }
  const nlohmann::json timings = json.value("timings_ms", nlohmann::json::object());
  if (timings.is_object() && timings.contains("total") && timings["total"].is_number()) {
    frame.recognizer_ms = timings["total"].get<double>();
  }
  return frame;
}

std::string TrackState(const ShownDetection& detection) {
  if (detection.tracked) return detection.confirmed ? "tracked, confirmed" : "tracked";
  return detection.confirmed ? "searched, confirmed" : "searched";
}

std::string DescribeFrame(const ShownFrame& frame) {
  std::string text = frame.frame + ":";
  if (!frame.error.empty()) return text + " skipped: " + frame.error;
  if (frame.detections.empty()) return text + " no detections";
  char score[16];
  for (size_t i = 0; i < frame.detections.size(); ++i) {
    const ShownDetection& d = frame.detections[i];
    std::snprintf(score, sizeof(score), "%.2f", d.score);
    text += (i > 0 ? "; " : " ") + d.model + " " + score + " " + TrackState(d) + (d.ppf ? " (ppf)" : "");
  }
  return text;
}

cv::Mat ComposeView(const cv::Mat& drawing, const ShownFrame& frame, const std::string& status) {
  const int panel = (kDetectionLines + 1) * kLineHeight + kMargin;
  cv::Mat canvas(drawing.rows + panel, drawing.cols, CV_8UC3, cv::Scalar(40, 40, 40));
  drawing.copyTo(canvas(cv::Rect(0, 0, drawing.cols, drawing.rows)));
  PutLine(canvas, drawing.rows, status, 0, cv::Scalar(255, 255, 255));
  if (!frame.error.empty()) PutLine(canvas, drawing.rows, "skipped: " + frame.error, 1, cv::Scalar(80, 80, 255));
  char score[16];
  for (size_t i = 0; i < frame.detections.size() && frame.error.empty(); ++i) {
    const ShownDetection& d = frame.detections[i];
    const int line = static_cast<int>(i) + 1;
    if (line == kDetectionLines && frame.detections.size() > static_cast<size_t>(kDetectionLines)) {
      PutLine(canvas, drawing.rows, "... and " + std::to_string(frame.detections.size() - i) + " more", line,
              {200, 200, 200});
      break;
    }
    std::snprintf(score, sizeof(score), "%.2f", d.score);
    // Tracked detections in green, searched ones in the drawing's red (BGR).
    const cv::Scalar colour = d.tracked ? cv::Scalar(120, 230, 120) : cv::Scalar(110, 110, 255);
    PutLine(canvas, drawing.rows, d.model + "  " + score + "  " + TrackState(d) + (d.ppf ? "  (ppf)" : ""), line,
            colour);
  }
  return canvas;
}

}  // namespace ecv::view
