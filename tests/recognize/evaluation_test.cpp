// EvaluateFrame's matching of detections to ground-truth instances, several of one model included: the mustard
// bottle of models/ at its real ground-truth poses in YCB-Video frames 0001/000001 and 0002/000001, taken as
// two instances in one frame, and detections built from those poses (exact, moved, turned).

#include <cmath>

#include <gtest/gtest.h>

#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "modeldb/mesh_sources.h"
#include "recognize/evaluation.h"
#include "support/test_data.h"

namespace ecv {
namespace {

constexpr char kMustard[] = "006_mustard_bottle";

// The mustard bottle's vertices (every 8th, metres, in YCB-Video's object frame) and its diameter.
EvalModel Mustard() {
  const MeshSourceScan scan =
      FindMeshSources({std::string(ECV_SOURCE_DIR) + "/models/meshes/006_mustard_bottle"}, ModelSource{});
  EXPECT_EQ(scan.sources.size(), 1U);
  MeshLoadOptions load;
  load.allow_missing_textures = true;
  load.object_from_mesh = scan.sources.at(0).object_from_mesh;
  const TriangleMesh mesh = LoadMesh(scan.sources.at(0).mesh_path, load);
  EvalModel model;
  model.name = kMustard;
  size_t vertex = 0;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3f& position : part.positions) {
      if (vertex++ % 8 == 0) model.points.push_back(position);
    }
  }
  for (const Eigen::Vector3f& a : model.points) {
    for (const Eigen::Vector3f& b : model.points) model.diameter_m = std::max(model.diameter_m, double((a - b).norm()));
  }
  return model;
}

GroundTruth MustardTruth(const std::string& frame) {
  for (const GroundTruth& truth : LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/" + frame)).ground_truth) {
    if (truth.object_name == kMustard) return truth;
  }
  ADD_FAILURE() << "no " << kMustard << " in " << frame;
  return {};
}

Detection At(const Eigen::Isometry3d& pose, double score) {
  Detection detection;
  detection.model = kMustard;
  detection.score = score;
  detection.camera_from_object = pose;
  return detection;
}

Eigen::Isometry3d Moved(const Eigen::Isometry3d& pose, double x_m) {
  Eigen::Isometry3d moved = pose;
  moved.translation().x() += x_m;
  return moved;
}

Eigen::Isometry3d TurnedAboutItsAxis(const Eigen::Isometry3d& pose) {
  return pose * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ());
}

class EvaluateFrameTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = new EvalModel(Mustard());
    a_ = MustardTruth("0001/000001");
    b_ = MustardTruth("0002/000001");
  }
  static void TearDownTestSuite() { delete model_; }

  static EvalModel* model_;
  static GroundTruth a_, b_;
};

EvalModel* EvaluateFrameTest::model_ = nullptr;
GroundTruth EvaluateFrameTest::a_, EvaluateFrameTest::b_;

TEST_F(EvaluateFrameTest, EachInstanceOfAModelIsTakenByOneDetection) {
  ASSERT_GT(model_->diameter_m, 0.15);
  ASSERT_LT(model_->diameter_m, 0.25);
  // Best score first: the turned bottle finds neither instance, the moved one takes b, the exact one a, and
  // the repeat of a finds only an instance already taken.
  const std::vector<Detection> detections = {
      At(a_.camera_from_object, 0.6), At(Moved(a_.camera_from_object, 0.003), 0.5),
      At(TurnedAboutItsAxis(b_.camera_from_object), 0.9), At(Moved(b_.camera_from_object, 0.005), 0.7)};
  const FrameEvaluation evaluation = EvaluateFrame("two bottles", detections, {a_, b_}, {*model_});
  ASSERT_EQ(evaluation.objects.size(), 2U);
  EXPECT_TRUE(evaluation.objects[0].correct);
  EXPECT_NEAR(evaluation.objects[0].error.translation_mm, 0.0, 1e-6);
  EXPECT_TRUE(evaluation.objects[1].correct);
  EXPECT_NEAR(evaluation.objects[1].error.translation_mm, 5.0, 1e-3);
  EXPECT_EQ(evaluation.false_positives, 2);
  EXPECT_EQ(evaluation.false_positive_models, std::vector<std::string>({kMustard, kMustard}));
}

TEST_F(EvaluateFrameTest, AWrongBestDetectionDoesNotHideARightOneOfTheSameModel) {
  const std::vector<Detection> detections = {At(TurnedAboutItsAxis(a_.camera_from_object), 0.9),
                                             At(Moved(a_.camera_from_object, 0.004), 0.4)};
  const FrameEvaluation evaluation = EvaluateFrame("one bottle", detections, {a_}, {*model_});
  ASSERT_EQ(evaluation.objects.size(), 1U);
  EXPECT_TRUE(evaluation.objects[0].correct);
  EXPECT_NEAR(evaluation.objects[0].error.translation_mm, 4.0, 1e-3);
  EXPECT_EQ(evaluation.false_positives, 1);
}

TEST_F(EvaluateFrameTest, AnInstanceNoDetectionFindsShowsTheBestWrongOnesError) {
  // 3 cm off is beyond a tenth of the diameter (about 2 cm): the instance is detected, not found.
  const std::vector<Detection> detections = {At(Moved(b_.camera_from_object, 0.05), 0.3),
                                             At(Moved(b_.camera_from_object, 0.03), 0.8)};
  const FrameEvaluation evaluation = EvaluateFrame("one bottle", detections, {b_}, {*model_});
  ASSERT_EQ(evaluation.objects.size(), 1U);
  EXPECT_TRUE(evaluation.objects[0].detected);
  EXPECT_FALSE(evaluation.objects[0].correct);
  EXPECT_NEAR(evaluation.objects[0].error.translation_mm, 30.0, 1e-3);
  EXPECT_EQ(evaluation.false_positives, 2);

  const FrameEvaluation nothing = EvaluateFrame("one bottle", {}, {b_}, {*model_});
  EXPECT_FALSE(nothing.objects[0].detected);
  EXPECT_EQ(nothing.false_positives, 0);
}

}  // namespace
}  // namespace ecv
