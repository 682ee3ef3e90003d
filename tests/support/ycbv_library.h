#pragma once

#include <string>

#include <gtest/gtest.h>

#include "io/frame_io.h"
#include "support/test_data.h"

namespace ecv::test {

/// A test suite with the 7-model library of scripts/build_ycbv_library (the 6 google16k meshes moved into the
/// YCB-Video object frame and the YCB-Video banana, 40 views at 0.9 m): the one ctest's ycbv_library fixture built
/// (ECV_YCBV_LIBRARY), else built once for the suite through the CLI. Tests read it and do not change it (copy it
/// first); the suite's temporary directory is theirs to write into.
class YcbvLibrarySuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite();
  static void TearDownTestSuite();

  /// Adds the YCB-Video mesh of `name` (ycbv_subset/models) to the library at `path` as the 16-model library has it:
  /// without its texture (one grey model), symmetric (judged by ADD-S) when `symmetric`; a test failure otherwise.
  static void AddUntexturedModel(const std::string& name, bool symmetric, const std::string& path);

  static TemporaryDirectory* directory_;
  static std::string library_;  ///< the library's path
};

/// The ground truth of `model` in `frame`; throws std::runtime_error when the frame has none.
const GroundTruth& TruthOf(const LoadedFrame& frame, const std::string& model);

}  // namespace ecv::test
