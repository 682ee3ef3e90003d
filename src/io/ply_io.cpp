#include "io/ply_io.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/files.h"

namespace ecv {
namespace {

constexpr const char* kHeaderEnd = "end_header";
constexpr size_t kRecordSize = 6 * sizeof(float) + 4;  // x y z nx ny nz, r g b, type

unsigned char ColorByte(float value) {
  return static_cast<unsigned char>(std::lround(std::clamp(value, 0.0F, 1.0F) * 255.0F));
}

}  // namespace

void WritePrimitivesPly(const std::string& path, const std::vector<Primitive>& primitives) {
  std::ostringstream stream(std::ios::binary);
  {
    stream << "ply\nformat binary_little_endian 1.0\ncomment ecvpose ECV primitives (metres)\n"
           << "element vertex " << primitives.size() << '\n'
           << "property float x\nproperty float y\nproperty float z\n"
           << "property float nx\nproperty float ny\nproperty float nz\n"
           << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
           << "property uchar type\n"
           << kHeaderEnd << '\n';
    for (const Primitive& primitive : primitives) {
      char record[kRecordSize];
      std::memcpy(record, primitive.position.data(), 3 * sizeof(float));
      std::memcpy(record + 3 * sizeof(float), primitive.orientation.data(), 3 * sizeof(float));
      unsigned char* tail = reinterpret_cast<unsigned char*>(record + 6 * sizeof(float));
      for (int k = 0; k < 3; ++k) tail[k] = ColorByte(primitive.color[k]);
      tail[3] = static_cast<unsigned char>(primitive.type);
      stream.write(record, kRecordSize);
    }
  }
  WriteFileAtomically(path, stream.str());
}

std::vector<Primitive> ReadPrimitivesPly(const std::string& path) {
  RequireRegularFile(path, "PLY");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) ThrowInputError(path, "PLY", "a readable file");
  std::string line;
  size_t count = 0;
  bool binary = false;
  while (std::getline(stream, line) && line != kHeaderEnd) {
    std::istringstream fields(line);
    std::string keyword, second;
    fields >> keyword >> second;
    if (keyword == "format") binary = second == "binary_little_endian";
    if (keyword == "element" && second == "vertex") fields >> count;
  }
  if (!binary || line != kHeaderEnd) ThrowInputError(path, "header", "a binary PLY written by ecvpose");
  // The count against the bytes that follow, before anything is allocated for it.
  const std::streamoff body = stream.tellg();
  stream.seekg(0, std::ios::end);
  const std::streamoff records = (stream.tellg() - body) / static_cast<std::streamoff>(kRecordSize);
  stream.seekg(body);
  if (static_cast<std::streamoff>(count) > records) {
    ThrowInputError(path, "element vertex", std::to_string(records) + " vertices (the records that follow)",
                    std::to_string(count));
  }
  std::vector<Primitive> primitives(count);
  for (Primitive& primitive : primitives) {
    char record[kRecordSize];
    if (!stream.read(record, kRecordSize)) ThrowInputError(path, "vertex data", std::to_string(count) + " vertices");
    std::memcpy(primitive.position.data(), record, 3 * sizeof(float));
    std::memcpy(primitive.orientation.data(), record + 3 * sizeof(float), 3 * sizeof(float));
    const auto* tail = reinterpret_cast<const unsigned char*>(record + 6 * sizeof(float));
    primitive.color = Eigen::Vector3f(tail[0], tail[1], tail[2]) / 255.0F;
    primitive.type = tail[3] == 0 ? PrimitiveType::kSegment : PrimitiveType::kTexlet;
  }
  return primitives;
}

}  // namespace ecv
