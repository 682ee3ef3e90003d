// End to end on real data with the whole textured library: the 7 textured YCB meshes of ../shared/data
// (6 google16k meshes moved into the YCB-Video object frame, and the YCB-Video banana) built with
// `ecvpose modeldb build`, then `ecvpose recognize --sequence` over frame 000001 of videos 0000, 0001 and
// 0002 (7 textured objects in all), scored against the ground truth.

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/pose.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "io/points_io.h"
#include "io/pose_io.h"
#include "modeldb/model_library.h"
#include "recognize/evaluation.h"
#include "recognize/recognition_json.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"
#include "scenes/composites.h"
#include "support/test_data.h"
#include "support/ycbv_library.h"
#include "verify_prior.h"

namespace ecv {
namespace {

constexpr int kFoundAtLeast = 6;  // of 7: all but the banana of 0002 (with the all-pairs context: the potted meat can)

class YcbvLibrary : public test::YcbvLibrarySuite {
 protected:
  static std::vector<std::string> Frames() {
    const std::string scenes = test::DataPath("ycbv_subset/Example-Scenes/");
    return {scenes + "0000/000001", scenes + "0001/000001", scenes + "0002/000001"};
  }

  // `recognize --sequence` over `frames`; the JSON lines, one per frame.
  static std::vector<nlohmann::json> Recognize(const std::string& tag, const std::string& flags,
                                               const std::vector<std::string>& frames = Frames()) {
    const std::string list = directory_->File(tag + ".txt"), out = directory_->File(tag + ".jsonl");
    std::ofstream list_file(list);
    for (const std::string& frame : frames) list_file << frame << '\n';
    list_file.close();
    const test::CommandResult run =
        test::RunCli("recognize --db " + library_ + " --sequence " + list + " --out-json " + out + " " + flags);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    std::vector<nlohmann::json> lines;
    std::ifstream in(out);
    for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
    return lines;
  }
};

TEST_F(YcbvLibrary, FindsTexturedObjectsOnThreeVideosWithoutFalsePositives) {
  const std::vector<nlohmann::json> lines = Recognize("run", "");
  ASSERT_EQ(lines.size(), 3U);
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  ASSERT_EQ(library.models().size(), 7U);
  const std::vector<EvalModel> models = EvalModels(library);

  int present = 0, correct = 0, false_positives = 0;
  std::string report;
  for (size_t i = 0; i < lines.size(); ++i) {
    const LoadedFrame frame = LoadYcbvFrame(Frames()[i]);
    const FrameEvaluation evaluation =
        EvaluateFrame(Frames()[i], DetectionsFromJson(lines[i], Frames()[i]), frame.ground_truth, models);
    false_positives += evaluation.false_positives;
    for (const ObjectEvaluation& object : evaluation.objects) {
      ++present;
      correct += object.correct ? 1 : 0;
      report += Frames()[i] + " " + object.model + (object.correct ? " correct\n" : " missed\n");
    }
  }
  EXPECT_EQ(present, 7);  // 009 in 0000; 003, 004, 006 in 0001; 006, 010, 011 in 0002
  // Not yet the aim (all 7): the floor measured when this test was written, to catch regressions.
  EXPECT_GE(correct, kFoundAtLeast) << report;
  EXPECT_EQ(false_positives, 0) << report;
}

// The wrong pose once reported in video 0002, frame 000009: the gelatin box lying flat on the unmodelled pudding box.
Eigen::Isometry3d GelatinBoxOnThePuddingBox() {
  Eigen::Isometry3d pose;
  pose.matrix() << 0.90183, 0.43200, 0.00878, 0.05684,  //
      0.27870, -0.56604, -0.77584, -0.05234,            //
      -0.33020, 0.70212, -0.63087, 1.05788,             //
      0.0, 0.0, 0.0, 1.0;
  pose.linear() = Eigen::Quaterniond(pose.linear()).normalized().toRotationMatrix();
  return pose;
}

using test::TruthOf;

// Verification's contour factor on the case it was made for. In video 0002 the unmodelled pudding box lies face up
// next to the mustard bottle; recognition used to report the gelatin box lying flat on its face (at this pose, in
// frame 000009, score 0.32: the depth agrees everywhere and the print correlates weakly). Its outline runs over
// the pudding box's face, not along a depth step, so it scores 0; the objects at their ground truth stand out.
TEST_F(YcbvLibrary, TheGelatinBoxLyingOnThePuddingBoxScoresZeroThroughItsOutline) {
  LibraryLoadOptions load;
  load.build_matchers = false;
  load.names = {"006_mustard_bottle", "009_gelatin_box", "010_potted_meat_can"};
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0002/000009"));
  const Eigen::Isometry3d on_pudding_box = GelatinBoxOnThePuddingBox();
  std::vector<Detection> priors(1);
  priors[0].model = "009_gelatin_box";
  priors[0].camera_from_object = on_pudding_box;
  for (const GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name != "006_mustard_bottle" && truth.object_name != "010_potted_meat_can") continue;
    priors.emplace_back().model = truth.object_name;
    priors.back().camera_from_object = truth.camera_from_object;
  }
  ASSERT_EQ(priors.size(), 3U);
  for (Detection& prior : priors) {
    prior.tracked = true;
    prior.score = 1.0;       // followed whatever the bar ...
    prior.confirmed = true;  // ... and not searched for again
  }

  RecognizerOptions options;
  options.verify.min_score = 0.0;  // report every prior with its score
  options.verify.min_visible_fraction = 0.0;
  options.max_overlap = 1.0;
  auto verified = [&](const RecognizerOptions& settings) {
    std::map<std::string, Detection> by_model;
    for (const Detection& detection : Recognizer(library, settings).Recognize(frame.rgbd, priors).detections) {
      by_model[detection.model] = detection;
    }
    EXPECT_EQ(by_model.size(), 3U);
    return by_model;
  };
  std::map<std::string, Detection> scored = verified(options);
  options.verify.contour_falloff = 0.0;       // no contour factor ...
  options.verify.continuation_falloff = 0.0;  // ... nor its counterpart, the surface running on across the outline
  std::map<std::string, Detection> unfactored = verified(options);
  EXPECT_LT(scored["009_gelatin_box"].contour_agreement, 0.15);
  EXPECT_GT(scored["009_gelatin_box"].depth_agreement, 0.9);
  EXPECT_LT(scored["009_gelatin_box"].score, 0.05);
  EXPECT_GT(unfactored["009_gelatin_box"].score, 0.3);  // without the factor it passes
  for (const char* model : {"006_mustard_bottle", "010_potted_meat_can"}) {
    EXPECT_GT(scored[model].contour_agreement, options.verify.contour_free) << model;
    EXPECT_GT(scored[model].score, 0.25) << model;
    EXPECT_EQ(scored[model].score, unfactored[model].score) << model;  // a factor of 1
  }
}

// The gelatin box laid flush on the face of an object that is larger than it: its back on the face's plane, its
// middle on the face's middle, its thin axis (z) along the face's outward normal. `face_axis` is the larger object's
// model axis (0-2) and `sign` the side of its face; `extent` its model box (min, max per axis).
Eigen::Isometry3d GelatinBoxOnFace(const Eigen::Isometry3d& camera_from_object, const Eigen::AlignedBox3d& extent,
                                   int face_axis, double sign) {
  constexpr double kGelatinBack = -0.0186, kGelatinMiddleX = -0.0014, kGelatinMiddleY = 0.0005;  // its model, metres
  const Eigen::Vector3d normal = sign * Eigen::Vector3d::Unit(face_axis);
  const Eigen::Vector3d along = Eigen::Vector3d::Unit((face_axis + 1) % 3);
  Eigen::Matrix3d object_from_box;
  object_from_box.col(0) = along;
  object_from_box.col(1) = normal.cross(along);
  object_from_box.col(2) = normal;
  Eigen::Vector3d face_middle = extent.center();
  face_middle[face_axis] = sign > 0.0 ? extent.max()[face_axis] : extent.min()[face_axis];
  Eigen::Isometry3d object_from_box_pose = Eigen::Isometry3d::Identity();
  object_from_box_pose.linear() = object_from_box;
  object_from_box_pose.translation() =
      face_middle - object_from_box * Eigen::Vector3d(kGelatinMiddleX, kGelatinMiddleY, kGelatinBack);
  return camera_from_object * object_from_box_pose;
}

// The face of a posed object's model box that turns most towards the camera: its axis and side.
std::pair<int, double> FaceToTheCamera(const Eigen::Isometry3d& camera_from_object, const Eigen::AlignedBox3d& extent) {
  const Eigen::Vector3d camera = camera_from_object.inverse().translation() - extent.center();
  const Eigen::Vector3d half = extent.sizes() / 2.0;
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(camera[k]) / half[k] > std::abs(camera[axis]) / half[axis]) axis = k;
  }
  return {axis, camera[axis] > 0.0 ? 1.0 : -1.0};
}

Eigen::AlignedBox3d ModelBox(const std::string& model) {
  MeshLoadOptions geometry;
  geometry.allow_missing_textures = true;  // the box is all that is needed
  return LoadMesh(test::DataPath("ycbv_subset/models/" + model + "/textured_simple.obj"), geometry).BoundingBox();
}

// Verification from both sides. In video 0002 the gelatin box laid flush on the potted meat can's front face (from
// the can's ground truth) fits the depth there; the can at its ground truth wins, and the box is not reported. In video
// 0001 the gelatin box laid on the cracker box's front covers a part of it, and the face runs on all round its
// outline: the continuation factor alone rejects it, where without the outline factors it would pass.
TEST_F(YcbvLibrary, AGelatinBoxLaidOnALargerObjectLosesToIt) {
  auto one_model = [](const std::string& name) {
    LibraryLoadOptions load;
    load.build_matchers = false;
    load.names = {name};
    return ModelLibrary::Load(library_, load);
  };
  const ModelLibrary box_library = one_model("009_gelatin_box");
  RecognizerOptions options;
  options.verify.min_score = 0.0;  // report the prior with its score
  options.verify.min_visible_fraction = 0.0;
  auto laid_on = [&](const LoadedFrame& frame, const std::string& model) {
    const Eigen::Isometry3d pose = TruthOf(frame, model).camera_from_object;
    const Eigen::AlignedBox3d extent = ModelBox(model);
    const auto [axis, sign] = FaceToTheCamera(pose, extent);
    return GelatinBoxOnFace(pose, extent, axis, sign);
  };

  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0002/000009"));
  const Detection can = test::VerifyPrior(one_model("010_potted_meat_can"), options, frame.rgbd, "010_potted_meat_can",
                                          TruthOf(frame, "010_potted_meat_can").camera_from_object);
  const Detection on_can =
      test::VerifyPrior(box_library, options, frame.rgbd, "009_gelatin_box", laid_on(frame, "010_potted_meat_can"));
  EXPECT_GT(on_can.depth_agreement, 0.9);  // it fits the can's face
  // The can lies on the table: its outline hardly steps back, but the table turns away from its faces there; the box's
  // outline lies on the can's front face, which goes on flat beyond it.
  EXPECT_GT(can.creased_contour, on_can.creased_contour + 0.15);
  EXPECT_GT(can.score, RecognizerOptions().verify.min_score);
  EXPECT_LT(on_can.score, RecognizerOptions().verify.min_score);
  EXPECT_LT(on_can.score, can.score - 0.1);

  const LoadedFrame cracker_frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  const Eigen::Isometry3d on_cracker = laid_on(cracker_frame, "003_cracker_box");
  const Detection cracker =
      test::VerifyPrior(one_model("003_cracker_box"), options, cracker_frame.rgbd, "003_cracker_box",
                        TruthOf(cracker_frame, "003_cracker_box").camera_from_object);
  EXPECT_LT(cracker.continuation, 0.1);
  EXPECT_GT(cracker.score, 0.5);
  options.verify.contour_falloff = 0.0;  // the continuation factor alone
  const Detection laid = test::VerifyPrior(box_library, options, cracker_frame.rgbd, "009_gelatin_box", on_cracker);
  EXPECT_GT(laid.depth_agreement, 0.9);
  EXPECT_GT(cracker.occluding_contour + cracker.creased_contour, laid.occluding_contour + laid.creased_contour + 0.25);
  EXPECT_GT(laid.continuation, 0.8);
  EXPECT_LT(laid.score, 0.05);
  options.verify.continuation_falloff = 0.0;
  EXPECT_GT(test::VerifyPrior(box_library, options, cracker_frame.rgbd, "009_gelatin_box", on_cracker).score, 0.1);
}

// Tracking must keep earning its place: video 0002 started from the wrong gelatin box on the pudding box (carried from
// frame 000009 into frame 000003 through the static mustard bottle's poses) as a followed track. No frame reports a
// gelatin box, and the bottle and the potted meat can beside it are found in each.
TEST_F(YcbvLibrary, AWrongTrackOnThePuddingBoxIsDroppedAndItsNeighboursFound) {
  const ModelLibrary library = ModelLibrary::Load(library_);
  const std::string scenes = test::DataPath("ycbv_subset/Example-Scenes/0002/");
  const LoadedFrame first = LoadYcbvFrame(scenes + "000003"), last = LoadYcbvFrame(scenes + "000009");
  std::vector<Detection> priors(1);
  priors[0].model = "009_gelatin_box";
  priors[0].score = 0.4;
  priors[0].tracked = true;
  priors[0].frames_followed = 1;
  priors[0].camera_from_object = TruthOf(first, "006_mustard_bottle").camera_from_object *
                                 TruthOf(last, "006_mustard_bottle").camera_from_object.inverse() *
                                 GelatinBoxOnThePuddingBox();
  const std::vector<EvalModel> models = EvalModels(library);
  Recognizer recognizer(library);
  for (const char* name : {"000003", "000005", "000007", "000009"}) {
    const LoadedFrame frame = LoadYcbvFrame(scenes + name);
    const RecognitionResult result = recognizer.Recognize(frame.rgbd, priors);
    for (const Detection& detection : result.detections) EXPECT_NE(detection.model, "009_gelatin_box") << name;
    const FrameEvaluation evaluation = EvaluateFrame(name, result.detections, frame.ground_truth, models);
    EXPECT_EQ(evaluation.false_positives, 0) << name;
    for (const ObjectEvaluation& object : evaluation.objects) {
      if (object.model == "006_mustard_bottle" || object.model == "010_potted_meat_can") {
        EXPECT_TRUE(object.correct) << name << " " << object.model;
      }
    }
    priors = result.detections;
  }
}

// Verification's edge term on the case it was made for. In video 0001 only the mustard bottle's shoulder shows above
// the sugar box, its plain side to the camera; recognition used to report it turned about 180 degrees (this pose,
// found in frame 000015): its colours correlate as well as the right pose's, but the printed side it puts there
// has edges the scene does not show.
TEST_F(YcbvLibrary, TheMustardBottleTurnedToItsPrintedSideLosesThroughItsTextureEdges) {
  LibraryLoadOptions load;
  load.build_matchers = false;
  load.names = {"006_mustard_bottle"};
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000015"));
  Eigen::Isometry3d turned;
  turned.matrix() << -0.69978, -0.71285, 0.04633, 0.15273,  //
      -0.42794, 0.36641, -0.82620, 0.01852,                 //
      0.57199, -0.59799, -0.56147, 1.09659,                 //
      0.0, 0.0, 0.0, 1.0;
  turned.linear() = Eigen::Quaterniond(turned.linear()).normalized().toRotationMatrix();
  Detection right;
  for (const GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name == "006_mustard_bottle") right.camera_from_object = truth.camera_from_object;
  }
  ASSERT_GT(RotationAngle(right.camera_from_object, turned), 170.0 * M_PI / 180.0);

  RecognizerOptions options;
  options.verify.min_score = 0.0;  // report the prior with its score
  options.verify.min_visible_fraction = 0.0;
  auto verified = [&](const RecognizerOptions& settings, const Eigen::Isometry3d& pose) {
    return test::VerifyPrior(library, settings, frame.rgbd, "006_mustard_bottle", pose);
  };
  const Detection right_scored = verified(options, right.camera_from_object);
  const Detection turned_scored = verified(options, turned);
  EXPECT_GT(right_scored.edge_pixels, options.verify.min_edge_pixels);
  EXPECT_GT(turned_scored.edge_pixels, 1.5 * right_scored.edge_pixels);  // the printed side
  EXPECT_GT(right_scored.edge_agreement, turned_scored.edge_agreement + 0.1);
  EXPECT_GT(right_scored.score, turned_scored.score);
  EXPECT_LT(RotationAngle(right_scored.camera_from_object, right.camera_from_object), 10.0 * M_PI / 180.0);
  // Colour alone prefers the turned bottle.
  options.verify.edge_weight = 0.0;
  EXPECT_LT(verified(options, right.camera_from_object).score, verified(options, turned).score);
}

// Verification under other light: the demo frame 0001/000001 with its white balance 15 % warmer and cooler and with
// gamma 0.8 and 1.25. Each of its three objects of the library, verified at its ground truth, scores within 0.05 of
// what it scores under the frame's own light (0.47-0.62); the red and white tomato soup can put where the blue master
// chef can stands (not in this library) stays below verification's bar.
TEST_F(YcbvLibrary, UnderAnotherLightRightPosesKeepTheirScoresAndTheSoupCanIsNotTakenForTheChefCan) {
  const std::vector<std::string> objects = {"003_cracker_box", "004_sugar_box", "006_mustard_bottle"};
  LibraryLoadOptions load;
  load.build_matchers = false;
  load.names = objects;
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  load.names = {"005_tomato_soup_can"};
  const ModelLibrary soup_can = ModelLibrary::Load(library_, load);
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  std::vector<Detection> at_truth;
  for (const std::string& model : objects) {
    Detection& prior = at_truth.emplace_back();
    prior.model = model;
    prior.camera_from_object = TruthOf(frame, model).camera_from_object;
    prior.tracked = true;
    prior.score = 1.0;
    prior.confirmed = true;
  }
  RecognizerOptions as_is;  // every prior reported with its score, at its pose
  as_is.verify.min_score = 0.0;
  as_is.verify.min_visible_fraction = 0.0;
  as_is.max_overlap = 1.0;
  as_is.refine = false;
  Recognizer recognizer(library, as_is);
  auto scores = [&](const RgbdFrame& rgbd) {
    std::map<std::string, double> by_model;
    for (const Detection& detection : recognizer.Recognize(rgbd, at_truth).detections) {
      by_model[detection.model] = detection.score;
    }
    EXPECT_EQ(by_model.size(), 3U);
    return by_model;
  };
  const std::map<std::string, double> own_light = scores(frame.rgbd);
  ColorCast warm, cool, bright, dark;
  warm.rgb_gain = Eigen::Vector3d(1.15, 1.0, 0.85);
  cool.rgb_gain = Eigen::Vector3d(0.85, 1.0, 1.15);
  bright.gamma = 0.8;
  dark.gamma = 1.25;
  for (const ColorCast& cast : {warm, cool, bright, dark}) {
    const RgbdFrame cast_frame = WithColorCast(frame.rgbd, cast);
    const std::string light = "red gain " + std::to_string(cast.rgb_gain.x()) + ", gamma " + std::to_string(cast.gamma);
    for (const auto& [model, score] : scores(cast_frame)) {
      EXPECT_GT(own_light.at(model), 0.45) << model;
      EXPECT_NEAR(score, own_light.at(model), 0.05) << light << ": " << model;
    }
    const Detection on_chef_can = test::VerifyPrior(soup_can, as_is, cast_frame, "005_tomato_soup_can",
                                                    TruthOf(frame, "002_master_chef_can").camera_from_object);
    EXPECT_LT(on_chef_can.score, RecognizerOptions().verify.min_score) << light;
  }
}

// Point pair hypotheses on the case they were made for: the banana of 0002/000001, a plain yellow surface that the
// context descriptors do not find. With --hypotheses both, point pairs find it; the mustard bottle and the potted
// meat can are still found by the context, and nothing else is reported. The JSON says where each pose came from.
TEST_F(YcbvLibrary, PointPairsFindTheBananaThatTheContextMisses) {
  const std::string frame_path = test::DataPath("ycbv_subset/Example-Scenes/0002/000001");
  const std::vector<nlohmann::json> lines = Recognize("point_pairs", "--hypotheses both --threads 2", {frame_path});
  ASSERT_EQ(lines.size(), 1U);
  LibraryLoadOptions load;
  load.build_matchers = false;
  const std::vector<EvalModel> models = EvalModels(ModelLibrary::Load(library_, load));
  const LoadedFrame frame = LoadYcbvFrame(frame_path);
  const std::vector<Detection> detections = DetectionsFromJson(lines[0], frame_path);
  const FrameEvaluation evaluation = EvaluateFrame(frame_path, detections, frame.ground_truth, models);
  EXPECT_EQ(evaluation.false_positives, 0);
  std::map<std::string, const Detection*> by_model;
  for (const Detection& detection : detections) by_model[detection.model] = &detection;
  for (const ObjectEvaluation& object : evaluation.objects) {
    EXPECT_TRUE(object.correct) << object.model;
    ASSERT_EQ(by_model.count(object.model), 1U) << object.model;
    const HypothesisSource expected =
        object.model == "011_banana" ? HypothesisSource::kPpf : HypothesisSource::kContext;
    EXPECT_EQ(by_model[object.model]->hypothesis_source, expected) << object.model;
    if (object.model == "011_banana") {  // within 1 cm and 5 degrees
      EXPECT_LT(object.error.translation_mm, 10.0);
      EXPECT_LT(object.error.rotation_deg, 5.0);
    }
  }
  EXPECT_EQ(evaluation.objects.size(), 3U);
}

// A pre-selection of 2 models leaves the banana out (its views rank low); of the 5 models left out, the 2 whose coarse
// point pair tables fit the surface the two found leave best are searched by point pairs, and the banana is found.
TEST_F(YcbvLibrary, AModelThePreselectionLeavesOutIsFoundByItsShape) {
  const std::string frame_path = test::DataPath("ycbv_subset/Example-Scenes/0002/000001");
  LibraryLoadOptions load;
  load.build_matchers = false;
  const std::vector<EvalModel> models = EvalModels(ModelLibrary::Load(library_, load));
  const LoadedFrame frame = LoadYcbvFrame(frame_path);
  for (const int shapes : {0, 2}) {
    const std::string flags = "--preselect 2 --preselect-shape " + std::to_string(shapes) + " --threads 2";
    const std::vector<nlohmann::json> lines = Recognize("shape" + std::to_string(shapes), flags, {frame_path});
    ASSERT_EQ(lines.size(), 1U);
    const std::vector<Detection> detections = DetectionsFromJson(lines[0], frame_path);
    const FrameEvaluation evaluation = EvaluateFrame(frame_path, detections, frame.ground_truth, models);
    EXPECT_EQ(evaluation.false_positives, 0) << flags;
    ASSERT_EQ(evaluation.objects.size(), 3U);
    for (const ObjectEvaluation& object : evaluation.objects) {
      EXPECT_EQ(object.correct, object.model != "011_banana" || shapes > 0) << flags << ": " << object.model;
    }
    for (const Detection& detection : detections) {
      const HypothesisSource expected =
          detection.model == "011_banana" ? HypothesisSource::kPpf : HypothesisSource::kContext;
      EXPECT_EQ(detection.hypothesis_source, expected) << flags << ": " << detection.model;
    }
  }
}

// A near-symmetric object searched from its other side: in 0002/000005 and 0002/000017 the context's best banana poses
// lie on the banana end to end (and score below the bar). Turned 180 degrees about the banana's principal axes and
// refined, the right end is found, within 1 cm and 15 degrees; --no-twins finds no banana there.
TEST_F(YcbvLibrary, ABananaSearchedFromItsOtherEndIsTurnedAroundAndFound) {
  const std::string video = test::DataPath("ycbv_subset/Example-Scenes/0002/");
  const std::vector<std::string> frames = {video + "000005", video + "000017"};
  LibraryLoadOptions load;
  load.build_matchers = false;
  load.names = {"011_banana"};
  const std::vector<EvalModel> models = EvalModels(ModelLibrary::Load(library_, load));
  // The context's poses alone: with point pairs the banana is found from its shape whichever way the context lay.
  const std::vector<nlohmann::json> turned = Recognize("twins", "--models 011_banana --hypotheses context", frames);
  const std::vector<nlohmann::json> unturned =
      Recognize("no_twins", "--models 011_banana --hypotheses context --no-twins", frames);
  ASSERT_EQ(turned.size(), frames.size());
  ASSERT_EQ(unturned.size(), frames.size());
  for (size_t f = 0; f < frames.size(); ++f) {
    const LoadedFrame frame = LoadYcbvFrame(frames[f]);
    const FrameEvaluation found =
        EvaluateFrame(frames[f], DetectionsFromJson(turned[f], frames[f]), frame.ground_truth, models);
    ASSERT_EQ(found.objects.size(), 1U) << frames[f];
    EXPECT_TRUE(found.objects[0].correct) << frames[f];
    EXPECT_LT(found.objects[0].error.translation_mm, 10.0) << frames[f];
    EXPECT_LT(found.objects[0].error.rotation_deg, 15.0) << frames[f];
    EXPECT_EQ(found.false_positives, 0) << frames[f];
    const FrameEvaluation missed =
        EvaluateFrame(frames[f], DetectionsFromJson(unturned[f], frames[f]), frame.ground_truth, models);
    EXPECT_FALSE(missed.objects[0].correct) << frames[f];
  }
}

// A composite of two real frames (bench/scenes/composites.h): the gelatin box of 0000/000001, which recognition finds
// in its own video, cut out and moved onto the table of 0002/000001 beside the potted meat can, seen from within 12
// degrees of its own view. Written as a frame JSON, recognition finds the box at its composite ground truth (ADD under
// 1 cm) and still finds the frame's own potted meat can.
TEST_F(YcbvLibrary, FindsTheGelatinBoxOfOneVideoInAComposite) {
  const std::string scenes = test::DataPath("ycbv_subset/Example-Scenes/");
  bench::Composite composite;
  ASSERT_TRUE(bench::MakeComposite(bench::LoadSourceFrame(scenes + "0000/000001"), "009_gelatin_box",
                                   bench::LoadSourceFrame(scenes + "0002/000001"), "010_potted_meat_can", 1,
                                   bench::CompositeOptions(), &composite));
  const std::string frame = directory_->File("composite.json"), out = directory_->File("composite_detections.json");
  WriteFrameJson(frame, composite.frame.rgbd);
  const test::CommandResult run = test::RunCli("recognize --db " + library_ + " " + frame + " --out-json " + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::vector<Detection> detections = DetectionsFromJson(ReadJsonFile(out), out);

  std::vector<Eigen::Vector3f> box_points;
  for (const Eigen::Vector3d& point : ReadXyzFile(test::DataPath("ycbv_subset/models/009_gelatin_box/points.xyz"))) {
    box_points.push_back(point.cast<float>());
  }
  const Eigen::Isometry3d& box_truth = TruthOf(composite.frame, "009_gelatin_box").camera_from_object;
  int boxes = 0;
  for (const Detection& detection : detections) {
    if (detection.model != "009_gelatin_box") continue;
    ++boxes;
    EXPECT_LT(ComputePoseError(box_points, detection.camera_from_object, box_truth).add_m, 0.01) << run.output;
  }
  EXPECT_EQ(boxes, 1) << run.output;

  LibraryLoadOptions load;
  load.build_matchers = false;
  load.names = {"010_potted_meat_can"};
  const FrameEvaluation evaluation =
      EvaluateFrame(frame, detections, composite.frame.ground_truth, EvalModels(ModelLibrary::Load(library_, load)));
  ASSERT_EQ(evaluation.objects.size(), 1U);
  EXPECT_TRUE(evaluation.objects[0].correct) << run.output;
}

// Geometry first (--plain-appearance 0.5): the grey foam brick model (no texture) is judged by depth, fit, outline and
// continuation alone. At its ground truth in 0000/000001 it is accepted, whatever the frame's colours (channels
// swapped: the same score); moved 2 cm sideways it is rejected.
TEST_F(YcbvLibrary, AGreyModelIsAcceptedAtItsPoseByItsGeometryAndRejectedTwoCentimetresOff) {
  const std::string library_path = directory_->File("grey_brick.sqlite");
  ASSERT_NO_FATAL_FAILURE(AddUntexturedModel("061_foam_brick", true, library_path));
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(library_path, load);
  LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0000/000001"));
  const Eigen::Isometry3d truth = TruthOf(frame, "061_foam_brick").camera_from_object;
  RecognizerOptions options;
  options.verify.min_score = 0.0;  // report the prior with its score
  options.verify.min_visible_fraction = 0.0;
  options.refine = false;  // the poses as given: ICP would pull the moved one back
  options.verify.plain_appearance = 0.5;
  const double bar = RecognizerOptions().verify.min_score;

  const Detection right = test::VerifyPrior(library, options, frame.rgbd, "061_foam_brick", truth);
  EXPECT_GT(right.score, bar);
  EXPECT_GT(right.depth_agreement, 0.9);
  Eigen::Isometry3d moved = truth;
  moved.pretranslate(Eigen::Vector3d(0.02, 0.0, 0.0));
  EXPECT_LT(test::VerifyPrior(library, options, frame.rgbd, "061_foam_brick", moved).score, bar);
  moved = truth;
  moved.pretranslate(Eigen::Vector3d(0.0, -0.02, 0.0));
  EXPECT_LT(test::VerifyPrior(library, options, frame.rgbd, "061_foam_brick", moved).score, bar);
  cv::cvtColor(frame.rgbd.color, frame.rgbd.color, cv::COLOR_RGB2BGR);  // red becomes blue
  EXPECT_DOUBLE_EQ(test::VerifyPrior(library, options, frame.rgbd, "061_foam_brick", truth).score, right.score);
  options.verify.plain_appearance = 0.0;  // judged by its grey render's colours instead
  EXPECT_NE(test::VerifyPrior(library, options, frame.rgbd, "061_foam_brick", truth).score, right.score);
}

// Untextured models (the YCB-Video meshes whose textures did not come through: grey, shaded views), added to the
// suite's library: point pairs alone find the grey foam brick of 0000/000001 (ADD-S under 1 cm), and with both
// sources, grey models judged by their geometry (--plain-appearance 0.5), a grey model absent from the frame (the tuna
// fish can, not in video 0001) is not reported while the textured objects of 0001/000001 and the grey chef can are
// found. The grey chef can is a cylinder: its turn about its axis cannot be told, so it is built symmetric (ADD-S).
TEST_F(YcbvLibrary, PointPairsFindAGreyModelAndReportNoAbsentOne) {
  const std::string library = directory_->File("with_grey.sqlite");
  std::filesystem::copy_file(library_, library);
  for (const std::string name : {"002_master_chef_can", "007_tuna_fish_can", "061_foam_brick"}) {
    ASSERT_NO_FATAL_FAILURE(AddUntexturedModel(name, name != "007_tuna_fish_can", library));
  }
  LibraryLoadOptions load;
  load.build_matchers = false;
  const std::vector<EvalModel> eval_models = EvalModels(ModelLibrary::Load(library, load));
  struct Run {
    std::vector<Detection> detections;
    FrameEvaluation evaluation;
    std::string output;
  };
  auto recognize = [&](const std::string& frame_path, const std::string& flags) {
    const std::string out = directory_->File("grey.json");
    const test::CommandResult run =
        test::RunCli("recognize --db " + library + " " + frame_path + " --threads 2 --out-json " + out + " " + flags);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    Run result{DetectionsFromJson(ReadJsonFile(out), out), {}, run.output};
    result.evaluation =
        EvaluateFrame(frame_path, result.detections, LoadYcbvFrame(frame_path).ground_truth, eval_models);
    return result;
  };

  const Run brick = recognize(test::DataPath("ycbv_subset/Example-Scenes/0000/000001"), "--hypotheses ppf");
  bool brick_found = false;
  for (const ObjectEvaluation& object : brick.evaluation.objects) {
    if (object.model != "061_foam_brick") continue;
    brick_found = object.correct;
    EXPECT_LT(object.error.adds_m, 0.01) << brick.output;
  }
  EXPECT_TRUE(brick_found) << brick.output;

  const Run both =
      recognize(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"), "--hypotheses both --plain-appearance 0.5");
  EXPECT_EQ(both.evaluation.false_positives, 0) << both.output;
  for (const Detection& detection : both.detections) EXPECT_NE(detection.model, "007_tuna_fish_can");
  for (const ObjectEvaluation& object : both.evaluation.objects) {
    EXPECT_TRUE(object.correct) << object.model << '\n' << both.output;  // the grey chef can too, by its geometry
  }
}

TEST_F(YcbvLibrary, SameSeedSameOutputWithOneOrTwoThreads) {
  // Not the dense close-up of 0000: the sanitizer build runs this too.
  const std::vector<std::string> frames = {Frames()[1], Frames()[2]};
  const std::vector<nlohmann::json> one = Recognize("one", "--threads 1 --seed 7", frames);
  const std::vector<nlohmann::json> two = Recognize("two", "--threads 2 --seed 7", frames);
  ASSERT_EQ(one.size(), two.size());
  for (size_t i = 0; i < one.size(); ++i) EXPECT_EQ(one[i].at("detections"), two[i].at("detections")) << i;
}

// RecognizerOptions::give_up_after_views on 0001/000001 (the cracker box, sugar box and mustard bottle; the other
// 4 models absent): every model tries views_per_model views when it never gives up, and 3 when no score can stay on; by
// default some absent model is given up after 4 views, and the detections are the same as without giving up.
TEST_F(YcbvLibrary, AModelWhoseFirstViewsAllScoreLowIsGivenUpWithTheSameDetections) {
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  const LoadedFrame frame = LoadYcbvFrame(Frames()[1]);
  auto recognize = [&](int give_up_after, double give_up_below, double good_enough) {
    RecognizerOptions options;
    options.give_up_after_views = give_up_after;
    options.give_up_below_score = give_up_below;
    options.good_enough_score = good_enough;
    return Recognizer(library, options).Recognize(frame.rgbd);
  };
  const RecognitionResult every_view = recognize(0, 0.1, 0.0);
  const RecognitionResult three_views = recognize(3, 2.0, 0.0);  // scores lie in [0, 1]: none stays on
  ASSERT_EQ(every_view.views_tried.size(), 7U);
  ASSERT_EQ(three_views.views_tried.size(), 7U);
  for (const auto& [model, tried] : every_view.views_tried) {
    EXPECT_EQ(tried, RecognizerOptions().views_per_model) << model;
    EXPECT_EQ(three_views.views_tried.at(model), 3) << model;
  }

  const RecognitionResult given_up = recognize(4, 0.1, RecognizerOptions().good_enough_score);
  const RecognitionResult never = recognize(0, 0.1, RecognizerOptions().good_enough_score);
  EXPECT_EQ(RecognitionToJson(given_up).at("detections"), RecognitionToJson(never).at("detections"));
  EXPECT_EQ(given_up.detections.size(), 3U);
  int absent_given_up = 0;
  for (const auto& [model, tried] : given_up.views_tried) {
    const bool present = std::any_of(frame.ground_truth.begin(), frame.ground_truth.end(),
                                     [&](const GroundTruth& truth) { return truth.object_name == model; });
    if (!present && tried == 4) ++absent_given_up;
    EXPECT_LE(tried, never.views_tried.at(model)) << model;
  }
  EXPECT_GE(absent_given_up, 1);
}

TEST_F(YcbvLibrary, TracksTheThreeObjectsOfVideo0001FromFrameToFrame) {
  const std::string scenes = test::DataPath("ycbv_subset/Example-Scenes/0001/");
  const std::vector<std::string> frames = {scenes + "000001", scenes + "000003", scenes + "000005", scenes + "000007"};
  const std::string overlays = directory_->File("track_overlays");
  const std::vector<nlohmann::json> lines = Recognize("track", "--track --overlay " + overlays, frames);
  ASSERT_EQ(lines.size(), frames.size());
  for (const char* picture : {"/0001.png", "/0002.png", "/0003.png", "/0004.png"}) {  // one per frame, in order
    EXPECT_EQ(ReadColorImage(overlays + picture).size(), cv::Size(640, 480)) << picture;
  }
  EXPECT_FALSE(std::filesystem::exists(overlays + "/0005.png"));
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  const std::vector<EvalModel> models = EvalModels(library);
  for (size_t i = 0; i < frames.size(); ++i) {
    const FrameEvaluation evaluation = EvaluateFrame(frames[i], DetectionsFromJson(lines[i], frames[i]),
                                                     LoadYcbvFrame(frames[i]).ground_truth, models);
    ASSERT_EQ(evaluation.objects.size(), 3U);  // cracker box, sugar box, mustard bottle
    for (const ObjectEvaluation& object : evaluation.objects) EXPECT_TRUE(object.correct) << frames[i] << object.model;
    EXPECT_EQ(evaluation.false_positives, 0) << frames[i];
    // The first frame has no priors. The second confirms the three new tracks by a search, keeping the better pose
    // of each surface (the track's or the search's); the later ones keep all three at their previous poses.
    if (i == 1) continue;
    for (const nlohmann::json& detection : lines[i].at("detections")) {
      EXPECT_EQ(detection.at("tracked").get<bool>(), i > 1) << frames[i] << detection.dump();
    }
  }
}

// `--search-every 4`: frame 1 searches every model; frame 2 follows the three objects and searches their models
// again to confirm the new tracks; frames 3-4 follow them and, all of them holding, search nothing (no primitives
// extracted), with the same three objects found.
TEST_F(YcbvLibrary, BetweenFullSearchesOnlyTheTracksAreFollowed) {
  const std::string scenes = test::DataPath("ycbv_subset/Example-Scenes/0001/");
  const std::vector<std::string> frames = {scenes + "000001", scenes + "000003", scenes + "000005", scenes + "000007"};
  const std::vector<nlohmann::json> lines = Recognize("search_every", "--track --search-every 4", frames);
  ASSERT_EQ(lines.size(), frames.size());
  LibraryLoadOptions load;
  load.build_matchers = false;
  const std::vector<EvalModel> models = EvalModels(ModelLibrary::Load(library_, load));
  for (size_t i = 0; i < frames.size(); ++i) {
    const FrameEvaluation evaluation = EvaluateFrame(frames[i], DetectionsFromJson(lines[i], frames[i]),
                                                     LoadYcbvFrame(frames[i]).ground_truth, models);
    for (const ObjectEvaluation& object : evaluation.objects) EXPECT_TRUE(object.correct) << frames[i] << object.model;
    EXPECT_EQ(evaluation.false_positives, 0) << frames[i];
    const nlohmann::json& timings = lines[i].at("timings_ms");
    EXPECT_EQ(timings.contains("extract"), i <= 1) << frames[i] << timings.dump();
    EXPECT_EQ(timings.contains("ransac"), i <= 1) << frames[i] << timings.dump();
  }
}

// The CLI's --track follows the streaming rules of RecognitionStream, which the benchmarks use: the same detections
// frame by frame (video 0001, a full search every second frame).
TEST_F(YcbvLibrary, TheCliTracksAsTheRecognitionStreamDoes) {
  const std::string scenes = test::DataPath("ycbv_subset/Example-Scenes/0001/");
  const std::vector<std::string> frames = {scenes + "000001", scenes + "000003", scenes + "000005", scenes + "000007"};
  const std::vector<nlohmann::json> lines = Recognize("stream_cli", "--track --search-every 2 --threads 1", frames);
  ASSERT_EQ(lines.size(), frames.size());
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  RecognizerOptions options;
  options.threads = 1;
  Recognizer recognizer(library, options);
  RecognitionStream stream(recognizer, {true, 2});
  int tracked = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const RecognitionResult result = stream.Next(LoadYcbvFrame(frames[i]).rgbd);
    const nlohmann::json& cli = lines[i].at("detections");
    ASSERT_EQ(cli.size(), result.detections.size()) << frames[i] << lines[i].dump();
    for (size_t d = 0; d < cli.size(); ++d) {
      const Detection& ours = result.detections[d];
      EXPECT_EQ(cli[d].at("model").get<std::string>(), ours.model) << frames[i];
      EXPECT_EQ(cli[d].at("tracked").get<bool>(), ours.tracked) << frames[i] << ours.model;
      EXPECT_NEAR(cli[d].at("score").get<double>(), ours.score, 1e-12) << frames[i] << ours.model;
      const Eigen::Isometry3d pose = PoseFromJson(cli[d].at("camera_from_object"), frames[i], "camera_from_object");
      EXPECT_LT((pose.matrix() - ours.camera_from_object.matrix()).cwiseAbs().maxCoeff(), 1e-9) << frames[i];
      tracked += ours.tracked ? 1 : 0;
    }
    // Full searches in frames 1 and 3; frame 2 searches the models of its new tracks to confirm them.
    EXPECT_EQ(lines[i].at("timings_ms").contains("extract"), i <= 2) << frames[i];
  }
  EXPECT_GE(tracked, 6);  // frames 2-4 follow the three objects
}

// --search-beside on two threads: each frame only follows the objects it knows while a second recognizer searches on
// a thread of its own. Fed one frame at 30 per second (0001/000001), the stream returns nothing until the first search
// is done, then the frame after it holds that search's three objects, followed into it (tracked) at their poses, and
// the next frames keep them.
TEST_F(YcbvLibrary, TheSearchBesideTheTrackingBringsItsObjectsIntoTheFramesAfterIt) {
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(library_, load);
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  StreamOptions beside;
  beside.track = true;
  beside.search_beside = true;
  RecognizerOptions options;
  options.threads = 2;
  const StreamRecognizerOptions shared = ShareThreads(options, beside);
  EXPECT_EQ(shared.track.threads, 1);  // one thread tracks, one searches
  EXPECT_EQ(shared.search.threads, 1);
  Recognizer tracker(library, shared.track);
  RecognitionStream stream(tracker, beside, MakeRecognizerFactory(library, shared.search));

  // The searcher is made on its thread, then searches (seconds under the sanitizers): a bound, not a measure.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  std::optional<RecognitionResult> joined;
  int before = 0;
  while (!joined && std::chrono::steady_clock::now() < deadline) {
    RecognitionResult result = stream.Next(frame.rgbd);
    if (result.searched_frames_ago >= 0) {
      joined = std::move(result);
    } else {
      EXPECT_TRUE(result.detections.empty()) << "frame " << before;  // no search done: nothing to follow
      EXPECT_EQ(result.timings_ms.count("extract"), 0U) << "frame " << before;
      ++before;
      std::this_thread::sleep_for(std::chrono::milliseconds(33));
    }
  }
  ASSERT_TRUE(joined) << "no search done in 3 minutes";
  EXPECT_GE(before, 1);
  EXPECT_GE(joined->searched_frames_ago, 1);
  EXPECT_EQ(RecognitionToJson(*joined).at("searched_frames_ago"), joined->searched_frames_ago);
  std::vector<RecognitionResult> results = {*joined};
  for (int i = 0; i < 2; ++i) results.push_back(stream.Next(frame.rgbd));
  for (size_t i = 0; i < results.size(); ++i) {
    ASSERT_EQ(results[i].detections.size(), 3U) << "frame " << before + i;  // cracker box, sugar box, mustard bottle
    EXPECT_EQ(results[i].timings_ms.count("extract"), 0U) << "frame " << before + i;
    for (const Detection& detection : results[i].detections) {
      const auto truth = std::find_if(frame.ground_truth.begin(), frame.ground_truth.end(),
                                      [&](const GroundTruth& t) { return t.object_name == detection.model; });
      ASSERT_NE(truth, frame.ground_truth.end()) << detection.model;
      EXPECT_TRUE(detection.tracked) << detection.model;
      EXPECT_LT(TranslationDistance(detection.camera_from_object, truth->camera_from_object), 0.01) << detection.model;
      EXPECT_LT(RotationAngle(detection.camera_from_object, truth->camera_from_object), 10.0 * M_PI / 180.0)
          << detection.model;
    }
  }
}

TEST_F(YcbvLibrary, BrokenFrameInSequenceIsReportedAndTheOthersAreProcessed) {
  const std::string list = directory_->File("broken.txt"), out = directory_->File("broken.jsonl");
  const std::string missing = directory_->File("no_such_video/000001");
  std::ofstream(list) << Frames()[0] << '\n' << missing << '\n' << Frames()[1] << '\n';
  const test::CommandResult run =
      test::RunCli("recognize --db " + library_ + " --sequence " + list + " --out-json " + out);
  EXPECT_EQ(run.exit_code, 1) << run.output;  // bad input, reported at the end
  EXPECT_NE(run.output.find(missing), std::string::npos) << run.output;
  std::ifstream in(out);
  std::vector<nlohmann::json> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_EQ(lines[1].at("frame"), missing);
  EXPECT_NE(lines[1].at("error").get<std::string>().find(missing), std::string::npos);
  for (const size_t i : {0U, 2U}) {
    EXPECT_FALSE(lines[i].contains("error")) << lines[i].dump();
    EXPECT_FALSE(lines[i].at("detections").empty()) << lines[i].dump();  // gelatin box; cracker box
  }
}

// With --search-every, the frame after a broken one searches every model: its priors were lost with it.
TEST_F(YcbvLibrary, AfterABrokenFrameTheNextOneSearchesEveryModel) {
  const std::string list = directory_->File("broken_every.txt"), out = directory_->File("broken_every.jsonl");
  const std::string missing = directory_->File("no_such_video/000001");
  std::ofstream(list) << Frames()[1] << '\n' << missing << '\n' << Frames()[1] << '\n' << Frames()[1] << '\n';
  // --confirm-first 0: frame 4 follows frame 3's new tracks without confirming them, so that only the frame after the
  // broken one searches.
  const test::CommandResult run = test::RunCli("recognize --db " + library_ + " --sequence " + list + " --out-json " +
                                               out + " --track --search-every 10 --confirm-first 0");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  std::ifstream in(out);
  std::vector<nlohmann::json> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(lines.size(), 4U);
  EXPECT_TRUE(lines[1].contains("error"));
  // Frames 1 and 3 search (the first; the one after the broken frame), frame 4 follows frame 3's three objects.
  for (const size_t i : {0U, 2U, 3U}) {
    EXPECT_EQ(lines[i].at("detections").size(), 3U) << i << lines[i].dump();
    EXPECT_EQ(lines[i].at("timings_ms").contains("extract"), i != 3U) << i << lines[i].dump();
  }
}

}  // namespace
}  // namespace ecv
