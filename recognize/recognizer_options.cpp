#include "recognize/recognizer_options.h"

#include "core/error.h"
#include "core/parallel.h"

namespace ecv {

RansacOptions RecognizerOptions::DefaultRansac() {
  RansacOptions options;           // the paper's numbers, but:
  options.adaptive = true;         // stop once the best pose shows the sampled views are easy
  options.prefer_agreeing = true;  // rank poses by agreeing (appearance-bearing) correspondences
  options.max_iterations = 10000;  // fewer samples per view, spent on more views
  // A sample's pose is counted only when one correspondence in a hundred (at least one) agrees with it besides the
  // sample: most wrong samples are agreed with by their own three alone.
  options.min_support = 1;
  options.min_support_share = 0.01;
  return options;
}

MatchOptions RecognizerOptions::DefaultMatch() {
  MatchOptions options;
  options.exact_below = 100;  // a frame's ~1000 segments are faster in the kd-trees than searched linearly
  // Randomised kd-trees with small leaves and more checks: nearer neighbours than FLANN's defaults in less time
  // (bench/RESULTS.md, matching_bench).
  options.index = MatchIndex::kKdForest;
  options.trees = 4;
  options.leaf_size = 8;
  options.checks = 128;
  return options;
}

const char* HypothesisSourceName(HypothesisSource source) {
  switch (source) {
    case HypothesisSource::kContext: return "context";
    case HypothesisSource::kPpf: return "ppf";
    case HypothesisSource::kBoth: return "both";
  }
  return "context";
}

HypothesisSource ParseHypothesisSource(const std::string& name, const std::string& what) {
  for (const HypothesisSource source : {HypothesisSource::kContext, HypothesisSource::kPpf, HypothesisSource::kBoth}) {
    if (name == HypothesisSourceName(source)) return source;
  }
  ThrowInputError(what, "hypotheses", "context, ppf or both", "'" + name + "'");
}

const char* AcceptanceName(Acceptance acceptance) {
  return acceptance == Acceptance::kLearned ? "learned" : "hand";
}

Acceptance ParseAcceptance(const std::string& name, const std::string& what) {
  for (const Acceptance acceptance : {Acceptance::kHandSet, Acceptance::kLearned}) {
    if (name == AcceptanceName(acceptance)) return acceptance;
  }
  ThrowInputError(what, "acceptance", "hand or learned", "'" + name + "'");
}

void TwinOptions::Check() const {
  const auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("recognizer options", field, expected);
  };
  require(min_gain >= 1.0 && min_gain <= 10.0, "twins.min_gain", "in [1, 10]");
  require(fit_margin_m >= 0.0 && fit_margin_m <= 0.1, "twins.fit_margin_m", "in [0, 0.1] metres");
  require(contour_margin >= 0.0 && contour_margin <= 1.0, "twins.contour_margin", "in [0, 1]");
}

void RecognizerOptions::Check() const {
  match.Check();
  ransac.Check();
  icp.Check();
  verify.Check();
  ranking.consistency.Check();
  point_pairs.ppf.Check();
  point_pairs.plane.Check();
  twins.Check();
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("recognizer options", field, expected);
  };
  require(threads >= 1 && threads <= kMaxThreads, "threads", "1 to 256");
  require(ranking.max_correspondences >= 3, "ranking.max_correspondences", "at least 3");
  require(ranking.checks >= 0, "ranking.checks", "0 (match.checks) or more");
  require(preselect.models >= 0, "preselect.models", ">= 0 (0: search every model)");
  require(preselect.rows >= 3, "preselect.rows", "at least 3");
  require(preselect.checks >= 0, "preselect.checks", "0 (match.checks) or more");
  require(preselect.shape_models >= 0, "preselect.shape_models", ">= 0 (0: none)");
  require(tracking.min_follow_score >= 0.0 && tracking.min_follow_score <= 1.0, "tracking.min_follow_score",
          "in [0, 1]");
  require(tracking.confirm_every >= 0, "tracking.confirm_every", ">= 0 (0: never)");
  require(tracking.confirm_first >= 0, "tracking.confirm_first", ">= 0 (0: at confirm_every)");
  require(views_per_model >= 1, "views_per_model", "at least 1");
  require(good_enough_score >= 0.0, "good_enough_score", ">= 0 (0: try every ranked view)");
  require(give_up_after_views >= 0, "give_up_after_views", ">= 0 (0: never give up)");
  require(give_up_below_score >= 0.0, "give_up_below_score", ">= 0");
  require(rival_min_ratio >= 0.0 && rival_min_ratio <= 1.0, "rival_min_ratio", "in [0, 1] (0: no rival refined)");
  require(scene_max_neighbours >= 0, "scene_max_neighbours", ">= 0 (0: the library's setting)");
  require(scene_max_descriptors >= 0, "scene_max_descriptors", ">= 0 (0: every primitive)");
  require(sample_radius_diameters >= 0.0, "sample_radius_diameters", ">= 0 (0: sample anywhere)");
  require(dense_stride_px >= 1, "dense_stride_px", "at least 1");
  require(ransac_stride_px >= 1, "ransac_stride_px", "at least 1");
  require(icp_max_points >= 0, "icp_max_points", ">= 0 (0: all)");
  require(max_overlap >= 0.0 && max_overlap <= 1.0, "max_overlap", "in [0, 1]");
  require(max_instances >= 1, "max_instances", "at least 1");
  require(later_instance_views >= 0, "later_instance_views", ">= 0 (0: views_per_model)");
  require(point_pairs.clusters >= 1, "point_pairs.clusters", "at least 1");
  require(point_pairs.model_samples >= 100, "point_pairs.model_samples", "at least 100");
}

}  // namespace ecv
