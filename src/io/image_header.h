#pragma once

// The pixel size an image file's header claims, read before anything decodes the file: a file of a few kilobytes can
// claim a size whose decoding takes gigabytes.

#include <cstdint>
#include <string>

namespace ecv {

/// The image formats whose header ecvpose reads (those its frames and textures come in).
enum class ImageFormat { kUnknown, kPng, kJpeg, kTiff };

/// "PNG", "JPG", "TIFF" or "unknown".
const char* ToString(ImageFormat format);

/// What an image file's header says.
struct ImageHeader {
  ImageFormat format = ImageFormat::kUnknown;
  uint64_t width = 0, height = 0;  ///< pixels; 0 where the header gives none
  int bytes_per_pixel = 0;         ///< of the image decoded unchanged (channels x bytes per channel), at least 1
};

/// The header of the PNG (IHDR chunk), JPEG (the first SOF marker) or TIFF (the first image's tags) file whose bytes
/// are `bytes`; format kUnknown for other bytes, or a header cut short or without its size.
ImageHeader ReadImageHeader(const std::string& bytes);

}  // namespace ecv
