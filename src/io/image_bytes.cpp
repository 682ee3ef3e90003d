#include "io/image_bytes.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace ecv {
namespace {

std::string ImageTypeText(const cv::Mat& image) {
  const int depth = image.depth();
  const char* bits = depth == CV_8U ? "8-bit" : depth == CV_16U ? "16-bit" : depth == CV_32F ? "32-bit float" : "other";
  return std::string(bits) + " " + std::to_string(image.channels()) + "-channel";
}

// The value of base64 digit `c`, or -1.
int Base64Digit(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

uint32_t BigEndian32(const std::string& bytes, size_t at) {
  uint32_t value = 0;
  for (size_t i = 0; i < 4; ++i) value = (value << 8) | static_cast<unsigned char>(bytes[at + i]);
  return value;
}

// The PNG in `bytes`, decoded as it is stored, after its header (signature and IHDR chunk: width and height, big
// endian, at bytes 16 and 20) has been checked against kMaxDecodedSide.
cv::Mat DecodePng(const std::string& bytes, const std::string& source, const char* what) {
  static const std::string kSignature = "\x89PNG\r\n\x1a\n";
  if (bytes.size() < 24 || bytes.compare(0, 8, kSignature) != 0 || bytes.compare(12, 4, "IHDR") != 0) {
    ThrowInputError(source, what, "a PNG file", "no PNG header");
  }
  const uint32_t width = BigEndian32(bytes, 16), height = BigEndian32(bytes, 20);
  const uint32_t bound = kMaxDecodedSide;
  if (width < 1 || height < 1 || width > bound || height > bound) {
    ThrowInputError(source, what, "a PNG of 1 to " + std::to_string(bound) + " pixels a side",
                    std::to_string(width) + " x " + std::to_string(height));
  }
  cv::Mat image;
  try {
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())),
                         cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    image.release();
  }
  if (image.empty()) ThrowInputError(source, what, "a PNG file", "bytes that do not decode");
  return image;
}

}  // namespace

std::string DecodeBase64(const std::string& text, const std::string& source, const std::string& field) {
  const std::string expected = "base64 (A-Z, a-z, 0-9, +, /, padded with = to a multiple of 4 characters)";
  if (text.size() % 4 != 0) ThrowInputError(source, field, expected, std::to_string(text.size()) + " characters");
  const auto ends_with = [&](const char* tail, size_t length) {
    return text.size() >= length && text.compare(text.size() - length, length, tail) == 0;
  };
  const size_t padding = ends_with("==", 2) ? 2 : ends_with("=", 1) ? 1 : 0;
  std::string bytes;
  bytes.reserve(text.size() / 4 * 3);
  uint32_t bits = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const int digit = i >= text.size() - padding ? 0 : Base64Digit(text[i]);
    if (digit < 0) ThrowInputError(source, field, expected, "another character at " + std::to_string(i));
    bits = (bits << 6) | static_cast<uint32_t>(digit);
    if (i % 4 == 3) {
      for (int shift : {16, 8, 0}) bytes.push_back(static_cast<char>((bits >> shift) & 0xFF));
      bits = 0;
    }
  }
  bytes.resize(bytes.size() - padding);
  return bytes;
}

cv::Mat ColorImageAsRgb(const cv::Mat& decoded, const std::string& source) {
  if (decoded.depth() != CV_8U || (decoded.channels() != 3 && decoded.channels() != 4 && decoded.channels() != 1)) {
    ThrowInputError(source, "colour image", "an 8-bit grey, RGB or RGBA image", ImageTypeText(decoded));
  }
  cv::Mat rgb;
  const int code = decoded.channels() == 1   ? cv::COLOR_GRAY2RGB
                   : decoded.channels() == 4 ? cv::COLOR_BGRA2RGB
                                             : cv::COLOR_BGR2RGB;
  cv::cvtColor(decoded, rgb, code);
  return rgb;
}

void CheckDepthScale(double depth_scale, const std::string& source) {
  if (!std::isfinite(depth_scale) || depth_scale <= 0.0) {
    ThrowInputError(source, "depth_scale", "a finite positive scale (metres = value / scale)",
                    std::to_string(depth_scale));
  }
}

cv::Mat DepthImageAsMetres(const cv::Mat& decoded, double depth_scale, const std::string& source) {
  CheckDepthScale(depth_scale, source);
  if (decoded.type() != CV_16UC1) {
    ThrowInputError(source, "depth image", "a 16-bit single-channel PNG", ImageTypeText(decoded));
  }
  cv::Mat metres;
  decoded.convertTo(metres, CV_32F, 1.0 / depth_scale);
  return metres;
}

cv::Mat DecodeColorPng(const std::string& bytes, const std::string& source) {
  return ColorImageAsRgb(DecodePng(bytes, source, "colour image"), source);
}

cv::Mat DecodeDepthPng(const std::string& bytes, double depth_scale, const std::string& source) {
  CheckDepthScale(depth_scale, source);
  return DepthImageAsMetres(DecodePng(bytes, source, "depth image"), depth_scale, source);
}

RgbdFrame FrameOfImages(const cv::Mat& color, const cv::Mat& depth, const std::array<double, 4>& intrinsics,
                        const std::string& color_source, const std::string& depth_source, const std::string& name) {
  if (color.size() != depth.size()) {
    ThrowInputError(
        depth_source, "depth image size",
        std::to_string(color.cols) + "x" + std::to_string(color.rows) + " as the colour image " + color_source,
        std::to_string(depth.cols) + "x" + std::to_string(depth.rows));
  }
  RgbdFrame frame;
  frame.name = name;
  frame.color = color;
  frame.depth = depth;
  frame.camera = {intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3], color.cols, color.rows};
  frame.Check();
  return frame;
}

}  // namespace ecv
