#pragma once

#include <cstddef>
#include <string>

namespace ecv {

/// Checks the structure of a MATLAB MAT-file of version 5 (the format of YCB-Video's -meta.mat) before matio reads
/// it: every data element, and every element inside a matrix, fits in what holds it; compressed elements inflate
/// whole (to at most 64 MB each); a matrix has no more values than it has bytes. matio sizes its allocations from
/// these counts alone (a 318-byte file asked for 4 GB). Version 7.3 files (HDF5) are refused. Throws InputError
/// naming `path` and what is wrong.
void CheckMatFileStructure(const unsigned char* data, size_t size, const std::string& path);

/// The same for the file at `path`, read whole: a regular file of at most 256 MB (InputError naming it otherwise).
void CheckMatFile(const std::string& path);

}  // namespace ecv
