#pragma once

#include <string>

namespace ecv {

/// Checks a binary glTF file (GLB, glTF 2.0 section 4.4: a 12-byte header "glTF", version, length; then chunks of
/// length, type and data) before an importer trusts its lengths: the header's length within the file and each
/// chunk within that length. The binary form of glTF 1.0 (version 1: a 20-byte header with the JSON content's
/// length) likewise. assimp allocates what a chunk length says (0xFFFFFFF0: 4 GB) before reading it. A file that
/// does not start with "glTF" is left alone. Throws InputError naming the file, the field and what was expected.
void CheckGlbFile(const std::string& path);

}  // namespace ecv
