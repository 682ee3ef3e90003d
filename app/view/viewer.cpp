#include "app/view/viewer.h"

#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>

#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>

#include "app/view/shown_frame.h"

namespace ecv::view {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kPollMs = 15;        // how long each turn waits for a key, milliseconds
constexpr size_t kFpsFrames = 10;  // frames per second are averaged over the last this many frames
// Key codes of waitKeyEx: the right arrow as OpenCV's Qt and GTK back ends report it.
constexpr int kQtRight = 0x01000014, kGtkRight = 0xff53, kEscape = 27;

class Viewer {
 public:
  Viewer(RecognizerChild& child, const ViewerOptions& options) : child_(child), options_(options) {
    cv::namedWindow(options_.window, cv::WINDOW_AUTOSIZE | cv::WINDOW_GUI_NORMAL);
    canvas_ = ComposeView(cv::Mat(480, 640, CV_8UC3, cv::Scalar(0, 0, 0)), {}, "starting the recognizer ...");
    cv::imshow(options_.window, canvas_);
  }

  int Run(const volatile std::sig_atomic_t& stop) {
    while (stop == 0) {
      const int key = cv::waitKeyEx(kPollMs);
      if ((key >= 0 && !OnKey(key)) || cv::getWindowProperty(options_.window, cv::WND_PROP_VISIBLE) < 1.0) break;
      if (!paused_ || step_) TakeFrame();
      if (!end_code_ && child_.Ended()) end_code_ = child_.ExitCode();
      if (end_code_ && !end_reported_) {
        end_reported_ = true;
        if (shown_ == 0 && *end_code_ != 0) {
          std::cerr << "ecvpose-view: the recognizer exited with code " << *end_code_
                    << " before its first frame (its message above)\n";
          return *end_code_;
        }
        std::cout << "end of the sequence: " << shown_ << " frames shown" << std::endl;
        if (options_.exit_at_end) break;
        Redraw();
      }
    }
    cv::destroyAllWindows();
    return end_code_ ? *end_code_ : 0;
  }

 private:
  // Acts on a key; false to quit.
  bool OnKey(int key) {
    if (key == 'q' || key == 'Q' || key == kEscape) return false;
    if (key == ' ') {
      paused_ = !paused_;
      arrivals_.clear();  // the pause is no frame time
      Redraw();
    } else if ((key == 'n' || key == kQtRight || key == kGtkRight) && paused_) {
      step_ = true;
      arrivals_.clear();
    } else if (key == 's' || key == 'S') {
      Save();
    }
    return true;
  }

  // Shows the child's next frame when one has come.
  void TakeFrame() {
    const std::optional<std::string> line = child_.NextLine(0);
    if (!line) return;
    step_ = false;
    frame_ = ParseRecognitionLine(*line);
    ++shown_;
    arrivals_.push_back(Clock::now());
    if (arrivals_.size() > kFpsFrames) arrivals_.pop_front();
    if (!frame_.overlay.empty()) {
      drawing_ = cv::imread(frame_.overlay, cv::IMREAD_COLOR);
      if (drawing_.empty()) throw std::runtime_error(frame_.overlay + ": overlay: expected the recognizer's PNG");
      std::filesystem::remove(frame_.overlay);  // a live camera would otherwise fill the disk
    }
    Redraw();
    std::cout << "frame " << shown_ << ' ' << DescribeFrame(frame_) << std::endl;
  }

  void Redraw() {
    if (drawing_.empty()) return;
    canvas_ = ComposeView(drawing_, frame_, Status());
    cv::imshow(options_.window, canvas_);
  }

  // "frame 12   9.8 fps   recognizer 102 ms   paused (space: resume, n: step)".
  std::string Status() const {
    char text[160];
    double fps = 0.0;
    if (arrivals_.size() > 1) {
      const double seconds = std::chrono::duration<double>(arrivals_.back() - arrivals_.front()).count();
      fps = seconds > 0.0 ? static_cast<double>(arrivals_.size() - 1) / seconds : 0.0;
    }
    std::snprintf(text, sizeof(text), "frame %d   %s fps   recognizer %.0f ms", shown_,
                  fps > 0.0 ? cv::format("%.1f", fps).c_str() : "--", frame_.recognizer_ms);
    std::string status = text;
    if (end_code_) status += "   end of sequence (q: quit)";
    if (paused_) status += "   paused (space: resume, n: step)";
    return status;
  }

  void Save() const {
    if (drawing_.empty()) return;
    const std::filesystem::path path =
        std::filesystem::absolute(options_.save_dir) / cv::format("ecvpose-view-%04d.png", shown_);
    if (cv::imwrite(path.string(), canvas_)) {
      std::cout << "saved " << path.string() << std::endl;
    } else {
      std::cerr << "ecvpose-view: " << path.string() << ": cannot write the picture\n";
    }
  }

  RecognizerChild& child_;
  const ViewerOptions& options_;
  ShownFrame frame_;
  cv::Mat drawing_, canvas_;  ///< the recognizer's drawing of the shown frame; the window's picture (BGR)
  std::deque<Clock::time_point> arrivals_;
  int shown_ = 0;
  bool paused_ = false, step_ = false, end_reported_ = false;
  std::optional<int> end_code_;
};

}  // namespace

int RunViewer(RecognizerChild& child, const ViewerOptions& options, const volatile std::sig_atomic_t& stop) {
  Viewer viewer(child, options);
  return viewer.Run(stop);
}

}  // namespace ecv::view
