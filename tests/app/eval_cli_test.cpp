// `ecvpose eval` over whole folders of real ground truth: the JSON Lines of `recognize --sequence` against the
// YCB-Video video 0001 (--gt-ycbv), and a BOP CSV against the LM-O scene 000002 (--gt-bop). The detections are
// built from the ground truth itself (some exact, some moved or turned, one frame missing, one failed), so the
// expected recall and false positives follow from the construction.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/frame_io.h"
#include "io/pose_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

class EvalCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = new test::TemporaryDirectory();
    // The three YCB meshes of models/ (all present in video 0001) and two LM-O models, two views each: eval
    // needs only their meshes, diameters and names.
    ycbv_library_ = directory_->File("ycbv.sqlite");
    const test::CommandResult ycbv =
        test::RunCli("modeldb build " + std::string(ECV_SOURCE_DIR) + "/models/meshes --views 2 --db " + ycbv_library_);
    ASSERT_EQ(ycbv.exit_code, 0) << ycbv.output;
    lmo_library_ = directory_->File("lmo.sqlite");
    const std::string models = test::DataPath("lmo_subset/data/bop/lmo/models");
    const test::CommandResult lmo = test::RunCli("modeldb build " + models + "/obj_000005.ply " + models +
                                                 "/obj_000008.ply --views 2 --unit mm --db " + lmo_library_);
    ASSERT_EQ(lmo.exit_code, 0) << lmo.output;
  }
  static void TearDownTestSuite() { delete directory_; }

  static std::string Write(const std::string& name, const std::string& text) {
    const std::string path = directory_->File(name);
    std::ofstream(path) << text;
    return path;
  }

  static test::TemporaryDirectory* directory_;
  static std::string ycbv_library_, lmo_library_;
};

test::TemporaryDirectory* EvalCli::directory_ = nullptr;
std::string EvalCli::ycbv_library_, EvalCli::lmo_library_;

nlohmann::json DetectionJson(const std::string& model, double score, const Eigen::Isometry3d& camera_from_object) {
  return {{"model", model}, {"score", score}, {"camera_from_object", PoseToJson(camera_from_object)}};
}

const nlohmann::json* FindObject(const nlohmann::json& frame, const std::string& model) {
  for (const nlohmann::json& object : frame.at("objects")) {
    if (object.at("model") == model) return &object;
  }
  return nullptr;
}

// Video 0001 has 10 frames with 002, 003, 004 and 006 in each; the library holds 003, 004 and 006 (30 objects).
// Frames 1-8 get 003 and 006 at their true pose (16 correct) and 004 moved by 5 cm (8 false positives), frame 1
// also a second, lower-scoring 003 (1 false positive); frame 5 is an "error" line and frame 10 has no line.
TEST_F(EvalCli, YcbVideoJsonLinesGiveTheConstructedRecallAndFalsePositives) {
  const std::string video = test::DataPath("ycbv_subset/Example-Scenes/0001");
  const std::vector<std::string> frames = ListSequenceFrames(video);
  ASSERT_EQ(frames.size(), 10U);
  std::ostringstream lines;
  for (size_t i = 0; i + 1 < frames.size(); ++i) {
    // The second frame is named by another path to the same file: frames match by video and frame name.
    const std::string name = i == 1 ? video + "/../0001/" + fs::path(frames[i]).filename().string() : frames[i];
    if (i == 4) {
      lines << nlohmann::json{{"frame", name}, {"error", "depth image: expected a 16-bit PNG"}}.dump() << '\n';
      continue;
    }
    nlohmann::json detections = nlohmann::json::array();
    for (const GroundTruth& truth : LoadYcbvFrame(frames[i]).ground_truth) {
      if (truth.object_name == "003_cracker_box" || truth.object_name == "006_mustard_bottle") {
        detections.push_back(DetectionJson(truth.object_name, 0.9, truth.camera_from_object));
      } else if (truth.object_name == "004_sugar_box") {
        const Eigen::Isometry3d moved = Eigen::Translation3d(0.05, 0.0, 0.0) * truth.camera_from_object;
        detections.push_back(DetectionJson(truth.object_name, 0.8, moved));
      }
      if (i == 0 && truth.object_name == "003_cracker_box") {
        detections.push_back(
            DetectionJson(truth.object_name, 0.5, Eigen::Translation3d(0.0, 0.1, 0.0) * truth.camera_from_object));
      }
    }
    lines << nlohmann::json{{"frame", name}, {"detections", detections}, {"timings_ms", {{"total", 1.0}}}}.dump()
          << '\n';
  }
  const std::string detections = Write("sequence.jsonl", lines.str());
  const std::string json = directory_->File("ycbv_eval.json");
  const test::CommandResult eval = test::RunCli("eval --db " + ycbv_library_ + " --detections " + detections +
                                                " --gt-ycbv " + video + " --out-json " + json);
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_THAT(eval.output, AllOf(HasSubstr("Recall at ADD < 0.1 d: 16 of 30"), HasSubstr("false positives: 9 "),
                                 HasSubstr("counted as missed (all their objects not detected): 2 of 10"),
                                 HasSubstr(frames[9] + ": no line in the detections"),
                                 HasSubstr(frames[4] + ": recognize failed: depth image"),
                                 HasSubstr("| 004_sugar_box | 10 | 8 | 0 | 0.0 % | 8 |"),
                                 HasSubstr("| 003_cracker_box | 10 | 8 | 8 | 80.0 % | 1 |")));

  const nlohmann::json result = ReadJsonFile(json);
  EXPECT_EQ(result.at("summary").at("objects"), 30);
  EXPECT_EQ(result.at("summary").at("correct"), 16);
  EXPECT_EQ(result.at("summary").at("false_positives"), 9);
  EXPECT_EQ(result.at("summary").at("frames_missed"), 2);
  ASSERT_EQ(result.at("frames").size(), 10U);
  const nlohmann::json& first = result.at("frames")[0];
  EXPECT_EQ(first.at("frame"), frames[0]);
  EXPECT_EQ(first.at("false_positives"), 2);
  ASSERT_EQ(first.at("objects").size(), 3U) << "002_master_chef_can is not in the library";
  const nlohmann::json* sugar = FindObject(first, "004_sugar_box");
  const nlohmann::json* cracker = FindObject(first, "003_cracker_box");
  ASSERT_TRUE(sugar != nullptr && cracker != nullptr) << first.dump();
  EXPECT_NEAR(sugar->at("translation_error_m").get<double>(), 0.05, 1e-6);
  EXPECT_NEAR(sugar->at("add_m").get<double>(), 0.05, 1e-5) << "a pure translation moves every point by 5 cm";
  EXPECT_NEAR(sugar->at("rotation_error_rad").get<double>(), 0.0, 1e-6);
  EXPECT_FALSE(sugar->at("correct").get<bool>());
  EXPECT_LT(cracker->at("add_m").get<double>(), 1e-5) << "the higher-scoring detection is the one judged";
  EXPECT_TRUE(cracker->at("correct").get<bool>());
  EXPECT_EQ(result.at("frames")[4].at("missed"), "recognize failed: depth image: expected a 16-bit PNG");

  // BOP's average recall of the same: the exact poses of 8 of 10 frames recall 0.8 at every threshold (frame 1's
  // second, lower-scoring cracker box is not taken for its single instance); the sugar box 5 cm off fails MSSD's
  // thresholds below 5 cm and VSD's (a 5 cm shift sideways leaves too little of its visible surface in common).
  const std::string bop_json = directory_->File("ycbv_bop.json");
  const test::CommandResult bop = test::RunCli("eval --db " + ycbv_library_ + " --detections " + detections +
                                               " --gt-ycbv " + video + " --metric bop --out-json " + bop_json);
  ASSERT_EQ(bop.exit_code, 0) << bop.output;
  EXPECT_THAT(bop.output, AllOf(HasSubstr("| 003_cracker_box | 10 | 0.800 | 0.800 | 0.800 | 0.800 |"),
                                HasSubstr("| 006_mustard_bottle | 10 | 0.800 | 0.800 | 0.800 | 0.800 |")));
  const nlohmann::json recall = ReadJsonFile(bop_json);
  EXPECT_EQ(recall.at("all").at("instances"), 30);
  const nlohmann::json& sugar_recall = recall.at("models").at("004_sugar_box");
  EXPECT_GT(sugar_recall.at("ar_mssd").get<double>(), 0.0) << "5 cm is within MSSD's largest thresholds";
  EXPECT_LT(sugar_recall.at("ar_mssd").get<double>(), 0.8);
  EXPECT_LT(sugar_recall.at("ar_vsd").get<double>(), 0.8);
  EXPECT_FALSE(FindObject(result.at("frames")[9], "006_mustard_bottle")->at("detected").get<bool>());
}

// LM-O image 3 as a BOP CSV straight from scene_gt.json: the can (obj 5) at its true pose, the driller (obj 8)
// turned by 90 degrees about its x axis.
TEST_F(EvalCli, BopCsvOnLmoSceneJudgesTheTurnedDrillerWrong) {
  const std::string scene = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  const nlohmann::json gt = ReadJsonFile(scene + "/scene_gt.json").at("3");
  std::ostringstream csv;
  csv << std::setprecision(12) << "scene_id,im_id,obj_id,score,R,t,time\n";
  for (const nlohmann::json& object : gt) {
    const int id = object.at("obj_id").get<int>();
    if (id != 5 && id != 8) continue;
    Eigen::Matrix3d r;
    for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = object.at("cam_R_m2c")[static_cast<size_t>(i)].get<double>();
    if (id == 8) r = r * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
    csv << 2 << ',' << 3 << ',' << id << ",0.7,";
    for (int i = 0; i < 9; ++i) csv << (i > 0 ? " " : "") << r(i / 3, i % 3);
    const nlohmann::json& t = object.at("cam_t_m2c");
    csv << ',' << t[0].get<double>() << ' ' << t[1].get<double>() << ' ' << t[2].get<double>() << ",0.25\n";
  }
  const std::string detections = Write("lmo.csv", csv.str());
  const std::string json = directory_->File("lmo_eval.json");
  const test::CommandResult eval = test::RunCli("eval --db " + lmo_library_ + " --detections " + detections +
                                                " --gt-bop " + scene + " --out-json " + json);
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_THAT(eval.output, AllOf(HasSubstr("Recall at ADD < 0.1 d: 1 of 2"), HasSubstr("false positives: 1 ")));
  EXPECT_THAT(eval.output, ::testing::Not(HasSubstr("missed"))) << "image 3 is the scene's one image";
  const nlohmann::json result = ReadJsonFile(json);
  ASSERT_EQ(result.at("frames").size(), 1U);
  EXPECT_EQ(result.at("frames")[0].at("frame"), scene + ":3");
  const nlohmann::json* can = FindObject(result.at("frames")[0], "obj_000005");
  const nlohmann::json* driller = FindObject(result.at("frames")[0], "obj_000008");
  ASSERT_TRUE(can != nullptr && driller != nullptr) << result.dump();
  EXPECT_TRUE(can->at("correct").get<bool>());
  EXPECT_LT(can->at("add_m").get<double>(), 1e-5);
  EXPECT_NEAR(driller->at("rotation_error_rad").get<double>(), M_PI / 2, 1e-6);
  EXPECT_NEAR(driller->at("translation_error_m").get<double>(), 0.0, 1e-9);
  EXPECT_FALSE(driller->at("correct").get<bool>());
  EXPECT_EQ(result.at("summary").at("false_positives"), 1);
}

// recognize --sequence over a BOP scene (a copy of LM-O scene 2 with the depth of image 3) writes JSON Lines and a
// BOP CSV; eval --gt-bop judges both alike. --min-score 0 keeps every model's best pose, so the CSV has rows
// (a CSV cannot tell a frame with no detection from a frame left out).
TEST_F(EvalCli, RecognizeSequenceOnBopSceneJudgedAlikeFromJsonLinesAndCsv) {
  const fs::path source = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  const fs::path scene = directory_->path() / "bop" / "000002";
  fs::create_directories(scene / "rgb");
  fs::create_directories(scene / "depth");
  for (const char* file : {"scene_camera.json", "scene_gt.json", "scene_gt_info.json", "rgb/000003.png"}) {
    fs::copy_file(source / file, scene / file, fs::copy_options::overwrite_existing);
  }
  fs::copy_file(test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png"), scene / "depth/000003.png",
                fs::copy_options::overwrite_existing);
  const std::string lines = directory_->File("bop.jsonl"), csv = directory_->File("bop.csv");
  const test::CommandResult run = test::RunCli("recognize --db " + lmo_library_ + " --sequence " + scene.string() +
                                               " --out-json " + lines + " --out-bop " + csv + " --min-score 0");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(lines);
  std::string first;
  ASSERT_TRUE(std::getline(in, first));
  EXPECT_EQ(nlohmann::json::parse(first).at("frame"), scene.string() + ":3");

  nlohmann::json results[2];
  for (int i = 0; i < 2; ++i) {
    const std::string json = directory_->File("bop_eval" + std::to_string(i) + ".json");
    const test::CommandResult eval =
        test::RunCli("eval --db " + lmo_library_ + " --detections " + (i == 0 ? lines : csv) + " --gt-bop " +
                     scene.string() + " --out-json " + json);
    ASSERT_EQ(eval.exit_code, 0) << eval.output;
    results[i] = ReadJsonFile(json);
  }
  EXPECT_EQ(results[0].at("summary"), results[1].at("summary"));
  ASSERT_EQ(results[0].at("frames").size(), 1U);
  ASSERT_EQ(results[1].at("frames").size(), 1U);
  for (const char* model : {"obj_000005", "obj_000008"}) {
    const nlohmann::json* a = FindObject(results[0].at("frames")[0], model);
    const nlohmann::json* b = FindObject(results[1].at("frames")[0], model);
    ASSERT_TRUE(a != nullptr && b != nullptr) << model;
    ASSERT_EQ(a->at("detected"), b->at("detected")) << model;
    if (!a->at("detected").get<bool>()) continue;
    // The CSV holds 6 significant digits (t in mm).
    EXPECT_NEAR(a->at("add_m").get<double>(), b->at("add_m").get<double>(), 1e-4) << model;
    EXPECT_NEAR(a->at("translation_error_m").get<double>(), b->at("translation_error_m").get<double>(), 1e-4);
    EXPECT_NEAR(a->at("rotation_error_rad").get<double>(), b->at("rotation_error_rad").get<double>(), 1e-4);
  }
}

TEST_F(EvalCli, OneFrameJsonStillWorks) {
  const std::string frame = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  nlohmann::json detections = nlohmann::json::array();
  for (const GroundTruth& truth : LoadYcbvFrame(frame).ground_truth) {
    if (truth.object_name != "002_master_chef_can") {
      detections.push_back(DetectionJson(truth.object_name, 0.9, truth.camera_from_object));
    }
  }
  const std::string path = Write("one.json", nlohmann::json{{"detections", detections}}.dump());
  const test::CommandResult eval = test::RunCli("eval --db " + ycbv_library_ + " --detections " + path + " " + frame);
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_THAT(eval.output, HasSubstr("Recall at ADD < 0.1 d: 3 of 3 (100.0 %); false positives: 0 "));
}

TEST_F(EvalCli, BadInputsNameFileLineAndField) {
  const std::string video = test::DataPath("ycbv_subset/Example-Scenes/0001");
  const std::string scene = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  const std::string good = nlohmann::json{{"frame", video + "/000001"}, {"detections", nlohmann::json::array()}}.dump();
  auto eval = [](const std::string& library, const std::string& detections, const std::string& truth) {
    return test::RunCli("eval --db " + library + " --detections " + detections + " " + truth);
  };

  const std::string broken = Write("broken.jsonl", good + "\n\n{\"frame\": \"" + video + "/000003\", \n");
  test::CommandResult run = eval(ycbv_library_, broken, "--gt-ycbv " + video);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(broken + ":3: JSON: expected one JSON object per line"));

  const std::string other =
      Write("other.jsonl", good + "\n" +
                               nlohmann::json{{"frame", test::DataPath("ycbv_subset/Example-Scenes/0000") + "/000001"},
                                              {"detections", nlohmann::json::array()}}
                                   .dump());
  run = eval(ycbv_library_, other, "--gt-ycbv " + video);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(other + ":2: frame: expected a frame of " + video));

  const std::string twice = Write("twice.jsonl", good + "\n" + good + "\n");
  run = eval(ycbv_library_, twice, "--gt-ycbv " + video);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(twice + ":2: frame: expected each frame once"));

  const std::string row = "2,3,5,0.5,1 0 0 0 1 0 0 0 1,0 0 1000,0.1\n";
  const std::string unknown = Write(
      "unknown.csv", "scene_id,im_id,obj_id,score,R,t,time\n" + row + "2,3,7,0.5,1 0 0 0 1 0 0 0 1,0 0 1000,0.1\n");
  run = eval(lmo_library_, unknown, "--gt-bop " + scene);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output,
              AllOf(HasSubstr(unknown + ":3: obj_id: expected a model of the library"), HasSubstr("'obj_000007'")));

  const std::string no_t = Write("no_t.csv", "scene_id,im_id,obj_id,score,R,time\n2,3,5,0.5,1 0 0 0 1 0 0 0 1,0.1\n");
  run = eval(lmo_library_, no_t, "--gt-bop " + scene);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(no_t + ":1: t: expected a column named so"));

  const std::string short_row =
      Write("short.csv", "scene_id,im_id,obj_id,score,R,t,time\n" + row + "2,3,5,0.5,1 0 0 0 1 0 0 0 1,0 0 1000\n");
  run = eval(lmo_library_, short_row, "--gt-bop " + scene);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(short_row + ":3: time: expected a value in column 7"));

  const std::string bad_r = Write("bad_r.csv", "scene_id,im_id,obj_id,score,R,t,time\n2,3,5,0.5,1 0 0 1,0 0 1,0\n");
  run = eval(lmo_library_, bad_r, "--gt-bop " + scene);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(bad_r + ":2: R: expected 9 numbers"));

  const std::string wrong_scene = Write("scene.csv", "scene_id,im_id,obj_id,score,R,t,time\n1" + row.substr(1));
  run = eval(lmo_library_, wrong_scene, "--gt-bop " + scene);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr(wrong_scene + ":2: scene_id: expected the scene of " + scene + " (2)"));

  run = eval(lmo_library_, unknown, "");
  EXPECT_EQ(run.exit_code, 2) << "neither FRAME nor a ground-truth folder: bad usage\n" << run.output;
}

}  // namespace
}  // namespace ecv
