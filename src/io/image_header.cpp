// Image headers: PNG (ISO/IEC 15948, 11.2.2 IHDR), JPEG (ITU-T T.81, B.2.2 frame header) and TIFF (TIFF 6.0, section
// 2: image file header and IFD; tags ImageWidth 256, ImageLength 257, BitsPerSample 258, SamplesPerPixel 277).

#include "io/image_header.h"

#include <algorithm>

namespace ecv {
namespace {

uint32_t Read(const std::string& bytes, size_t at, int count, bool big_endian) {
  uint32_t value = 0;
  for (int i = 0; i < count; ++i) {
    const auto byte = static_cast<unsigned char>(bytes[at + static_cast<size_t>(big_endian ? i : count - 1 - i)]);
    value = (value << 8) | byte;
  }
  return value;
}

ImageHeader PngHeader(const std::string& bytes) {
  ImageHeader header;
  if (bytes.size() < 26 || bytes.compare(12, 4, "IHDR") != 0) return header;
  header.width = Read(bytes, 16, 4, true);
  header.height = Read(bytes, 20, 4, true);
  const int bit_depth = static_cast<unsigned char>(bytes[24]), colour_type = static_cast<unsigned char>(bytes[25]);
  // Grey 1 channel, RGB 3; a palette, grey with alpha and RGBA decode to 4.
  const int channels = colour_type == 0 ? 1 : colour_type == 2 ? 3 : 4;
  header.bytes_per_pixel = channels * (bit_depth > 8 ? 2 : 1);
  header.format = ImageFormat::kPng;
  return header;
}

// The segments from the start of image up to the first start of frame (SOF0-SOF15 but DHT C4, JPG C8, DAC CC).
ImageHeader JpegHeader(const std::string& bytes) {
  ImageHeader header;
  size_t at = 2;
  while (at + 4 <= bytes.size()) {
    if (static_cast<unsigned char>(bytes[at]) != 0xFF) return header;
    const auto marker = static_cast<unsigned char>(bytes[at + 1]);
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      at += 2;
      continue;
    }
    if (marker == 0xDA || marker == 0xD9) return header;  // scan or end before any frame header
    const size_t length = Read(bytes, at + 2, 2, true);
    const bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (frame) {
      if (length < 8 || at + 10 > bytes.size()) return header;
      const int precision = static_cast<unsigned char>(bytes[at + 4]);
      header.height = Read(bytes, at + 5, 2, true);
      header.width = Read(bytes, at + 7, 2, true);
      const int components = static_cast<unsigned char>(bytes[at + 9]);
      header.bytes_per_pixel = std::max(1, std::min(components, 4)) * (precision > 8 ? 2 : 1);
      header.format = ImageFormat::kJpeg;
      return header;
    }
    at += 2 + length;
  }
  return header;
}

ImageHeader TiffHeader(const std::string& bytes, bool big_endian) {
  ImageHeader header;
  const size_t ifd = Read(bytes, 4, 4, big_endian);
  if (ifd < 8 || ifd + 2 > bytes.size()) return header;
  const size_t entries = Read(bytes, ifd, 2, big_endian);
  uint64_t bits = 1, samples = 1;
  for (size_t i = 0; i < entries && ifd + 2 + 12 * (i + 1) <= bytes.size(); ++i) {
    const size_t entry = ifd + 2 + 12 * i;
    const uint32_t tag = Read(bytes, entry, 2, big_endian), type = Read(bytes, entry + 2, 2, big_endian);
    const uint32_t count = Read(bytes, entry + 4, 4, big_endian);
    // SHORT (3) or LONG (4); the first value, inside the entry when it fits there (BitsPerSample of several samples
    // lies at an offset: the first of equal sizes).
    const int size = type == 3 ? 2 : type == 4 ? 4 : 0;
    if (size == 0 || count == 0) continue;
    size_t value_at = entry + 8;
    if (static_cast<uint64_t>(count) * static_cast<uint64_t>(size) > 4) {
      value_at = Read(bytes, entry + 8, 4, big_endian);
      if (value_at + static_cast<size_t>(size) > bytes.size()) continue;
    }
    const uint32_t value = Read(bytes, value_at, size, big_endian);
    if (tag == 256) header.width = value;
    if (tag == 257) header.height = value;
    if (tag == 258) bits = value;
    if (tag == 277) samples = value;
  }
  if (header.width == 0 || header.height == 0) return header;
  header.bytes_per_pixel = static_cast<int>(std::min<uint64_t>(samples * ((bits + 7) / 8), 1 << 20));
  header.bytes_per_pixel = std::max(header.bytes_per_pixel, 1);
  header.format = ImageFormat::kTiff;
  return header;
}

}  // namespace

const char* ToString(ImageFormat format) {
  switch (format) {
    case ImageFormat::kPng: return "PNG";
    case ImageFormat::kJpeg: return "JPG";
    case ImageFormat::kTiff: return "TIFF";
    case ImageFormat::kUnknown: break;
  }
  return "unknown";
}

ImageHeader ReadImageHeader(const std::string& bytes) {
  static const std::string kPngSignature = "\x89PNG\r\n\x1a\n";
  if (bytes.compare(0, kPngSignature.size(), kPngSignature) == 0) return PngHeader(bytes);
  if (bytes.size() >= 4 && static_cast<unsigned char>(bytes[0]) == 0xFF &&
      static_cast<unsigned char>(bytes[1]) == 0xD8) {
    return JpegHeader(bytes);
  }
  if (bytes.size() >= 8 &&
      (bytes.compare(0, 4, std::string("II*\0", 4)) == 0 || bytes.compare(0, 4, std::string("MM\0*", 4)) == 0)) {
    return TiffHeader(bytes, bytes[0] == 'M');
  }
  return {};
}

}  // namespace ecv
