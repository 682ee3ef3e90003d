#pragma once

#include <fstream>
#include <string>

namespace ecv {

/// Writes `bytes` to `path` through a temporary file beside it, renamed into place: a reader sees the old file or the
/// whole new one, never half of it. Throws InputError naming `path` when it cannot (the temporary file removed).
void WriteFileAtomically(const std::string& path, const std::string& bytes);

/// A file written piece by piece (and patched by seeking back) under a temporary name beside `path`, renamed into
/// place by Commit: until then `path` is untouched, and a writer destroyed without Commit (an error, an exception)
/// removes the temporary file. For outputs too large to hold in memory (recordings).
class AtomicFile {
 public:
  /// Opens `path` + ".tmp" for binary writing; throws InputError naming `path` when it cannot.
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The temporary file's stream, for writing and seeking.
  std::ofstream& stream() { return stream_; }

  /// Flushes and renames the temporary file to `path`; throws InputError naming `path` when it cannot (no space).
  void Commit();

 private:
  std::string path_;
  std::string temporary_;
  std::ofstream stream_;
  bool committed_ = false;
};

}  // namespace ecv
