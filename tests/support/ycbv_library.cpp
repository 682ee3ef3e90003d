#include "support/ycbv_library.h"

#include <cstdlib>
#include <stdexcept>

#include "io/mesh_io.h"
#include "io/pose_io.h"

namespace ecv::test {

TemporaryDirectory* YcbvLibrarySuite::directory_ = nullptr;
std::string YcbvLibrarySuite::library_;

void YcbvLibrarySuite::SetUpTestSuite() {
  directory_ = new TemporaryDirectory();
  if (const char* shared = std::getenv("ECV_YCBV_LIBRARY")) {
    library_ = shared;
    return;
  }
  library_ = directory_->File("ycbv.sqlite");
  const std::string data = DataPath("ycbv_subset");
  for (const auto& [name, object_from_mesh] : ReadTransformTable(data + "/derived/google16k_to_ycbv.txt")) {
    const std::string pose = directory_->File(name + ".json");
    WriteJsonFile(pose, {{"object_from_mesh", PoseToJson(object_from_mesh)}});
    const CommandResult build =
        RunCli("modeldb build " + data + "/ycb_google16k_textured/" + name + "_textured.obj --name " + name +
               " --object-from-mesh " + pose + " --views 40 --distance 0.9 --db " + library_);
    ASSERT_EQ(build.exit_code, 0) << build.output;
  }
  const CommandResult banana = RunCli("modeldb build " + data +
                                      "/models/011_banana/textured_simple.obj --name 011_banana "
                                      "--views 40 --distance 0.9 --db " +
                                      library_);
  ASSERT_EQ(banana.exit_code, 0) << banana.output;
}

void YcbvLibrarySuite::AddUntexturedModel(const std::string& name, bool symmetric, const std::string& path) {
  const CommandResult build =
      RunCli("modeldb build " + DataPath("ycbv_subset/models/" + name + "/textured_simple.obj") + " --name " + name +
             " --allow-missing-textures --views 40 --distance 0.9 --db " + path + (symmetric ? " --symmetric" : ""));
  ASSERT_EQ(build.exit_code, 0) << build.output;
}

void YcbvLibrarySuite::TearDownTestSuite() {
  delete directory_;
  directory_ = nullptr;
}

const GroundTruth& TruthOf(const LoadedFrame& frame, const std::string& model) {
  for (const GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name == model) return truth;
  }
  throw std::runtime_error("no ground truth of " + model);
}

}  // namespace ecv::test
