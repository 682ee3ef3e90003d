#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ecv {

/// How a PCD file stores its points (its DATA line).
enum class PcdData { kAscii, kBinary, kBinaryCompressed };

/// One field of a PCD point: TYPE 'F' (float), 'I' (signed) or 'U' (unsigned), SIZE bytes, COUNT values.
struct PcdField {
  std::string name;
  char type = 'F';
  uint32_t size = 4;
  uint32_t count = 1;
  uint64_t offset = 0;  // bytes from the start of a point
};

/// What a checked PCD header says.
struct PcdLayout {
  std::vector<PcdField> fields;  // FIELDS, in order
  uint64_t width = 0, height = 0;
  uint64_t point_bytes = 0;  // sum over the fields of SIZE x COUNT
  PcdData data = PcdData::kAscii;
  uint64_t body_offset = 0;       // first byte after the DATA line
  uint64_t compressed_bytes = 0;  // binary_compressed: the LZF data's size, after the two 4-byte sizes

  uint64_t Points() const { return width * height; }
  /// The field called `name`, or nullptr.
  const PcdField* Find(const std::string& name) const;
};

/// Checks a PCD file's header and the size of its body. The header: comment lines (#), then VERSION, FIELDS, SIZE,
/// TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS and DATA in this order, each once (VERSION, COUNT and VIEWPOINT may
/// be left out); one SIZE, TYPE and COUNT per field; types F (SIZE 4 or 8), I or U (SIZE 1, 2, 4 or 8);
/// WIDTH x HEIGHT = POINTS. The body: ascii at least a byte per value; binary POINTS x point bytes; binary_compressed
/// its two sizes, the compressed bytes inside the file and the uncompressed ones exactly POINTS x point bytes. Throws
/// InputError naming the file, the field and what was expected.
PcdLayout CheckPcdFile(const std::string& path);

/// A PCD file's points, each `layout.point_bytes` long with its fields in order (little-endian, as binary PCD).
struct PcdCloud {
  PcdLayout layout;
  std::string bytes;

  /// Element `element` of `field` of point `point`, converted to double.
  double Value(uint64_t point, const PcdField& field, uint32_t element = 0) const;
  /// The 4 bytes of `field` of point `point` as an unsigned number (a packed colour); `field` must be 4 bytes.
  uint32_t Bits32(uint64_t point, const PcdField& field) const;
};

/// Reads a PCD file checked as CheckPcdFile: ascii, binary or binary_compressed (LZF, stored field by field). Throws
/// InputError naming the file and what is wrong (an ascii value that is no number, compressed data that does not
/// decompress to its size).
PcdCloud ReadPcdFile(const std::string& path);

}  // namespace ecv
