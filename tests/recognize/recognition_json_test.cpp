// Detections to JSON and back (RecognitionToJson, DetectionsFromJson).
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "recognize/recognition_json.h"

namespace ecv {
namespace {

// Each detection's source of hypotheses survives the JSON; a source that is no detection's is refused by name.
TEST(RecognitionJson, KeepsEachDetectionsHypothesisSource) {
  RecognitionResult result;
  result.detections.resize(2);
  result.detections[0].model = "011_banana";
  result.detections[0].hypothesis_source = HypothesisSource::kPpf;
  result.detections[1].model = "006_mustard_bottle";
  nlohmann::json json = RecognitionToJson(result);
  EXPECT_EQ(json["detections"][0]["hypothesis"], "ppf");
  EXPECT_EQ(json["detections"][1]["hypothesis"], "context");
  const std::vector<Detection> read = DetectionsFromJson(json, "detections.json");
  ASSERT_EQ(read.size(), 2U);
  EXPECT_EQ(read[0].hypothesis_source, HypothesisSource::kPpf);
  EXPECT_EQ(read[1].hypothesis_source, HypothesisSource::kContext);
  // The message of DetectionsFromJson's refusal of `json` ("" when it reads it).
  const auto refusal = [](const nlohmann::json& edited) {
    try {
      DetectionsFromJson(edited, "detections.json");
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  json["detections"][0]["hypothesis"] = "both";
  EXPECT_THAT(refusal(json), ::testing::HasSubstr("detections[0].hypothesis"));
  json["detections"][0]["hypothesis"] = "ppf";
  json["detections"][0]["score"] = "high";
  EXPECT_THAT(refusal(json), ::testing::HasSubstr("detections[0].score"));
  EXPECT_EQ(ParseHypothesisSource("both", "--hypotheses"), HypothesisSource::kBoth);
  EXPECT_THROW(ParseHypothesisSource("shape", "--hypotheses"), InputError);
}

}  // namespace
}  // namespace ecv
