#pragma once

#include "ecv/matching.h"
#include "recognize/scoring.h"
#include "recognize/verification.h"
#include "registration/icp.h"
#include "registration/ppf.h"
#include "registration/ransac.h"

namespace ecv {

/// View ranking: a model's library views ordered by the largest pairwise-consistent set among their
/// object-to-scene correspondences (ConsistentSetSize), best first; RANSAC tries them in that order.
struct RankingOptions {
  /// When two correspondences agree; max_distance_m is set to each model's diameter.
  ConsistencyOptions consistency;
  /// Per view, at most this many of its descriptors (a seeded random subset) are matched for the ranking.
  int max_correspondences = 200;
  /// Descriptors compared per ranking query (0: MatchOptions::checks). Fewer rank faster and less well.
  int checks = 0;
};

/// Pre-selection of candidate models, for large libraries: every model's views are ranked quickly (fewer descriptors
/// per view, fewer checks than the search's ranking), and only the `models` models whose best view ranks highest are
/// searched (ranking, RANSAC, point pairs, verification). A library of more models loads each mesh when it is first
/// verified.
struct PreselectOptions {
  /// Models searched per frame (0: every model; tracked models are not counted). So that a large library costs
  /// about what a 16-model one does beyond the quick ranking, and its distractors cannot all be tried.
  int models = 16;
  int rows = 100;   ///< descriptors of each view ranked (a seeded random subset, as the search's ranking takes)
  int checks = 32;  ///< descriptors compared per query (0: MatchOptions::checks)
  /// Models left out by the ranking that are also searched, by point pairs alone: those whose shape best fits the
  /// surface no detection explains (a coarse table of their stored points voted there, most votes per table point
  /// first). Plain and thin objects, whose views rank low, are found by their shape (0: none).
  int shape_models = 4;
};

/// Tracking between the frames of a stream (Recognizer::Recognize with priors).
struct TrackingOptions {
  /// A detection is followed into the next frame only while it scores at least this, whether a search found it or
  /// it was followed itself: a track keeps earning the bar it started from. Below it (down to VerifyOptions::min_score)
  /// a detection is reported, and its model searched for afresh in the next frame. The default is verification's
  /// own bar: what is reported is followed, and a wrong track loses to a better-supported detection on its surface.
  double min_follow_score = 0.3;
  /// A followed object's model is searched for again (view ranking and RANSAC, as without priors) once it has been
  /// followed this many frames since a search last found it. The search's and the track's poses then compete on
  /// score: one on the same surface confirms the track, a better one elsewhere replaces it. 0: never.
  int confirm_every = 5;
  /// A track no search has confirmed yet is due once followed this many frames instead (1: in the frame after the
  /// search that found it): a wrong first detection would otherwise keep its model from being searched for
  /// confirm_every frames. 0: at confirm_every as the others; unused when confirm_every is 0.
  int confirm_first = 1;
};

/// What a tracking frame (Recognizer::Recognize with priors) searches for, by view ranking and RANSAC, besides
/// following its priors.
enum class SearchScope {
  kAllModels,  ///< every model whose prior fails or that has none: a full detection frame
  /// Only the models whose prior failed or fell below TrackingOptions::min_follow_score (a lost track is looked for at
  /// once) or whose track is due for confirmation (TrackingOptions::confirm_every); models without a prior are not
  /// looked for. When every prior passes and none is due, the frame's primitives are not even
  /// extracted. RecognitionStream alternates it with full frames to follow known objects at a fraction of the cost
  /// and still pick up new ones every N frames.
  kLostTracks,
  /// No model is searched, not even for confirmation: the priors are followed, nothing else (RecognitionStream's
  /// tracking when the search runs beside it, StreamOptions::search_beside).
  kPriorsOnly,
};

/// Where pose hypotheses come from: the shape and appearance context descriptors (view ranking and RANSAC), point
/// pair features of the model's surface (shape alone), or both, point pairs for the models the context did not find.
enum class HypothesisSource { kContext, kPpf, kBoth };

/// "context", "ppf" or "both".
const char* HypothesisSourceName(HypothesisSource source);
/// The source called `name`; throws InputError naming `what` otherwise.
HypothesisSource ParseHypothesisSource(const std::string& name, const std::string& what);

/// How a verified pose is accepted as a detection: by the hand-set rule (its score at least verify.min_score), or by
/// the learned model's probability that it is right (AcceptanceModel::Learned, at its threshold); both also ask
/// for verify.min_visible_fraction.
enum class Acceptance { kHandSet, kLearned };

/// "hand" or "learned".
const char* AcceptanceName(Acceptance acceptance);
/// The acceptance called `name`; throws InputError naming `what` otherwise.
Acceptance ParseAcceptance(const std::string& name, const std::string& what);

/// Shape-driven hypotheses: point pair features (registration/ppf.h) voted on the scene's depth samples (at
/// dense_stride_px), the best pose clusters refined by ICP and verified as the context's poses are.
struct PointPairOptions {
  HypothesisSource source = HypothesisSource::kBoth;
  PpfOptions ppf;
  /// The scene's dominant plane (a table top) is left out of the voting when it holds at least min_share of the
  /// scene's points (remove_plane false: never).
  bool remove_plane = true;
  ScenePlaneOptions plane;
  int clusters = 5;  ///< the best pose clusters refined and verified per model
  /// Points spread over a model's mesh before sub-sampling. A library's stored points are used when they were drawn
  /// alike (PpfModelSampling); otherwise the model's points are drawn from its mesh when the recognizer loads.
  int model_samples = PpfModelSampling().samples;
};

/// A near-symmetric object's sides: a box's front and back, a can's print and a banana's ends fit the depth alike,
/// so that a pose from the wrong side is turned 180 degrees from the truth with its surface in place. Each searched
/// model's best pose is also verified turned 180 degrees about each of the model's principal axes (through the middle
/// of its extent), each turn refined by ICP when it scored RecognizerOptions::rival_min_ratio of the pose.
struct TwinOptions {
  bool enabled = true;
  /// A turn replaces the pose only when it scores at least this many times the pose's score: the pose has RANSAC's
  /// correspondences behind it, the turn none.
  double min_gain = 1.1;
  /// Geometry first: and only when it fits the depth as well, its mean surface residual at most fit_margin_m above
  /// the pose's (metres) and its share of outline on depth steps at most contour_margin below: appearance tells sides
  /// apart only where the shape cannot (a banana's two ends have the same yellow, but not the same curve).
  double fit_margin_m = 0.001;
  double contour_margin = 0.1;

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// Settings of the online recognizer (paper Sect. III and IV-C, and what goes beyond it). bench/RESULTS.md,
/// "Recognizer defaults", gives the measurements behind each default.
struct RecognizerOptions {
  MatchOptions match = DefaultMatch();
  /// The Recognizer's workers: they describe the scene and then take a model each (a model's RANSAC shares the spare
  /// ones); the detections do not depend on the count.
  int threads = 1;
  /// RANSAC per model view: the paper's test (t_poly 0.25, eps 1 cm, 50 % of the visible object points). Its
  /// `threads` are set per search from `threads`.
  RansacOptions ransac = DefaultRansac();
  RankingOptions ranking;
  PreselectOptions preselect;
  VerifyOptions verify;
  TrackingOptions tracking;
  PointPairOptions point_pairs;
  Acceptance acceptance = Acceptance::kHandSet;

  /// Views per model tried with RANSAC, the best ranked first.
  int views_per_model = 10;
  /// A model's remaining views are not tried once one verifies at this score (0: try views_per_model).
  double good_enough_score = 0.5;
  /// A model whose first give_up_after_views views all verify below give_up_below_score is taken to be absent:
  /// its remaining views are not tried (0: never give up). Not applied to a model's later instances. A best pose
  /// (refined) verifying below give_up_below_score is not turned (twins): with next to none of its surface on the
  /// frame's, no turn makes it right, and the turns were most of the time spent on absent models.
  int give_up_after_views = 4;
  double give_up_below_score = 0.1;
  /// Beyond the best verified pose of a model, its best pose turned more than 90 degrees from it is refined and
  /// verified too when it scored at least this share of the best (0: never): coarse poses of a bottle's front and
  /// back score alike before ICP, and which one is refined decides.
  double rival_min_ratio = 0.7;
  /// Each searched model's best pose is also tried turned 180 degrees about the model's principal axes.
  TwinOptions twins;
  /// The scene's contexts take at most this many neighbours when the library's setting allows more (0: the
  /// library's): pairs grow with its square, so it bounds the describe time of close-ups.
  int scene_max_neighbours = 128;
  /// A scene with more primitives describes only every n-th of them (the smallest n that keeps the sources at or
  /// under this); all of them still form the contexts. 0: every primitive.
  int scene_max_descriptors = 8000;
  /// A RANSAC sample's later correspondences are drawn within this many model diameters of its first one
  /// (RansacOptions::sample_radius_m); 0 draws them anywhere.
  double sample_radius_diameters = 1.0;
  int dense_stride_px = 2;   ///< scene depth points for ICP and verification: every n-th pixel
  int ransac_stride_px = 4;  ///< scene depth samples for RANSAC's inlier count: every n-th pixel
  /// RANSAC looks for an object point's inlier partner among the 3 x 3 depth samples around the pixel it projects
  /// to (RansacOptions::projective_stride_px) instead of the nearest scene point in 3D.
  bool projective_inliers = true;
  bool refine = true;  ///< point-to-plane ICP of accepted poses against the scene
  /// ICP takes the model's surface as rendered at the pose (every dense_stride_px-th pixel), at most this many
  /// points of it (every n-th; 0: all).
  int icp_max_points = 3000;
  IcpOptions icp;
  /// ICP pairs each model point with the scene sample it projects to (7x faster, narrower basin) instead of the
  /// nearest scene point in 3D.
  bool projective_icp = false;
  /// A detection whose surface pixels lie for more than this share on pixels that a better detection of another
  /// model explains is dropped (one surface, one object); a model's later instances likewise against its earlier.
  double max_overlap = 0.3;
  /// Instances of one model looked for per frame (e.g. a bin of identical parts); 1: the best pose only.
  int max_instances = 1;
  /// Views tried for each instance after a model's first: it is known to be in the frame (0: views_per_model).
  int later_instance_views = 21;
  /// Keep every pose the acceptance judged in RecognitionResult::judged, accepted or not: the records an acceptance
  /// is learned from.
  bool keep_judged = false;
  /// Keep every pose verified in RecognitionResult::verified: where a search's hypotheses were right and where not.
  bool keep_verified = false;

  /// The paper's RANSAC with adaptive stopping, poses ranked by agreeing correspondences, at most 10 000 samples
  /// per view, and a sample counted only when 1 % of the correspondences (at least 1) agree with it.
  static RansacOptions DefaultRansac();
  /// ecvpose's KdForest (4 trees, leaves of 8, 128 checks), approximate from 100 train descriptors on.
  static MatchOptions DefaultMatch();
  /// Throws InputError on values outside their ranges.
  void Check() const;
  /// Compared descriptors per view-ranking query: ranking.checks, or match.checks when it is 0.
  int RankingChecks() const { return ranking.checks > 0 ? ranking.checks : match.checks; }
};

}  // namespace ecv
