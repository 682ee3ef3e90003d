// ecvpose-view under a virtual X server (Xvfb): the window shows the recognizer's own detection drawing of the demo
// frame, pixel for pixel, and names the three demo objects.

#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "support/demo_library.h"

namespace ecv {
namespace {

// A big-endian CARD32 of an xwd file's header.
uint32_t BigEndian32(const std::string& bytes, size_t at) {
  uint32_t value = 0;
  for (size_t i = 0; i < 4; ++i) value = (value << 8) | static_cast<unsigned char>(bytes[at + i]);
  return value;
}

// The colour of a pixel value under a channel mask of 8 bits (e.g. 0xff0000 -> bits 16..23).
uint8_t Channel(uint32_t pixel, uint32_t mask) {
  if (mask == 0) return 0;
  int shift = 0;
  while (((mask >> shift) & 1U) == 0) ++shift;
  return static_cast<uint8_t>((pixel & mask) >> shift);
}

// An xwd dump (X Window Dump, version 7, as `xwd -root` writes it) of a true-colour screen of 24 or 32 bits a pixel,
// as BGR; nothing for other kinds. The header is 25 big-endian CARD32s, then the window name, then ncolors colour
// entries of 12 bytes, then the rows of bytes_per_line in the header's byte order.
std::optional<cv::Mat> ReadXwd(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 100 || BigEndian32(bytes, 4) != 7 || BigEndian32(bytes, 8) != 2) return std::nullopt;
  const auto field = [&](int index) { return BigEndian32(bytes, 4 * static_cast<size_t>(index)); };
  const uint32_t width = field(4), height = field(5), msb_first = field(7), bits = field(11), stride = field(12);
  const uint32_t red = field(14), green = field(15), blue = field(16);
  const size_t data = field(0) + 12 * size_t{field(19)};
  if ((bits != 32 && bits != 24) || bytes.size() < data + size_t{stride} * height) return std::nullopt;
  cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC3);
  const size_t pixel_bytes = bits / 8;
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const size_t at = data + size_t{y} * stride + x * pixel_bytes;
      uint32_t pixel = 0;
      for (size_t i = 0; i < pixel_bytes; ++i) {
        const auto byte = static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + i]));
        pixel |= msb_first != 0 ? byte << (8 * (pixel_bytes - 1 - i)) : byte << (8 * i);
      }
      image.at<cv::Vec3b>(static_cast<int>(y), static_cast<int>(x)) =
          cv::Vec3b(Channel(pixel, blue), Channel(pixel, green), Channel(pixel, red));
    }
  }
  return image;
}

// Where `part` lies in `screen` exactly, pixel for pixel; nothing when it is nowhere.
std::optional<cv::Point> FindExactly(const cv::Mat& screen, const cv::Mat& part) {
  for (int y = 0; y + part.rows <= screen.rows; ++y) {
    for (int x = 0; x + part.cols <= screen.cols; ++x) {
      const cv::Mat region = screen(cv::Rect(x, y, part.cols, part.rows));
      // The first row decides at once almost everywhere; the whole picture where it matches.
      if (cv::countNonZero(region.row(0).reshape(1) != part.row(0).reshape(1)) > 0) continue;
      if (cv::countNonZero(region.reshape(1) != part.reshape(1)) == 0) return cv::Point(x, y);
    }
  }
  return std::nullopt;
}

bool Installed(const std::string& program) {
  return test::RunCommand("command -v " + program).exit_code == 0;
}

class ViewerWindow : public test::DemoLibrarySuite {};

TEST_F(ViewerWindow, ShowsTheRecognizersDrawingOfTheDemoFrame) {
  for (const char* program : {"xvfb-run", "Xvfb", "xauth", "xwd"}) {
    if (!Installed(program))
      GTEST_SKIP() << program << " is not installed (scripts/setup installs xvfb, xauth and x11-apps)";
  }
  // The recognizer's drawing of the demo frame, through the same drawing code as the viewer's child.
  const std::string expected_png = directory_->File("expected.png");
  const test::CommandResult recognize =
      test::RunCli("recognize --db " + library_ + " " + DemoFrame() + " --overlay " + expected_png);
  ASSERT_EQ(recognize.exit_code, 0) << recognize.output;
  const std::string list = directory_->File("view-frames.txt"), log = directory_->File("view.log");
  std::ofstream(list) << DemoFrame() << '\n';

  // The viewer under Xvfb: wait for its first frame, dump the screen, stop it as a window manager would (SIGTERM).
  const std::string shot = directory_->File("screen.xwd"), script = directory_->File("view.sh");
  std::ofstream(script) << ECV_VIEW_PATH << " --db " << library_ << " --sequence " << list << " > " << log
                        << " 2>&1 &\n"
                        << "pid=$!\n"
                        << "i=0\n"
                        << "until grep -q '^frame 1 ' " << log << "; do\n"
                        << "  i=$((i+1)); [ $i -gt 600 ] && break; sleep 0.1\n"
                        << "done\n"
                        << "sleep 1\n"  // for the X server to paint the window
                        << "xwd -root -silent > " << shot << "\n"
                        << "kill -TERM $pid\n"
                        << "wait $pid\n"
                        << "echo \"viewer exit $?\"\n";
  const test::CommandResult run = test::RunCommand("xvfb-run -a -s '-screen 0 1024x768x24 -nolisten tcp' sh " + script);
  std::ifstream in(log);
  const std::string viewer_output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(run.exit_code, 0) << run.output << viewer_output;
  EXPECT_NE(run.output.find("viewer exit 0"), std::string::npos) << run.output << viewer_output;

  // The three demo objects, as the viewer read them from the recognizer and lists them under the picture.
  for (const char* model : {"003_cracker_box", "004_sugar_box", "006_mustard_bottle"}) {
    EXPECT_NE(viewer_output.find(model), std::string::npos) << model << " not named:\n" << viewer_output;
  }
  const cv::Mat expected = cv::imread(expected_png, cv::IMREAD_COLOR);
  ASSERT_FALSE(expected.empty()) << expected_png;
  const std::optional<cv::Mat> screen = ReadXwd(shot);
  ASSERT_TRUE(screen.has_value()) << shot << " is not a 24/32-bit true-colour xwd dump";
  const std::optional<cv::Point> at = FindExactly(*screen, expected);
  EXPECT_TRUE(at.has_value()) << "the recognizer's drawing (" << expected.cols << " x " << expected.rows
                              << ") is nowhere on the " << screen->cols << " x " << screen->rows << " screen, "
                              << "pixel for pixel:\n"
                              << viewer_output;
}

TEST(ViewerErrors, NoDisplayIsAClearErrorExitOne) {
  const test::CommandResult run = test::RunCommand(std::string("env -u DISPLAY -u WAYLAND_DISPLAY ") + ECV_VIEW_PATH +
                                                   " --db /nonexistent/library.sqlite --sequence openni2://");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("ecvpose-view: no display: DISPLAY is not set"), std::string::npos) << run.output;
  const test::CommandResult stale = test::RunCommand(std::string("DISPLAY=:4711 ") + ECV_VIEW_PATH +
                                                     " --db /nonexistent/library.sqlite --sequence openni2://");
  EXPECT_EQ(stale.exit_code, 1) << stale.output;
  EXPECT_NE(stale.output.find("no X server listens on /tmp/.X11-unix/X4711"), std::string::npos) << stale.output;
  const test::CommandResult usage = test::RunCommand(std::string(ECV_VIEW_PATH) + " --sequence openni2://");
  EXPECT_EQ(usage.exit_code, 2) << usage.output;  // --db is required
}

}  // namespace
}  // namespace ecv
