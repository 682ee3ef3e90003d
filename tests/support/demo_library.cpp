#include "support/demo_library.h"

#include <cstdlib>

namespace ecv::test {

TemporaryDirectory* DemoLibrarySuite::directory_ = nullptr;
std::string DemoLibrarySuite::library_;

void DemoLibrarySuite::SetUpTestSuite() {
  directory_ = new TemporaryDirectory();
  // Under ctest, the library its demo_library fixture built once for every test; run alone, a library of its own.
  if (const char* shared = std::getenv("ECV_DEMO_LIBRARY")) {
    library_ = shared;
    return;
  }
  library_ = directory_->File("library.sqlite");
  const CommandResult build = RunCli("modeldb build " + std::string(ECV_SOURCE_DIR) +
                                     "/models/meshes --views 40 --distance 0.9 --db " + library_);
  ASSERT_EQ(build.exit_code, 0) << build.output;
}

void DemoLibrarySuite::TearDownTestSuite() {
  delete directory_;
  directory_ = nullptr;
}

std::string DemoLibrarySuite::DemoFrame() {
  return std::string(ECV_SOURCE_DIR) + "/models/frame/000001";
}

}  // namespace ecv::test
