#pragma once

#include <string>

namespace ecv {

/// Writes `bytes` to `path` through a temporary file beside it, renamed into place: a reader sees the old file or the
/// whole new one, never half of it. Throws InputError naming `path` when it cannot (the temporary file removed).
void WriteFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace ecv
