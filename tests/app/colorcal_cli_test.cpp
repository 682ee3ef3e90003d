// `ecvpose colorcal` (issue 8): fit from an RGB-triplet CSV with a known matrix, automatic fit on the demo frame at
// the ground-truth pose, on several frames pooled, with the diagonal form; show, clear, and the errors for an unknown
// model and a missing pose.

#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "colorcal/pairs_csv.h"
#include "modeldb/model_database.h"
#include "support/test_data.h"

namespace ecv {
namespace {

const std::string kModel = "006_mustard_bottle";
const std::string kSource = ECV_SOURCE_DIR;
const std::string kFrame = kSource + "/models/frame/000001";

class ColorcalCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = new test::TemporaryDirectory();
    library_ = directory_->File("lib.sqlite");
    const std::string mesh_dir = kSource + "/models/meshes/" + kModel;
    const test::CommandResult built =
        test::RunCli("modeldb build " + mesh_dir + "/" + kModel + ".obj --name " + kModel + " --object-from-mesh " +
                     mesh_dir + "/object_from_mesh.json --views 4 --db " + library_);
    ASSERT_EQ(built.exit_code, 0) << built.output;
  }
  static void TearDownTestSuite() {
    delete directory_;
    directory_ = nullptr;
  }
  static std::optional<ColorMatrixRecord> StoredMatrix() {
    return ModelDatabase(library_, OpenMode::kReadOnly).GetColorMatrix(kModel);
  }

  static test::TemporaryDirectory* directory_;
  static std::string library_;
};

test::TemporaryDirectory* ColorcalCliTest::directory_ = nullptr;
std::string ColorcalCliTest::library_;

// The two numbers of the "mean colour error: BEFORE -> AFTER" line.
// (Parsed by hand: GCC 12 warns inside <regex> under the sanitizer build, and warnings are errors there.)
std::vector<double> MeanErrors(const std::string& output) {
  const std::string label = "mean colour error: ";
  const size_t at = output.find(label);
  if (at == std::string::npos) return {};
  double before = 0.0, after = 0.0;
  if (std::sscanf(output.c_str() + at + label.size(), "%lf -> %lf", &before, &after) != 2) return {};
  return {before, after};
}

TEST_F(ColorcalCliTest, FitRecoversAKnownMatrixFromTriplets) {
  Eigen::Matrix3d truth;
  truth << 0.9, 0.05, 0.02, 0.03, 0.8, 0.04, 0.01, 0.06, 0.7;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(0.05, 0.95);
  std::vector<ColorPair> pairs(30);
  for (ColorPair& pair : pairs) {
    pair.model = Eigen::Vector3d(uniform(random), uniform(random), uniform(random));
    pair.scene = truth * pair.model;  // stays inside [0, 1] for these values, so no clamping
  }
  const std::string csv = directory_->File("triplets.csv");
  WriteColorPairsCsv(csv, pairs);

  for (const char* method : {"lsq", "ransac", "irls"}) {
    SCOPED_TRACE(method);
    const test::CommandResult result =
        test::RunCli("colorcal fit --db " + library_ + " --model " + kModel + " --pairs " + csv + " --method " +
                     method + " --form full --no-keep-brightness");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    EXPECT_NE(result.output.find("inliers: 30/30"), std::string::npos) << result.output;
    const std::optional<ColorMatrixRecord> stored = StoredMatrix();
    ASSERT_TRUE(stored);
    EXPECT_LT((stored->model_to_scene - truth).cwiseAbs().maxCoeff(), 1e-6) << stored->model_to_scene;
    EXPECT_LT(stored->rms, 1e-6);
    EXPECT_EQ(stored->source, "pairs:" + csv);
  }
}

TEST_F(ColorcalCliTest, AutoFitsOnTheFrameThenShowAndClear) {
  const test::CommandResult fitted =
      test::RunCli("colorcal auto --db " + library_ + " --model " + kModel + " " + kFrame + " --no-keep-brightness");
  ASSERT_EQ(fitted.exit_code, 0) << fitted.output;
  const std::vector<double> errors = MeanErrors(fitted.output);
  ASSERT_EQ(errors.size(), 2U) << fitted.output;
  EXPECT_LT(errors[1], 0.8 * errors[0]) << fitted.output;

  const std::optional<ColorMatrixRecord> stored = StoredMatrix();
  ASSERT_TRUE(stored);
  EXPECT_EQ(stored->source, "auto:frame/000001");
  EXPECT_FALSE(stored->model_to_scene.isApprox(Eigen::Matrix3d::Identity(), 1e-3)) << stored->model_to_scene;

  const test::CommandResult shown = test::RunCli("colorcal show --db " + library_ + " --model " + kModel);
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  char first_row[128];
  std::snprintf(first_row, sizeof(first_row), "A = [%.6f %.6f %.6f", stored->model_to_scene(0, 0),
                stored->model_to_scene(0, 1), stored->model_to_scene(0, 2));
  EXPECT_NE(shown.output.find(first_row), std::string::npos) << first_row << " not in\n" << shown.output;
  EXPECT_NE(shown.output.find("source: auto:frame/000001"), std::string::npos) << shown.output;

  const test::CommandResult cleared = test::RunCli("colorcal clear --db " + library_ + " --model " + kModel);
  ASSERT_EQ(cleared.exit_code, 0) << cleared.output;
  EXPECT_FALSE(StoredMatrix());
  const test::CommandResult empty = test::RunCli("colorcal show --db " + library_ + " --model " + kModel);
  EXPECT_EQ(empty.exit_code, 0) << empty.output;
  EXPECT_NE(empty.output.find("no colour matrix"), std::string::npos) << empty.output;
}

// Several frames: the pairs of each are pooled into one fit, and the stored source names every frame. The defaults
// store per-channel gains scaled to keep the brightness (the frames are darker than the texture: scale above 1).
TEST_F(ColorcalCliTest, AutoPoolsThePairsOfSeveralFrames) {
  const std::string first = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  const std::string second = test::DataPath("ycbv_subset/Example-Scenes/0001/000011");
  const test::CommandResult single =
      test::RunCli("colorcal auto --db " + library_ + " --model " + kModel + " " + first);
  ASSERT_EQ(single.exit_code, 0) << single.output;
  const test::CommandResult pooled = test::RunCli("colorcal auto --db " + library_ + " --model " + kModel + " " +
                                                  first + " " + second);  // defaults: diagonal, brightness kept
  ASSERT_EQ(pooled.exit_code, 0) << pooled.output;
  EXPECT_NE(pooled.output.find(kModel + " in 0001/000001: "), std::string::npos) << pooled.output;
  EXPECT_NE(pooled.output.find(kModel + " in 0001/000011: "), std::string::npos) << pooled.output;
  EXPECT_NE(pooled.output.find("form: diagonal"), std::string::npos) << pooled.output;
  EXPECT_NE(pooled.output.find("brightness kept: A scaled by 1."), std::string::npos) << pooled.output;
  // Each frame gives up to 2000 pairs: the pooled fit counts both frames' pairs.
  const size_t at = pooled.output.find("inliers: ");
  ASSERT_NE(at, std::string::npos) << pooled.output;
  int inliers = 0, total = 0;
  ASSERT_EQ(std::sscanf(pooled.output.c_str() + at, "inliers: %d/%d", &inliers, &total), 2) << pooled.output;
  EXPECT_GT(total, 2000) << pooled.output;
  const std::optional<ColorMatrixRecord> stored = StoredMatrix();
  ASSERT_TRUE(stored);
  EXPECT_EQ(stored->source, "auto:0001/000001+0001/000011");
  const Eigen::Matrix3d& A = stored->model_to_scene;
  EXPECT_EQ(A(0, 1), 0.0);
  EXPECT_EQ(A(1, 0), 0.0);
  EXPECT_EQ(A(2, 0), 0.0);
  EXPECT_GT(A.diagonal().minCoeff(), 0.0) << A;  // gains, not the full form's extrapolation

  // One --pose cannot hold for two frames.
  const test::CommandResult two_poses = test::RunCli("colorcal auto --db " + library_ + " --model " + kModel + " " +
                                                     first + " " + second + " --pose " + directory_->File("p.json"));
  EXPECT_EQ(two_poses.exit_code, 1) << two_poses.output;
  EXPECT_NE(two_poses.output.find("--pose"), std::string::npos) << two_poses.output;
  ModelDatabase(library_, OpenMode::kReadWrite).ClearColorMatrix(kModel);
}

TEST_F(ColorcalCliTest, UnknownModelAndMissingPoseAreInputErrors) {
  for (const std::string& command :
       {"colorcal auto --db " + library_ + " --model 999_nothing " + kFrame,
        "colorcal fit --db " + library_ + " --model 999_nothing --pairs " + directory_->File("none.csv"),
        "colorcal show --db " + library_ + " --model 999_nothing",
        "colorcal clear --db " + library_ + " --model 999_nothing"}) {
    SCOPED_TRACE(command);
    const test::CommandResult result = test::RunCli(command);
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_NE(result.output.find("999_nothing"), std::string::npos) << result.output;
    EXPECT_NE(result.output.find(library_), std::string::npos) << result.output;
  }

  ModelDatabase(library_, OpenMode::kReadWrite).ClearColorMatrix(kModel);
  // The same frame given by files carries no ground truth, and no --pose is given.
  const test::CommandResult no_pose = test::RunCli(
      "colorcal auto --db " + library_ + " --model " + kModel + " --color " + kFrame + "-color.png --depth " + kFrame +
      "-depth.png --depth-scale 10000 --camera 1066.778,1067.487,312.9869,241.3109");
  EXPECT_EQ(no_pose.exit_code, 1) << no_pose.output;
  EXPECT_NE(no_pose.output.find(kModel), std::string::npos) << no_pose.output;
  EXPECT_NE(no_pose.output.find("--pose"), std::string::npos) << no_pose.output;
  EXPECT_FALSE(StoredMatrix());  // nothing stored by a failed command

  // A missing --pose file names the file.
  const test::CommandResult bad_pose = test::RunCli("colorcal auto --db " + library_ + " --model " + kModel + " " +
                                                    kFrame + " --pose " + directory_->File("missing.json"));
  EXPECT_EQ(bad_pose.exit_code, 1) << bad_pose.output;
  EXPECT_NE(bad_pose.output.find("missing.json"), std::string::npos) << bad_pose.output;
}

}  // namespace
}  // namespace ecv
