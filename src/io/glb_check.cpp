// The lengths of a binary glTF file checked against its size before an importer allocates what they say.

#include "io/glb_check.h"

#include <cstdint>
#include <fstream>

#include "core/error.h"

namespace ecv {
namespace {

uint32_t LittleEndian32(const unsigned char* bytes) {
  return uint32_t{bytes[0]} | uint32_t{bytes[1]} << 8 | uint32_t{bytes[2]} << 16 | uint32_t{bytes[3]} << 24;
}

}  // namespace

void CheckGlbFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) ThrowInputError(path, "mesh", "a readable file");
  const auto file_bytes = static_cast<uint64_t>(file.tellg());
  unsigned char header[20] = {};
  file.seekg(0);
  file.read(reinterpret_cast<char*>(header), sizeof(header));
  if (file.gcount() < 12 || std::string(reinterpret_cast<char*>(header), 4) != "glTF") return;
  const uint32_t version = LittleEndian32(header + 4), length = LittleEndian32(header + 8);
  const std::string size_text = std::to_string(file_bytes) + " bytes";
  if (length > file_bytes)
    ThrowInputError(path, "GLB length", "at most the file's " + size_text, std::to_string(length));
  if (version == 1) {  // glTF 1.0: content length and format at bytes 12 and 16, the content after the header
    const uint32_t content = LittleEndian32(header + 12);
    if (file.gcount() < 20 || length < 20 || content > length - 20) {
      ThrowInputError(path, "GLB content length",
                      "at most the " + std::to_string(length < 20 ? 0 : length - 20) + " bytes after the header",
                      std::to_string(content));
    }
    return;
  }
  uint64_t at = 12;
  for (int index = 0; at + 8 <= length; ++index) {
    unsigned char chunk[8];
    file.clear();
    file.seekg(static_cast<std::streamoff>(at));
    if (!file.read(reinterpret_cast<char*>(chunk), sizeof(chunk))) {
      ThrowInputError(path, "GLB chunk " + std::to_string(index), "a chunk header", "the end of the file");
    }
    const uint64_t chunk_bytes = LittleEndian32(chunk), room = length - at - 8;
    if (chunk_bytes > room) {
      ThrowInputError(path, "GLB chunk " + std::to_string(index) + " length",
                      "at most the " + std::to_string(room) + " bytes left of the file's length",
                      std::to_string(chunk_bytes));
    }
    at += 8 + chunk_bytes;
  }
}

}  // namespace ecv
