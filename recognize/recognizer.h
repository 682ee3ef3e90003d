#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/frame.h"
#include "ecv/matching.h"
#include "ecv/primitives.h"
#include "modeldb/model_library.h"
#include "recognize/scoring.h"
#include "registration/icp.h"
#include "registration/ransac.h"

namespace ecv {

/// Settings of the online recognizer (DESIGN.md "Pose estimation"; paper Sect. III and IV-C).
struct RecognizerOptions {
  MatchOptions match = DefaultMatch();
  /// RANSAC per model view; the paper's test (t_poly 0.25, eps 1 cm, 50 % of the visible object points).
  /// Its `threads` are the Recognizer's workers: they describe the scene and then take a model each (ranking,
  /// RANSAC, verification, ICP; renders one at a time; a RANSAC gets more than one thread only when there are
  /// fewer models to search than workers). The detections do not depend on the count.
  RansacOptions ransac = DefaultRansac();
  /// Views per model tried with RANSAC, the best ranked first. On the 30 YCB-Video frames, RANSAC seeds 1/2/3:
  /// 7 views found 49/47/46 of 70 objects and 5 views 47/43/44 (both with ransac_stride_px 4 and approximate
  /// search from 100 descriptors; before those, 5 views found 49/43/44); 3 views at ~37 000 samples found 45/39/39,
  /// and with seed 1, 8 views at 5000 samples 43. The right view is often not ranked first: of the 70 objects, 68
  /// have a library view with 6 or more right correspondences among its 200 ranking ones, and such a view is
  /// among the best-ranked 5 for 56 of them (session 7, scratch study). With give_up_after_views, 10 views found
  /// 62 / 59 / 61 with 0 / 2 / 0 false positives against 7 views' 61 / 59 / 59 with 1 / 2 / 1 (session 27), from
  /// 1058 instead of 914 views tried over the 30 frames (seed 1; 7 views without giving up: 1295).
  int views_per_model = 10;
  /// A model's remaining ranked views are not tried once one verifies at or above this score (0: always try
  /// views_per_model). On the 30 YCB-Video frames (seeds 1/2/3) 0.5 found the same 49/47/46 of 70 objects with
  /// the same false positives, in 1433/1403/1413 instead of 1620/1563/1569 ms per frame (median, one thread).
  double good_enough_score = 0.5;
  /// A model whose first `give_up_after_views` tried views all verify below `give_up_below_score` is taken to be
  /// absent from the frame: its remaining views are not tried (0: always try views_per_model). Most models of a
  /// library are absent from any one frame, and each tried all its views. On the 30 YCB-Video frames (seeds
  /// 1 / 2 / 3) the same 61 / 59 / 59 of 70 objects with 1 / 2 / 1 false positives (instead of 1 / 2 / 2); with seed
  /// 1 the same detections in every frame from 914 instead of 1295 views, 1319-1381 instead of 1504-1562 ms per
  /// frame (median, one thread). Not applied to a model's later instances: it is known to be in the frame.
  int give_up_after_views = 4;
  double give_up_below_score = 0.1;
  /// Beyond the paper, for large libraries (issue 9: pre-select candidate models): before the search each model
  /// gets a quick score, the largest consistent set (as view ranking's) over every preselect_view_stride-th view
  /// on preselect_rows of its ranking descriptors (1/8 of the ranking's matching at the defaults), and only the
  /// `preselect_models` best-scoring are searched (0: every model; tracked models are not counted). The 16-model
  /// YCB-Video library on the 30 frames (seed 1, two threads): every model searched 68 of 130 objects, no false
  /// positive, 2251 ms per frame (median); the best 6 searched 61 (the mustard bottle 18 of 20, the foam brick 1 of
  /// 10 instead of 6), 1168 ms; the best 4, 58 in 867 ms. Descriptor votes did worse (bench/RESULTS.md).
  int preselect_models = 0;
  int preselect_view_stride = 4;
  int preselect_rows = 100;
  /// Beyond the best verified pose of a model, its best pose turned more than 90 degrees from it is refined and
  /// verified as well when it scored at least this share of the best (0: never): RANSAC's coarse poses of a
  /// bottle seen from the front and turned to its back score alike before ICP, and which one is refined decides.
  /// On the 30 YCB-Video frames (with the edge term; seeds 1 / 2 / 3): 61 / 59 / 59 of 70 objects with 1 / 2 / 2
  /// false positives, against 59 / 57 / 58 with 2 / 4 / 3 without (0.5: the same, with more ICP); without the edge
  /// term it does not help (59 / 53 / 57 with 3 / 8 / 3): the turned pose, refined, still wins on colour.
  double rival_min_ratio = 0.7;
  /// The scene's descriptors take at most this many neighbours (spread over the distance ranks, see
  /// DescriptorOptions::max_neighbours) when the library's setting allows more; 0 keeps the library's.
  /// Pairs grow with its square, so it bounds the describe time of close-ups: on the 10 close-ups of YCB-Video
  /// video 0000, 128 took 1.63 s instead of 2.98 s per frame (96: 1.04 s). Over the 30 frames, RANSAC seeds
  /// 1/2/3, 128 found 49/43/44 of 70 objects as without a cap (96: 49/42/43), with 7 instead of 6 false
  /// positives in the 90 frames. (Session 5, at 3 views per model, 64 found 7 instead of 9 of 10 in video 0000.)
  /// The shell context (the libraries' default since session 15) costs linearly, but the cap still pays: seed 1,
  /// no cap 53 of 70 objects with 13 false positives, 64: 47 / 11, 96: 52 / 9, 128: 57 / 6.
  int scene_max_neighbours = 128;
  /// A scene with more primitives than this describes only every n-th of them (the smallest n that keeps the
  /// sources at or under it); all of them still form the contexts. 0: every primitive. On YCB-Video only the
  /// close-ups of video 0000 (10 700 primitives) are over it: their describe went from 1550 to 775 ms per frame
  /// (median, one thread), all 10 objects found with seeds 1/2/3 either way, 4 instead of 3 false positives in the
  /// 30 frame runs.
  int scene_max_descriptors = 8000;
  /// A model's views are ranked by the largest pairwise-consistent set among their object-to-scene
  /// correspondences (ConsistentSetSize; max_distance_m is set to each model's diameter). On YCB-Video this
  /// replaced votes of the scene descriptors for views through a ratio test, which rarely picked the right
  /// view: near-duplicates of a surface spot in neighbouring views fail the ratio test.
  ConsistencyOptions consistency;
  /// Per view, at most this many of its descriptors (a seeded random subset) are matched for the ranking.
  int consistency_max_correspondences = 200;
  /// Descriptors compared per ranking query (MatchOptions::checks for these; 0: match.checks). Ranking every
  /// library view is the largest stage, and a view's ranking needs only its consistent set, not each row's exact
  /// neighbour; a tried view's rows are then all matched again with match.checks. On the 30 YCB-Video frames
  /// (two threads, RANSAC seeds 1-5, found / false positives of 350): 0 (128) 301 / 6, 64 292 / 12, 32 299 / 5,
  /// 16 293 / 5; with 32 the ranking took 230 instead of 470 ms per frame (summed over the threads) and the tried
  /// views' matching 90 instead of 45, but a good view ranked first for 52 instead of 58 of the 70 objects
  /// (ranking_bench) and the LM-O can was lost (with 48 too; 64 keeps it). Which views are tried decides the
  /// turned mustard bottle by chance, so recall moves either way: left at 0 (bench/RESULTS.md, session 29).
  int ranking_checks = 0;
  /// Beyond the paper: a RANSAC sample's later correspondences are drawn near its first one, within this
  /// many model diameters (RansacOptions::sample_radius_m); 0 draws them anywhere in the scene.
  double sample_radius_diameters = 1.0;
  int dense_stride_px = 2;  ///< scene depth points for ICP and verification: every n-th pixel
  /// Scene depth samples for RANSAC's inlier count (see projective_inliers): every n-th pixel. An inlier needs a
  /// scene point within 1 cm; points 4 px apart (about 4 mm at 1 m) still show that, with a quarter of the
  /// points to search. On the 30 YCB-Video frames (seeds 1/2/3, with every 4th of the stride-2 points): 46/42/46
  /// of 70 objects against 49/43/44 at stride 2, RANSAC 455-595 instead of 550-600 ms per frame (median; two runs
  /// at a time on 2 cores); with approximate search from 100 descriptors as well (DefaultMatch), 47/43/44 and
  /// 330-380 ms.
  int ransac_stride_px = 4;
  /// RANSAC looks for an object point's inlier partner among the 3 x 3 depth samples ransac_stride_px apart
  /// around the pixel it projects to (RansacOptions::projective_stride_px) instead of the nearest of the depth
  /// points and primitives in 3D (false, `recognize --nearest-inliers`). On the 30 YCB-Video frames (seeds
  /// 1 / 2 / 3) the same 61 / 59 / 59 of 70 objects with the same 1 / 2 / 2 false positives; see bench/RESULTS.md
  /// (session 26) for the time.
  bool projective_inliers = true;
  bool refine = true;  ///< point-to-plane ICP of accepted poses against the scene
  /// ICP takes the model's surface as rendered at the pose (every dense_stride_px-th pixel), at most this many
  /// points of it (every n-th); a close-up renders tens of thousands. 0: all. On the 30 YCB-Video frames (with
  /// scene_max_descriptors 8000 as well): refine 150 -> 92 ms per frame (median), the mean frame 2.0 -> 1.6 s,
  /// 49/47/46 of 70 objects found with seeds 1/2/3 as before, 5 instead of 4 false positives with seed 1.
  int icp_max_points = 3000;
  IcpOptions icp;
  /// ICP pairs each model point with the scene depth sample it projects to (RefinePointToPlaneProjective)
  /// instead of the nearest scene point in 3D (RefinePointToPlane over the points near the object). On the
  /// 30 YCB-Video frames: refinement 7x faster (33 against 238 ms per frame) but 41 instead of 45 of the 70
  /// objects found (its basin is narrower), so it is off by default (`recognize --fast-icp`).
  bool projective_icp = false;
  /// Verification by rendering the model at the pose: of its pixels with a scene depth that are not hidden
  /// behind a nearer scene surface, the share within `depth_tolerance_m` of the scene ...
  double depth_tolerance_m = 0.015;
  /// ... times, on those pixels, the normalised cross-correlation of the rendered colours (through the model's
  /// colour matrix) with the scene's (per channel, averaged, clipped at 0). The correlation ignores gain and
  /// offset, so it does not need a calibrated light, and drops for a box turned over or shifted by a few
  /// centimetres. On 15 YCB-Video frames it cut false positives from 1.7 to 0.2 per frame at a higher recall
  /// than a share of pixels of the same colour (after one gain), which failed on correct poses of dark or
  /// saturated objects.
  /// Gaussian sigma, pixels, of both colour images before the correlation: forgives a pose a pixel or two
  /// off. On the same frames, 1.5 px raised recall at 0.07 false positives per frame from 18 to 20 of 35
  /// (with the earlier consistency tolerances of 1 cm and 0.2).
  double color_blur_px = 1.5;
  /// ... times a factor for how closely the surface fits: 1 while the mean |rendered - scene depth| on those
  /// pixels is at most residual_free_m, falling linearly to 0 over residual_falloff_m beyond (0: no factor).
  /// A right pose after ICP fits to the sensor's noise (1-4 mm on YCB-Video); a wrong one that the 1.5 cm
  /// tolerance lets through fits worse, e.g. a can whose curved side lies on a flat box face (4.5-5.3 mm).
  double residual_free_m = 0.0035;
  double residual_falloff_m = 0.003;
  /// ... times a factor for how much of the pose's outline runs along a depth step of the scene (more than
  /// `depth_step_m` to a neighbouring pixel; OutlineOnDepthSteps): 1 from contour_free on, falling linearly to 0
  /// over contour_falloff below (0: no factor). An object stands out from what lies behind it; a pose that lies
  /// flat on a larger surface does not. On the 30 YCB-Video frames (seed 1, without the factor, every pose verified
  /// at 0.1 or more): the 57 right detections had 0.32-0.94 of their outline on a step (median 0.73), the gelatin
  /// box found on the unmodelled pudding box 0.01-0.24 in the 9 frames where it was reported. With the factor, seeds
  /// 1 / 2 / 3 found 58 / 55 / 56 of 70 objects with 3 / 7 / 4 false positives, against 57 / 55 / 57 with 6 / 10 / 5.
  /// Thin objects lying flat (under depth_step_m) have no step to show: `recognize --no-contour`.
  double contour_free = 0.3;
  double contour_falloff = 0.2;
  double depth_step_m = 0.01;
  /// ... and the colour correlation is weighed with the texture edges (beyond the paper): color^(1 - edge_weight)
  /// x edges^edge_weight, edges the share of the rendered model's texture edges that the scene shows at the same
  /// orientation (CompareEdges, on the surface pixels at least 2 samples inside the silhouette), when at least
  /// min_edge_pixels are predicted (0: colour alone). A mustard bottle turned 180 degrees correlates in colour
  /// as well as the right pose where only its shoulder shows (0.57 against 0.52 in 0001/000015), but its printed
  /// side's edges fall on the plain side the scene shows: 48 % of them found against 68 %. On the 30 YCB-Video
  /// frames (seeds 1 / 2 / 3), 0.5 found 59 / 57 / 58 of 70 objects with 2 / 4 / 3 false positives, against
  /// 58 / 55 / 56 with 3 / 6 / 4 without; 0.67 found the same but let the gelatin box onto the pudding box again.
  double edge_weight = 0.5;
  int min_edge_pixels = 50;
  EdgeOptions edge;
  /// A pose with fewer outline samples (at dense_stride_px) seen than this gets a contour factor of 1: an object
  /// filling the image, or hidden but for a patch, shows too little outline to tell.
  int min_outline_samples = 20;
  double min_score = 0.3;  ///< detections below are dropped
  /// Tracking: a prior that was not itself tracked (a detection's first appearance) is followed only when it
  /// scored at least this; once followed, it is kept while it scores min_score. A false detection near
  /// min_score then shows in one frame instead of persisting along the stream. On the 30 YCB-Video frames
  /// with tracking: 0.3 (no stricter bar) found 68 of 70 objects at 0.13 false positives per frame (one
  /// false track, 009 on the unmodelled 008 pudding box, first scored 0.30 and then kept for 4 frames),
  /// 0.35 found 68 at 0.03, 0.4 found 59 at 0.03.
  double min_track_start_score = 0.35;
  double min_visible_fraction = 0.1;  ///< of the model's rendered pixels that the scene can show
  /// A pose whose surface pixels are one patch of a larger scene plane (PatchOfLargerPlane: the plane goes on
  /// around the silhouette) scores 0: the depth shows nothing of the object there. On video 0002 it was a
  /// tomato soup can sunk into the table, its lid flush with the table top (depth agreement 1.0), tracked
  /// for 8 frames.
  bool reject_plane_patches = true;
  PlanePatchOptions plane_patch;
  /// A detection whose surface pixels (rendered on the scene surface) lie on more than this share of pixels
  /// that a better-scored detection of another model explains is dropped: one surface, one object.
  double max_overlap = 0.3;
  /// Instances of one model looked for per frame (beyond the paper, e.g. a bin of identical parts). After each
  /// accepted instance the model's views are tried again (their RANSAC poses are kept, not recomputed) for the
  /// best pose that does not lie mostly (max_overlap) on the surfaces of the instances found, until none passes.
  /// 1: the best pose only. On YCB-Video's demo frame with a second mustard bottle pasted in from video 0002
  /// (RANSAC seeds 1-10, bench/instances_bench): 2 found the pasted bottle within 15 mm and 20 degrees in 9 of 10
  /// runs (1: 5 of 10, and never both); on the 30 single-instance frames the same 49 of 70 objects, one more false
  /// positive in 30 frames, and +46 % median time (every model found has its later views tried).
  int max_instances = 1;
  /// Views tried for each instance after a model's first: it is known to be in the frame then, so more views
  /// are worth their time. 0: views_per_model. On the two-bottle frame the second bottle was found in 9 of 10
  /// runs with 21 (and with 40, for 1.6x the time), 5 of 10 with 7 or 14.
  int later_instance_views = 21;
  /// Apply a model's stored colour matrix (when it has one) to its view colours before matching (the views'
  /// descriptors are recomputed once, when the Recognizer is made) and to its rendered colours in verification.
  bool use_color_matrix = true;
  /// Textures larger than this (pixels per side) are downscaled for verification renders, where a model covers a
  /// few hundred pixels. YCB's 4096 x 4096 textures (decoded, uploaded, mipmapped) took most of the Recognizer's
  /// set-up: with 7 YCB models, 1764 ms at 2048 against 2341 ms uncapped (one thread). On the 30 YCB-Video
  /// frames 2048 found the same 49 of 70 objects as no cap; 1024 (1650 ms) lost a banana scored 0.380.
  int max_texture_size = 2048;
  /// Verification renders skip the faces turned away from the camera for meshes that close outwards
  /// (TriangleMesh::IsClosedOutward; RenderOptions::cull_back_faces): the same images in about a third less time.
  bool cull_back_faces = true;

  static RansacOptions DefaultRansac();
  /// ecvpose's KdForest (4 trees, leaves of 8, 128 checks) instead of FLANN's 32 checks: nearer neighbours in less
  /// time. Approximate search from 100 train descriptors on, instead of 1000 (see the .cpp).
  static MatchOptions DefaultMatch();
  /// Throws InputError on values outside their ranges.
  void Check() const;
  /// Compared descriptors per view-ranking query: ranking_checks, or match.checks when it is 0.
  int RankingChecks() const { return ranking_checks > 0 ? ranking_checks : match.checks; }
};

/// One recognised object (the JSON of DESIGN.md "Interfaces").
struct Detection {
  std::string model;
  /// 0..1, higher is surer: depth agreement x appearance (colour correlation and texture edges) of the rendered
  /// model x its fit and contour factors
  double score = 0.0;
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  double inlier_fraction = 0.0;    ///< RANSAC inliers over the visible view primitives
  double fit_error_m = 0.0;        ///< RANSAC mean inlier distance, metres
  int view = -1;                   ///< library view that matched
  double depth_agreement = 0.0;    ///< share of the visible rendered pixels on the scene surface
  double color_agreement = 0.0;    ///< correlation of the rendered colours with the scene's on those, 0..1
  double surface_error_m = 0.0;    ///< mean |rendered - scene depth| on those, metres
  double contour_agreement = 0.0;  ///< share of the seen outline on a scene depth step (0: none seen)
  double visible_fraction = 0.0;   ///< share of the rendered pixels the scene can show (not hidden, with depth)
  /// Of the rendered model's texture edges on those, the share the scene shows (0: none predicted) ...
  double edge_agreement = 0.0;
  int edge_pixels = 0;   ///< ... and how many were predicted
  bool tracked = false;  ///< found from a prior (the previous frame's pose), without RANSAC
};

/// Detections of one frame and where the time went.
struct RecognitionResult {
  std::vector<Detection> detections;  ///< best score first, at most max_instances per model, overlaps suppressed
  /// Per stage: extract, describe, track, match, ransac, refine, verify, total (a stage not run is absent).
  std::map<std::string, double> timings_ms;
  int scene_primitives = 0;
  /// Per model searched in the frame (not only tracked): the library views RANSAC ran on.
  std::map<std::string, int> views_tried;
};

/// One library view as view ranking saw it in a frame.
struct RankedView {
  int view = -1;  ///< index among the model's views
  int score = 0;  ///< ConsistentSetSize of its ranking correspondences
  /// Its ranking correspondences: a view primitive (object frame) and its nearest scene primitive by descriptor
  /// (camera frame).
  std::vector<std::pair<Primitive, Primitive>> correspondences;
};

/// The detections JSON of DESIGN.md "Interfaces": {"detections": [{"model", "score", "camera_from_object",
/// "inlier_fraction", "fit_error", "view", ...}], "timings_ms": {stage: ms}}.
nlohmann::json RecognitionToJson(const RecognitionResult& result);

/// The detections of such JSON (model, score, camera_from_object); throws InputError naming `source` and the
/// field when one is missing or malformed.
std::vector<Detection> DetectionsFromJson(const nlohmann::json& json, const std::string& source);

/// A frame's descriptors as the recognizer computes them from its `primitives`: the library's `descriptor`
/// settings with at most options.scene_max_neighbours neighbours per context, and every n-th primitive a source
/// so that at most options.scene_max_descriptors are described; on options.ransac.threads threads. `surface`: the
/// frame's surface, for a library whose descriptors use the surface context (DescriptorShape::kSurface).
Descriptors ComputeSceneDescriptors(const std::vector<Primitive>& primitives, const DescriptorOptions& descriptor,
                                    const RecognizerOptions& options, const SurfaceSamples* surface = nullptr);

/// What a tracking frame (Recognizer::Recognize with priors) searches for, by view ranking and RANSAC, besides
/// following its priors.
enum class SearchScope {
  kAllModels,  ///< every model whose prior fails or that has none: a full detection frame
  /// Only the models whose prior failed or fell below RecognizerOptions::min_track_start_score (a lost track is
  /// looked for at once); models without a prior are not looked for. When every prior passes, the frame's primitives
  /// are not even extracted. A stream alternates it with full frames (`recognize --track --search-every N`) to follow
  /// known objects at a fraction of the cost and still pick up new ones every N frames.
  kLostTracks,
};

/// Finds the library's models in RGB-D frames. Owns an offscreen renderer (for verification) with the
/// models' meshes, loaded from the paths stored in the library. One Recognizer per thread.
class Recognizer {
 public:
  Recognizer(const ModelLibrary& library, const RecognizerOptions& options = {});
  ~Recognizer();
  Recognizer(const Recognizer&) = delete;
  Recognizer& operator=(const Recognizer&) = delete;

  RecognitionResult Recognize(const RgbdFrame& frame);

  /// Tracking, for frames of a stream (beyond the paper): each prior (a detection of the previous frame) is
  /// first tried at its pose, refined by ICP and verified as any detection; when it passes, its model skips
  /// view ranking and RANSAC in this frame. Which of the other models are searched: see SearchScope.
  RecognitionResult Recognize(const RgbdFrame& frame, const std::vector<Detection>& priors,
                              SearchScope scope = SearchScope::kAllModels);

  /// View ranking alone, for studying it: every model's views as Recognize ranks them in `frame`, best first
  /// (RANSAC tries the first views_per_model of them).
  std::map<std::string, std::vector<RankedView>> RankViews(const RgbdFrame& frame);

  /// `frame`'s colour image with each detected model rendered at its pose in red, outlined, with its name.
  cv::Mat DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ecv
