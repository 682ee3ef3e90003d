#include "fuzz_util.h"

#include <stdlib.h>

#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace ecv::fuzz {
namespace fs = std::filesystem;
namespace {

class Scratch {
 public:
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "ecvfuzz-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("cannot make a folder like " + pattern);
    path_ = pattern;
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

const fs::path& ScratchDir() {
  static const Scratch scratch;
  return scratch.path();
}

void WriteFile(const fs::path& path, const std::string& bytes) {
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!stream) throw std::runtime_error("cannot write " + path.string());
}

std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t count) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t start = 0;
  while (parts.size() + 1 < count) {
    const size_t end = input.find(kPartSeparator, start);
    if (end == std::string::npos) break;
    parts.push_back(input.substr(start, end - start));
    start = end + kPartSeparator.size();
  }
  parts.push_back(input.substr(start));
  parts.resize(count);
  return parts;
}

void WriteGoodImages(const fs::path& color_png, const fs::path& depth_png) {
  cv::Mat color(24, 32, CV_8UC3), depth(24, 32, CV_16UC1);
  for (int v = 0; v < color.rows; ++v) {
    for (int u = 0; u < color.cols; ++u) {
      color.at<cv::Vec3b>(v, u) = {static_cast<uchar>(8 * u), static_cast<uchar>(10 * v), 128};
      depth.at<uint16_t>(v, u) = static_cast<uint16_t>(8000 + 125 * u);
    }
  }
  if (!cv::imwrite(color_png.string(), color) || !cv::imwrite(depth_png.string(), depth)) {
    throw std::runtime_error("cannot write the good images " + color_png.string() + ", " + depth_png.string());
  }
}

}  // namespace ecv::fuzz
