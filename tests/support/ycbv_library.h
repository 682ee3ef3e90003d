#pragma once

#include <string>

#include <gtest/gtest.h>

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

  static TemporaryDirectory* directory_;
  static std::string library_;  ///< the library's path
};

}  // namespace ecv::test
