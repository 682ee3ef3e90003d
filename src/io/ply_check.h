#pragma once

#include <string>

namespace ecv {

/// Checks a PLY file's structure before an importer trusts it: a header (from "ply" to a line "end_header") of format
/// ascii, binary_little_endian or
/// binary_big_endian with elements of scalar and list properties, among them vertex and face, each with a count; as
/// many values after it as the header counts; finite vertex coordinates; lists of at most 1000 values; every face's
/// vertex index below the vertex count; a regular file of at most 1 GB. Throws InputError naming the file, the element
/// and what was expected.
void CheckPlyFile(const std::string& path);

}  // namespace ecv
