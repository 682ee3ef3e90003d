#include "io/atomic_file.h"

#include <filesystem>
#include <system_error>

#include "core/error.h"

namespace ecv {

AtomicFile::AtomicFile(const std::string& path) : path_(path), temporary_(path + ".tmp") {
  stream_.open(temporary_, std::ios::binary | std::ios::trunc);
  if (!stream_) ThrowInputError(path, "output", "a writable location");
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  std::error_code ignored;
  std::filesystem::remove(temporary_, ignored);
}

void AtomicFile::Commit() {
  if (!stream_.flush()) ThrowInputError(path_, "output", "a writable location with free space");
  stream_.close();
  std::error_code error;
  std::filesystem::rename(temporary_, path_, error);
  if (error) ThrowInputError(path_, "output", "a writable location", error.message());
  committed_ = true;
}

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  AtomicFile file(path);
  file.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  file.Commit();
}

}  // namespace ecv
