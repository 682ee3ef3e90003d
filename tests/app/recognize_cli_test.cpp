// `ecvpose recognize` as a user runs it: errors a library's missing files cause.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "support/test_data.h"

namespace ecv {
namespace {

// A library built without its meshes reads them when a Recognizer is made (for verification renders), on worker
// threads: a mesh file gone since the library was built is an error naming it, raised from whichever thread read it.
TEST(RecognizeCli, AMeshFileGoneSinceALibraryWithoutMeshesWasBuiltIsNamed) {
  const test::TemporaryDirectory directory;
  const std::filesystem::path meshes = directory.File("meshes");
  std::filesystem::copy(std::string(ECV_SOURCE_DIR) + "/models/meshes", meshes,
                        std::filesystem::copy_options::recursive);
  const std::string library = directory.File("library.sqlite");
  const test::CommandResult build =
      test::RunCli("modeldb build " + meshes.string() + " --views 4 --distance 0.9 --no-stored-mesh --db " + library);
  ASSERT_EQ(build.exit_code, 0) << build.output;
  EXPECT_NE(build.output.find("mesh not stored"), std::string::npos) << build.output;
  const std::filesystem::path gone = meshes / "004_sugar_box" / "004_sugar_box.obj";
  ASSERT_TRUE(std::filesystem::remove(gone));

  const test::CommandResult run = test::RunCli("recognize --db " + library + " --threads 2 " +
                                               std::string(ECV_SOURCE_DIR) + "/models/frame/000001");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(gone.string()), std::string::npos) << run.output;
}

}  // namespace
}  // namespace ecv
