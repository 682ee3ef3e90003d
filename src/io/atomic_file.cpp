#include "io/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/error.h"

namespace ecv {

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  const std::string temporary = path + ".tmp";
  std::error_code ignored;
  {
    std::ofstream stream(temporary, std::ios::binary);
    if (!stream) ThrowInputError(path, "output", "a writable location");
    stream.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!stream.flush()) {
      stream.close();
      std::filesystem::remove(temporary, ignored);
      ThrowInputError(path, "output", "a writable location with free space");
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, ignored);
    ThrowInputError(path, "output", "a writable location", error.message());
  }
}

}  // namespace ecv
