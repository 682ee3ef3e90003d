// BOP's task files: the targets file, the results CSV written and read back, and ground truth named after the
// library's models.

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/pose.h"
#include "recognize/bop_task.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string Write(const test::TemporaryDirectory& directory, const std::string& name, const std::string& text) {
  const std::string path = directory.File(name);
  std::ofstream(path) << text;
  return path;
}

// The InputError message of `read`, or "" when it throws none.
template <typename Read>
std::string ErrorOf(Read read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(BopTask, TargetsAreGroupedByImageInSceneThenImageOrder) {
  test::TemporaryDirectory directory;
  const std::string path = Write(directory, "targets.json",
                                 R"([{"im_id": 7, "inst_count": 2, "obj_id": 5, "scene_id": 3},
                                     {"im_id": 1, "inst_count": 1, "obj_id": 9, "scene_id": 3},
                                     {"im_id": 7, "inst_count": 1, "obj_id": 1, "scene_id": 3},
                                     {"im_id": 4, "inst_count": 1, "obj_id": 5, "scene_id": 2}])");
  const std::vector<BopTarget> targets = ReadBopTargets(path);
  ASSERT_EQ(targets.size(), 4U);
  EXPECT_EQ(targets[0].instances, 2);
  const std::vector<BopImage> images = GroupBopTargets(targets, path);
  ASSERT_EQ(images.size(), 3U);
  EXPECT_EQ(images[0].key(), std::make_pair(2, 4));
  EXPECT_EQ(images[1].key(), std::make_pair(3, 1));
  EXPECT_EQ(images[2].key(), std::make_pair(3, 7));
  EXPECT_EQ(images[2].objects, (std::map<int, int>{{1, 1}, {5, 2}}));

  std::set<int> missing;
  EXPECT_EQ(TargetModels(images[2], {{5, "obj_000005"}, {8, "obj_000008"}}, &missing),
            (std::map<std::string, int>{{"obj_000005", 2}}));
  EXPECT_EQ(missing, std::set<int>{1});
}

TEST(BopTask, BadTargetsAreNamedByFileEntryAndField) {
  test::TemporaryDirectory directory;
  const std::string text_id = Write(directory, "a.json", R"([{"im_id": 1, "inst_count": 1, "obj_id": 1, "scene_id": 0},
                                                             {"im_id": 1, "inst_count": 1, "obj_id": "5", "scene_id": 0}])");
  EXPECT_THAT(ErrorOf([&] { ReadBopTargets(text_id); }), AllOf(HasSubstr("a.json: [1]"), HasSubstr("obj_id")));
  const std::string none = Write(directory, "b.json", R"([{"im_id": 1, "inst_count": 0, "obj_id": 1, "scene_id": 0}])");
  EXPECT_THAT(ErrorOf([&] { ReadBopTargets(none); }), AllOf(HasSubstr("[0]"), HasSubstr("inst_count")));
  const std::string object = Write(directory, "c.json", R"({"im_id": 1})");
  EXPECT_THAT(ErrorOf([&] { ReadBopTargets(object); }), HasSubstr("an array"));
  const std::string twice = Write(directory, "d.json", R"([{"im_id": 1, "inst_count": 1, "obj_id": 4, "scene_id": 0},
                                                          {"im_id": 1, "inst_count": 2, "obj_id": 4, "scene_id": 0}])");
  EXPECT_THAT(ErrorOf([&] { GroupBopTargets(ReadBopTargets(twice), twice); }), HasSubstr("4 is listed twice"));
}

TEST(BopTask, ResultsWrittenAndReadBackKeepPoseScoreAndImage) {
  test::TemporaryDirectory directory;
  Detection a;
  a.model = "002_master_chef_can";
  a.score = 0.8125;
  a.camera_from_object = Eigen::Translation3d(0.1234567, -0.05, 0.9) *
                         Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized());
  Detection b = a;
  b.model = "obj_000005";
  b.score = 0.25;
  std::ostringstream csv;
  csv << kBopCsvHeader;
  WriteBopRows(csv, {1, 3}, {a, b}, {{"002_master_chef_can", 1}, {"obj_000005", 5}}, 1.5);
  WriteBopRows(csv, {2, 0}, {b}, {{"obj_000005", 5}}, 0.25);
  EXPECT_THAT(csv.str(), HasSubstr("\n1,3,1,0.8125,"));
  const std::string path = Write(directory, "results.csv", csv.str());
  const std::map<int, std::string> models = {{1, "002_master_chef_can"}, {5, "obj_000005"}};
  const auto results = ReadBopResults(path, models);
  ASSERT_EQ(results.size(), 2U);
  const std::vector<Detection>& first = results.at({1, 3});
  ASSERT_EQ(first.size(), 2U);
  EXPECT_EQ(first[0].model, "002_master_chef_can");
  EXPECT_EQ(first[1].model, "obj_000005");
  EXPECT_DOUBLE_EQ(first[0].score, 0.8125);
  EXPECT_LT(TranslationDistance(first[0].camera_from_object, a.camera_from_object), 1e-9);
  EXPECT_LT(RotationAngle(first[0].camera_from_object, a.camera_from_object), 1e-7);
  EXPECT_EQ(results.at({2, 0}).size(), 1U);

  // Each malformed row is named by its line and field.
  const std::string row = "1,3,5,0.5,1 0 0 0 1 0 0 0 1,1 2 3,0.1\n";
  const auto error = [&](const std::string& text) {
    const std::string bad = Write(directory, "bad.csv", kBopCsvHeader + row + text);
    return ErrorOf([&] { ReadBopResults(bad, models); });
  };
  EXPECT_EQ(error(""), "");
  EXPECT_THAT(error("1,3,5,0.5,1 0 0 0 1 0 0 0 1,1 2 3\n"), AllOf(HasSubstr("bad.csv:3"), HasSubstr("columns")));
  EXPECT_THAT(error("1,3,5,0.5,1 0 0 0 1 0 0 0,1 2 3,0.1\n"), AllOf(HasSubstr("bad.csv:3"), HasSubstr("R")));
  EXPECT_THAT(error("1,3,7,0.5,1 0 0 0 1 0 0 0 1,1 2 3,0.1\n"), AllOf(HasSubstr("bad.csv:3"), HasSubstr("obj_id")));
  EXPECT_THAT(error("1,-3,5,0.5,1 0 0 0 1 0 0 0 1,1 2 3,0.1\n"), HasSubstr("im_id"));
  EXPECT_THAT(error("1,3,5,nan,1 0 0 0 1 0 0 0 1,1 2 3,0.1\n"), HasSubstr("score"));
  EXPECT_THAT(error("1,3,5,0.5,2 0 0 0 1 0 0 0 1,1 2 3,0.1\n"), HasSubstr("R"));  // no rotation
  const std::string header = Write(directory, "header.csv", "scene,im\n" + row);
  EXPECT_THAT(ErrorOf([&] { ReadBopResults(header, models); }), AllOf(HasSubstr("header.csv:1"), HasSubstr("header")));
}

TEST(BopTask, GroundTruthIsNamedAfterTheLibrarysModelOfItsObjectId) {
  std::vector<GroundTruth> truth(3);
  truth[0].object_id = 1;
  truth[0].object_name = "obj_000001";
  truth[1].object_id = 5;
  truth[1].object_name = "obj_000005";  // the library's own name: kept
  truth[2].object_id = 9;
  truth[2].object_name = "obj_000009";  // no model: kept
  NameTruthAfterModels({{1, "002_master_chef_can"}, {5, "obj_000005"}}, &truth);
  EXPECT_EQ(truth[0].object_name, "002_master_chef_can");
  EXPECT_EQ(truth[1].object_name, "obj_000005");
  EXPECT_EQ(truth[2].object_name, "obj_000009");
}

}  // namespace
}  // namespace ecv
