#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ecv {

/// SHA-256 (FIPS 180-4) computed incrementally; identifies the content a library model was built from
/// and lets `verify` detect stored descriptors that changed.
class Sha256 {
 public:
  Sha256();

  /// Appends `size` bytes at `data`.
  void Update(const void* data, size_t size);

  /// The digest as 64 lower-case hexadecimal digits; the object must not be updated afterwards.
  std::string HexDigest();

 private:
  void Compress(const uint8_t* block);

  uint32_t state_[8];
  uint8_t buffer_[64];
  size_t buffered_ = 0;
  uint64_t total_bytes_ = 0;
};

/// SHA-256 of `size` bytes.
std::string Sha256Hex(const void* data, size_t size);

/// SHA-256 of the contents of the files, in order (each file's bytes appended to the last's). Throws
/// InputError naming the file that cannot be read.
std::string Sha256OfFiles(const std::vector<std::string>& paths);

}  // namespace ecv
