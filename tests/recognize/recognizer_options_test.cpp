// RecognizerOptions::Check: every value out of its range is refused, naming the field.
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "recognize/recognizer_options.h"

namespace ecv {
namespace {

TEST(RecognizerOptions, OutOfRangeValuesAreReportedByName) {
  EXPECT_NO_THROW(RecognizerOptions().Check());
  auto message = [](const RecognizerOptions& options) {
    try {
      options.Check();
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  RecognizerOptions options;
  options.ransac_stride_px = 0;
  EXPECT_NE(message(options).find("ransac_stride_px"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.dense_stride_px = 0;
  EXPECT_NE(message(options).find("dense_stride_px"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.scene_max_descriptors = -1;
  EXPECT_NE(message(options).find("scene_max_descriptors"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.icp_max_points = -1;
  EXPECT_NE(message(options).find("icp_max_points"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.verify.min_score = 1.5;
  EXPECT_NE(message(options).find("min_score"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.verify.residual_falloff_m = -0.001;
  EXPECT_NE(message(options).find("residual_falloff_m"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.max_instances = 0;
  EXPECT_NE(message(options).find("max_instances"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.tracking.min_follow_score = -0.1;
  EXPECT_NE(message(options).find("tracking.min_follow_score"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.tracking.confirm_every = -1;
  EXPECT_NE(message(options).find("tracking.confirm_every"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.later_instance_views = -1;
  EXPECT_NE(message(options).find("later_instance_views"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.verify.max_texture_size = 0;
  EXPECT_NE(message(options).find("max_texture_size"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.good_enough_score = -0.1;
  EXPECT_NE(message(options).find("good_enough_score"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.give_up_after_views = -1;
  EXPECT_NE(message(options).find("give_up_after_views"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.give_up_below_score = -0.1;
  EXPECT_NE(message(options).find("give_up_below_score"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.verify.edge_weight = 1.2;
  EXPECT_NE(message(options).find("edge_weight"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.verify.min_edge_pixels = 0;
  EXPECT_NE(message(options).find("min_edge_pixels"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.verify.edge.weak = -1.0;
  EXPECT_NE(message(options).find("weak"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.rival_min_ratio = -0.5;
  EXPECT_NE(message(options).find("rival_min_ratio"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.point_pairs.clusters = 0;
  EXPECT_NE(message(options).find("point_pairs.clusters"), std::string::npos) << message(options);
  options = RecognizerOptions();
  options.point_pairs.ppf.spread_margin = 0.7;
  EXPECT_NE(message(options).find("spread_margin"), std::string::npos) << message(options);
}

}  // namespace
}  // namespace ecv
