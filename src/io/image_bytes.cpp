#include "io/image_bytes.h"

#include <cmath>
#include <cstdint>
#include <sstream>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/files.h"
#include "io/image_header.h"

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

// `bytes` decoded with `flags` once `header` (theirs) has been checked against the bounds.
cv::Mat DecodeChecked(const std::string& bytes, const ImageHeader& header, const std::string& source,
                      const std::string& what, int flags) {
  const uint64_t bound = kMaxDecodedSide;
  const std::string format = ToString(header.format);
  if (header.width < 1 || header.height < 1 || header.width > bound || header.height > bound) {
    ThrowInputError(source, what, "a " + format + " of 1 to " + std::to_string(bound) + " pixels a side",
                    std::to_string(header.width) + " x " + std::to_string(header.height));
  }
  const uint64_t decoded = header.width * header.height * static_cast<uint64_t>(header.bytes_per_pixel);
  if (decoded > kMaxDecodedBytes) {
    ThrowInputError(source, what,
                    "a " + format + " of at most " + std::to_string(kMaxDecodedBytes >> 20) + " MB decoded",
                    std::to_string(header.width) + " x " + std::to_string(header.height) + " pixels of " +
                        std::to_string(header.bytes_per_pixel) + " bytes");
  }
  cv::Mat image;
  try {
    image = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())), flags);
  } catch (const cv::Exception& error) {
    if (error.code == cv::Error::StsNoMem) throw;  // out of memory, not bad bytes: the command names it
    image.release();
  }
  if (image.empty()) ThrowInputError(source, what, "a " + format + " file", "bytes that do not decode");
  return image;
}

// The PNG in `bytes`, decoded as it is stored, after its header has been checked.
cv::Mat DecodePng(const std::string& bytes, const std::string& source, const char* what) {
  const ImageHeader header = ReadImageHeader(bytes);
  if (header.format != ImageFormat::kPng) ThrowInputError(source, what, "a PNG file", "no PNG header");
  return DecodeChecked(bytes, header, source, what, cv::IMREAD_UNCHANGED);
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

cv::Mat DecodeImage(const std::string& bytes, const std::string& source, const std::string& what, int flags) {
  const ImageHeader header = ReadImageHeader(bytes);
  if (header.format == ImageFormat::kUnknown) {
    ThrowInputError(source, what, "a PNG, JPG or TIFF image", bytes.empty() ? "an empty file" : "no such header");
  }
  return DecodeChecked(bytes, header, source, what, flags);
}

cv::Mat ReadImageFile(const std::string& path, const std::string& what, int flags) {
  return DecodeImage(ReadFileBytes(path, what, kMaxImageFileBytes), path, what, flags);
}

void CheckDepthScale(double depth_scale, const std::string& source, const std::string& field) {
  if (!std::isfinite(depth_scale) || depth_scale <= 0.0) {
    std::ostringstream given;
    given << depth_scale;
    ThrowInputError(source, field, "a finite positive scale (metres = value / scale)", given.str());
  }
}

void CheckIntrinsics(const std::array<double, 4>& intrinsics, const std::string& source, const std::string& field) {
  const auto [fx, fy, cx, cy] = intrinsics;
  if (std::isfinite(fx) && fx > 0.0 && std::isfinite(fy) && fy > 0.0 && std::isfinite(cx) && std::isfinite(cy)) return;
  std::ostringstream given;
  given << "fx " << fx << ", fy " << fy << ", cx " << cx << ", cy " << cy;
  ThrowInputError(source, field, "fx and fy finite and positive, cx and cy finite (pixels)", given.str());
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
        name, "depth image size",
        std::to_string(color.cols) + "x" + std::to_string(color.rows) + " as the colour image (" + color_source + ")",
        std::to_string(depth.cols) + "x" + std::to_string(depth.rows) + " (" + depth_source + ")");
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
