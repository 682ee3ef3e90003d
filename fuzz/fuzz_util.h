#pragma once

// What the fuzz targets share: a scratch folder to write inputs into, inputs that fill several files, a small good
// frame to put beside the fuzzed file, and the rule that an InputError is the one expected answer to bad input.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace ecv::fuzz {

/// Joins the files of an input that fills several (make_corpus.sh and ecv_fuzz_seeds join seeds with it).
inline const std::string kPartSeparator = "\n--ecvfuzz-part--\n";

/// An empty folder of this process under the temporary directory ($TMPDIR), removed at exit.
const std::filesystem::path& ScratchDir();

/// Writes `bytes` to `path`, replacing it.
void WriteFile(const std::filesystem::path& path, const std::string& bytes);

/// The input cut at kPartSeparator into `count` parts: missing parts are empty, the last keeps any further separator.
std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t count);

/// A good 32 x 24 frame: an 8-bit RGB PNG and a 16-bit depth PNG (values 8000-12000, 0.8-1.2 m at YCB-Video's
/// 10000 per metre).
void WriteGoodImages(const std::filesystem::path& color_png, const std::filesystem::path& depth_png);

/// Runs `read`. An InputError is how a reader answers bad input (printed when ECV_FUZZ_VERBOSE is set, to see how far
/// a seed gets); any other exception escapes to libFuzzer, which reports it as a finding, as it does crashes and
/// sanitizer reports.
template <typename Read>
void ExpectOnlyInputErrors(Read read) {
  try {
    read();
  } catch (const InputError& error) {
    if (std::getenv("ECV_FUZZ_VERBOSE") != nullptr) std::fprintf(stderr, "InputError: %s\n", error.what());
  }
}

}  // namespace ecv::fuzz
