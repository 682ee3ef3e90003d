// The element structure of MAT-files of version 5 ("MAT-File Format", MathWorks: a 128-byte header, then tagged data
// elements of (type, byte count); a type word with its upper 16 bits set is a small element, its byte count there and
// its data in the tag's second word).

#include "io/mat_check.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include <zlib.h>

#include "core/error.h"
#include "io/files.h"

namespace ecv {
namespace {

constexpr uint32_t kMiInt32 = 5, kMiUint32 = 6, kMiMatrix = 14, kMiCompressed = 15;
constexpr uint32_t kSparseClass = 5;
constexpr size_t kHeaderBytes = 128;
constexpr size_t kMaxInflatedBytes = size_t{64} << 20;
constexpr int kMaxDepth = 16;  // matrices within matrices (cells, structs)

class ElementReader {
 public:
  ElementReader(bool swap, std::string path) : swap_(swap), path_(std::move(path)) {}

  uint32_t Word(const unsigned char* at) const {
    uint32_t value;
    std::memcpy(&value, at, sizeof(value));
    return swap_ ? __builtin_bswap32(value) : value;
  }

  [[noreturn]] void Fail(const std::string& what, size_t offset) const {
    ThrowInputError(path_, "MAT-file element at byte " + std::to_string(offset), "a well-formed version 5 MAT-file",
                    what);
  }

  // The body of a matrix: its sub-elements, each within it; the array flags and dimensions first, with no more values
  // than the matrix has bytes (offsets are of the body in its own buffer, for the messages).
  void CheckMatrix(const unsigned char* body, size_t size, size_t offset, int depth) const {
    if (depth > kMaxDepth) Fail("matrices nested deeper than " + std::to_string(kMaxDepth), offset);
    size_t at = 0;
    int index = 0;
    uint32_t array_class = 0;
    while (at + 8 <= size) {
      uint32_t type = Word(body + at), bytes = Word(body + at + 4);
      const bool small = (type >> 16) != 0;
      if (small) {
        bytes = type >> 16;
        type &= 0xffffU;
      }
      const size_t room = small ? 4 : size - at - 8;
      if (bytes > room) {
        Fail("an element of " + std::to_string(bytes) + " bytes where " + std::to_string(room) + " remain",
             offset + at);
      }
      const unsigned char* data = body + at + (small ? 4 : 8);
      if (index == 0) {
        if (type != kMiUint32 || bytes != 8) Fail("a matrix without its array flags", offset + at);
        array_class = Word(data) & 0xffU;
      } else if (index == 1) {
        if (type != kMiInt32 || bytes % 4 != 0 || bytes < 8) Fail("a matrix without its dimensions", offset + at);
        double values = 1.0;
        for (uint32_t d = 0; d < bytes / 4; ++d) values *= static_cast<double>(Word(data + 4 * d));
        // A sparse matrix stores its non-zeros only, and one column index per column.
        const double limit = static_cast<double>(size);
        const double claimed = array_class == kSparseClass ? static_cast<double>(Word(data + 4)) : values;
        if (claimed > limit) {
          Fail("a matrix of " + std::to_string(claimed) + " values in " + std::to_string(size) + " bytes", offset + at);
        }
      } else if (type == kMiMatrix && !small) {
        CheckMatrix(data, bytes, offset + at + 8, depth + 1);
      }
      ++index;
      at += small ? 8 : 8 + ((static_cast<size_t>(bytes) + 7) & ~size_t{7});
    }
    if (index < 2) Fail("a matrix without its array flags and dimensions", offset);
  }

  // A top-level matrix element, compressed or not, at `offset` of the file.
  void CheckTopLevel(uint32_t type, const unsigned char* data, size_t bytes, size_t offset) const {
    if (type == kMiMatrix) return CheckMatrix(data, bytes, offset + 8, 0);
    if (type != kMiCompressed) Fail("an element of type " + std::to_string(type) + " at the top level", offset);
    std::vector<unsigned char> inflated = Inflate(data, bytes, offset);
    if (inflated.size() < 8 || Word(inflated.data()) != kMiMatrix)
      Fail("a compressed element without a matrix", offset);
    const uint32_t size = Word(inflated.data() + 4);
    if (size > inflated.size() - 8) {
      Fail("a compressed matrix of " + std::to_string(size) + " bytes that inflates to " +
               std::to_string(inflated.size() - 8),
           offset);
    }
    CheckMatrix(inflated.data() + 8, size, offset, 0);
  }

 private:
  std::vector<unsigned char> Inflate(const unsigned char* data, size_t bytes, size_t offset) const {
    z_stream stream{};
    if (inflateInit(&stream) != Z_OK) Fail("a compressed element zlib cannot open", offset);
    std::vector<unsigned char> out;
    stream.next_in = const_cast<unsigned char*>(data);
    stream.avail_in = static_cast<uInt>(bytes);
    int status = Z_OK;
    while (status == Z_OK) {
      if (out.size() >= kMaxInflatedBytes) break;
      const size_t done = out.size();
      out.resize(std::min(kMaxInflatedBytes, done + (size_t{1} << 16)));
      stream.next_out = out.data() + done;
      stream.avail_out = static_cast<uInt>(out.size() - done);
      status = inflate(&stream, Z_NO_FLUSH);
      out.resize(out.size() - stream.avail_out);
      if (status == Z_BUF_ERROR && stream.avail_in == 0) break;
    }
    inflateEnd(&stream);
    if (status != Z_STREAM_END) {
      Fail(out.size() >= kMaxInflatedBytes ? "a compressed element of more than 64 MB"
                                           : "a compressed element that does not inflate whole",
           offset);
    }
    return out;
  }

  bool swap_;
  std::string path_;
};

}  // namespace

void CheckMatFileStructure(const unsigned char* data, size_t size, const std::string& path) {
  // Version 4 files have no text header, and matio trusts their counts alone (an 80-byte file took 2 GB).
  if (size < 6 || std::memcmp(data, "MATLAB", 6) != 0 || size < kHeaderBytes) {
    ThrowInputError(
        path, "header", "a MATLAB MAT-file of version 5 or later (a 128-byte header \"MATLAB ...\")",
        size >= 6 && std::memcmp(data, "MATLAB", 6) == 0 ? std::to_string(size) + " bytes" : "no such header");
  }
  const unsigned char* endian = data + 126;
  if (!((endian[0] == 'I' && endian[1] == 'M') || (endian[0] == 'M' && endian[1] == 'I'))) {
    ThrowInputError(path, "header", "the byte order mark IM or MI at byte 126");
  }
  const bool swap = endian[0] == 'M';
  const unsigned version = swap ? (unsigned{data[124]} << 8 | data[125]) : (unsigned{data[125]} << 8 | data[124]);
  // 7.3 files are HDF5 files, which the HDF5 library reads by trusting them (it leaked on fuzzed ones); YCB-Video's are
  // version 5, as scipy and MATLAB's -v7 write them.
  if (version == 0x0200) {
    ThrowInputError(path, "header", "a version 5 MAT-file (MATLAB: save -v7; scipy.io.savemat)",
                    "version 7.3 (HDF5), which ecvpose does not read");
  }
  if (version != 0x0100) ThrowInputError(path, "header", "version 0x0100 (5)", std::to_string(version));
  const ElementReader reader(swap, path);
  size_t at = kHeaderBytes;
  while (at + 8 <= size) {
    const uint32_t type = reader.Word(data + at), bytes = reader.Word(data + at + 4);
    if (bytes > size - at - 8) {
      reader.Fail(
          "an element of " + std::to_string(bytes) + " bytes where " + std::to_string(size - at - 8) + " remain", at);
    }
    reader.CheckTopLevel(type, data + at + 8, bytes, at);
    // Compressed elements follow one another unpadded; matrices are padded to 8 bytes.
    at += 8 + (type == kMiCompressed ? size_t{bytes} : (size_t{bytes} + 7) & ~size_t{7});
  }
}

void CheckMatFile(const std::string& path) {
  constexpr size_t kMaxBytes = size_t{256} << 20;  // a YCB-Video meta file holds a few KB
  const std::string bytes = ReadFileBytes(path, "meta", kMaxBytes);
  CheckMatFileStructure(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), path);
}

}  // namespace ecv
