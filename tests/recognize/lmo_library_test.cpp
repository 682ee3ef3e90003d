// End to end on the LM-O frame (Kinect v1, scene 000002, image 3, with SAM-6D's depth): the 8 scanned,
// vertex-coloured LM-O models built with `ecvpose modeldb build` as scripts/build_lmo_library builds them (their
// views headlight-shaded: they have no texture), then `ecvpose recognize`, scored against the ground truth.

#include <fstream>

#include <gtest/gtest.h>

#include "io/frame_io.h"
#include "io/pose_io.h"
#include "modeldb/model_library.h"
#include "recognize/evaluation.h"
#include "recognize/recognition_json.h"
#include "support/test_data.h"

namespace ecv {
namespace {

TEST(LmoLibrary, FindsTheCanAndWithPointPairsTheDuckWithoutFalsePositives) {
  const test::TemporaryDirectory directory;
  const std::string library = directory.File("lmo.sqlite");
  const std::string models = test::DataPath("lmo_subset/data/bop/lmo/models");
  for (const char* id : {"01", "05", "06", "08", "09", "10", "11", "12"}) {
    const std::string name = std::string("obj_0000") + id;
    const bool symmetric = name == "obj_000010" || name == "obj_000011";  // eggbox, glue (BOP models_info)
    const test::CommandResult build = test::RunCli(
        "modeldb build " + models + "/" + name + ".ply --name " + name +
        " --unit mm --camera 572.4114,573.57043,325.2611,242.04899 --size 640x480 --views 40 --distance 1.0" +
        (symmetric ? " --symmetric" : "") + " --db " + library);
    ASSERT_EQ(build.exit_code, 0) << build.output;
  }
  const std::string scene = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  const std::string depth = test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png");
  const std::string out = directory.File("detections.json");
  const test::CommandResult run = test::RunCli("recognize --db " + library + " " + scene + ":3 --depth " + depth +
                                               " --hypotheses context --out-json " + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;

  LibraryLoadOptions load;
  load.build_matchers = false;
  const std::vector<EvalModel> eval_models = EvalModels(ModelLibrary::Load(library, load));
  std::ifstream in(out);
  const nlohmann::json detections = nlohmann::json::parse(in);
  const LoadedFrame frame = LoadBopFrame(scene, 3, depth);
  const FrameEvaluation evaluation =
      EvaluateFrame("lmo", DetectionsFromJson(detections, out), frame.ground_truth, eval_models);
  ASSERT_EQ(evaluation.objects.size(), 8U);
  std::vector<std::string> found;
  for (const ObjectEvaluation& object : evaluation.objects) {
    if (object.correct) found.push_back(object.model);
  }
  // Not all 8: the floor measured when headlight shading came in (0 of 8 with unlit views), to catch regressions.
  // The duck (obj_000009) was found as well until the recognizer took the KdForest (2026-11-24), but only with
  // FLANN's matches at exactly 4 trees and 32 checks: its best views hold at most 5 right correspondences of 200,
  // and with 64 or 128 checks (nearer neighbours) FLANN lost it too, as does the recognizer's KdForest
  // (bench/RESULTS.md, "Recognizer defaults", match).
  EXPECT_EQ(found, std::vector<std::string>({"obj_000005"})) << run.output;
  EXPECT_EQ(evaluation.false_positives, 0) << run.output;

  // Verification renders each model shaded as its library views were: the can's colours then correlate with
  // the image's (score 0.60; 0.43 when verification rendered it unlit, as before 31c68b2).
  double can_score = 0.0;
  for (const Detection& detection : DetectionsFromJson(detections, out)) {
    if (detection.model == "obj_000005") can_score = detection.score;
  }
  EXPECT_GT(can_score, 0.5) << run.output;

  // With the default hypotheses, point pairs for the models the context did not find, the duck is found too, by its
  // shape alone, within 2 cm and 8 degrees (its depth lies 5-7 mm off the ground truth's), and so is the hole punch
  // (since colour channels in which a render is plain count less in verification); nothing is reported wrongly.
  const std::string both = directory.File("both.json");
  const test::CommandResult shaped = test::RunCli("recognize --db " + library + " " + scene + ":3 --depth " + depth +
                                                  " --threads 2 --out-json " + both);
  ASSERT_EQ(shaped.exit_code, 0) << shaped.output;
  const std::vector<Detection> shaped_detections = DetectionsFromJson(ReadJsonFile(both), both);
  const FrameEvaluation shaped_evaluation = EvaluateFrame("lmo", shaped_detections, frame.ground_truth, eval_models);
  found.clear();
  for (const ObjectEvaluation& object : shaped_evaluation.objects) {
    if (!object.correct) continue;
    found.push_back(object.model);
    if (object.model == "obj_000009") {
      EXPECT_LT(object.error.translation_mm, 20.0);
      EXPECT_LT(object.error.rotation_deg, 8.0);
    }
  }
  EXPECT_EQ(found, std::vector<std::string>({"obj_000005", "obj_000009", "obj_000012"})) << shaped.output;
  EXPECT_EQ(shaped_evaluation.false_positives, 0) << shaped.output;
  for (const Detection& detection : shaped_detections) {
    if (detection.model == "obj_000009") {
      EXPECT_EQ(detection.hypothesis_source, HypothesisSource::kPpf);
    }
  }
}

}  // namespace
}  // namespace ecv
