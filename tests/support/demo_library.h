#pragma once

#include <string>

#include <gtest/gtest.h>

#include "support/test_data.h"

namespace ecv::test {

/// A test suite with the library of the three demo meshes in models/meshes (40 views at 0.9 m, as scripts/demo builds
/// it): the one ctest's demo_library fixture built (ECV_DEMO_LIBRARY), else built once for the suite through the CLI.
/// Tests read it and do not change it (copy it first); the suite's temporary directory is theirs to write into.
class DemoLibrarySuite : public ::testing::Test {
 protected:
  static void SetUpTestSuite();
  static void TearDownTestSuite();

  /// The demo frame: the YCB-Video prefix models/frame/000001.
  static std::string DemoFrame();

  static TemporaryDirectory* directory_;
  static std::string library_;  ///< the library's path
};

}  // namespace ecv::test
