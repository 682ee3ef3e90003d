#pragma once

#include <string>
#include <vector>

#include "ecv/primitives.h"

namespace ecv {

/// Writes primitives as a binary little-endian PLY point cloud: x y z (metres), nx ny nz (orientation),
/// red green blue (their colour), and a uchar "type" (0 segment, 1 texlet). Written to a temporary file,
/// then renamed; throws InputError if the location is not writable.
void WritePrimitivesPly(const std::string& path, const std::vector<Primitive>& primitives);

/// Reads a PLY written by WritePrimitivesPly (for round trips and tools).
std::vector<Primitive> ReadPrimitivesPly(const std::string& path);

}  // namespace ecv
