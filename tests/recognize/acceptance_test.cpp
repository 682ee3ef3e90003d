// The learned acceptance's model: its probability as the formula gives it, the model file's errors by field, and the
// model that ships.
#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "recognize/acceptance.h"

namespace ecv {
namespace {

nlohmann::json TwoTermModel() {
  return {{"kind", "logistic"},     {"terms", {"depth_agreement", "ppf"}},
          {"mean", {0.5, 0.0}},     {"scale", {0.25, 1.0}},
          {"weights", {2.0, -1.0}}, {"bias", 0.5},
          {"threshold", 0.7}};
}

// The message of FromJson's refusal of `json` ("" when it reads it).
std::string Refusal(const nlohmann::json& json) {
  try {
    AcceptanceModel::FromJson(json, "model.json");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(AcceptanceModel, GivesTheLogisticOfItsStandardisedTerms) {
  const AcceptanceModel model = AcceptanceModel::FromJson(TwoTermModel(), "model.json");
  EXPECT_EQ(model.threshold(), 0.7);
  Detection detection;
  detection.depth_agreement = 0.75;                      // (0.75 - 0.5) / 0.25 = 1, weighed 2
  detection.hypothesis_source = HypothesisSource::kPpf;  // 1, weighed -1
  EXPECT_NEAR(model.Probability(detection), 1.0 / (1.0 + std::exp(-(0.5 + 2.0 - 1.0))), 1e-12);
  detection.hypothesis_source = HypothesisSource::kContext;
  EXPECT_NEAR(model.Probability(detection), 1.0 / (1.0 + std::exp(-2.5)), 1e-12);
}

TEST(AcceptanceModel, RefusesAModelFileByField) {
  EXPECT_EQ(Refusal(TwoTermModel()), "");
  nlohmann::json json = TwoTermModel();
  json["terms"][1] = "luck";
  EXPECT_THAT(Refusal(json), ::testing::AllOf(::testing::HasSubstr("model.json"), ::testing::HasSubstr("terms"),
                                              ::testing::HasSubstr("luck")));
  json = TwoTermModel();
  json["mean"] = {0.5};
  EXPECT_THAT(Refusal(json), ::testing::HasSubstr("mean"));
  json = TwoTermModel();
  json["scale"][0] = 0.0;
  EXPECT_THAT(Refusal(json), ::testing::HasSubstr("scale"));
  json = TwoTermModel();
  json["threshold"] = 1.5;
  EXPECT_THAT(Refusal(json), ::testing::HasSubstr("threshold"));
  json = TwoTermModel();
  json.erase("bias");
  EXPECT_THAT(Refusal(json), ::testing::HasSubstr("bias"));
  json = TwoTermModel();
  json["kind"] = "forest";
  EXPECT_THAT(Refusal(json), ::testing::HasSubstr("kind"));
  EXPECT_THAT(Refusal(nlohmann::json::array()), ::testing::HasSubstr("JSON object"));
}

TEST(AcceptanceModel, TheShippedModelWeighsKnownTermsAndSeparatesAClearCase) {
  const AcceptanceModel& learned = AcceptanceModel::Learned();
  EXPECT_GT(learned.threshold(), 0.0);
  EXPECT_LT(learned.threshold(), 1.0);
  Detection right;  // a pose the frame confirms in every respect
  right.depth_agreement = right.color_agreement = right.edge_agreement = 0.95;
  right.edge_pixels = 2000;
  right.surface_error_m = 0.002;
  right.contour_agreement = right.occluding_contour = 0.6;
  right.visible_fraction = right.inlier_fraction = right.explained_surface = 0.9;
  Detection wrong = right;  // ... and one it contradicts
  wrong.depth_agreement = wrong.explained_surface = 0.3;
  wrong.color_agreement = wrong.edge_agreement = 0.1;
  wrong.surface_error_m = 0.009;
  wrong.contour_agreement = wrong.occluding_contour = 0.05;
  wrong.free_space_violation = 0.5;
  EXPECT_GE(learned.Probability(right), learned.threshold());
  EXPECT_LT(learned.Probability(wrong), learned.threshold());
}

}  // namespace
}  // namespace ecv
