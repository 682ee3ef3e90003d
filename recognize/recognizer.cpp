#include "recognize/recognizer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <functional>
#include <mutex>
#include <numeric>
#include <optional>
#include <random>
#include <thread>

#include <opencv2/imgproc.hpp>

#include "colorcal/color_matrix.h"
#include "core/error.h"
#include "core/timing.h"
#include "ecv/descriptor.h"
#include "ecv/primitives.h"
#include "io/pose_io.h"
#include "modeldb/model_builder.h"
#include "recognize/scoring.h"
#include "render/overlay.h"
#include "render/renderer.h"
#include "render/view_sampling.h"

namespace ecv {
namespace {

// What one frame offers to every model: primitives with descriptors, a matcher over them, dense points.
struct Scene {
  const RgbdFrame* frame = nullptr;
  std::vector<Primitive> primitives;
  Descriptors descriptors;
  std::unique_ptr<DescriptorMatcher> matcher;
  std::vector<Eigen::Vector3f> points;  // the depth points at dense_stride_px, for ICP
  // Primitive positions first, then (unless projective_inliers) the depth points at ransac_stride_px and a grid
  // over all of them with the inlier threshold as radius, built once per frame.
  std::vector<Eigen::Vector3f> ransac_points;
  std::unique_ptr<RadiusGrid> ransac_grid;
  cv::Mat color;             // the frame's colours, as verification compares them
  cv::Mat depth_steps;       // DepthSteps of the frame, for verification's contour factor
  cv::Mat gradient;          // GreyGradient of `color` at dense_stride_px, for the edge factor
  OrganizedScene organized;  // the depth samples with normals, for projective ICP
  SceneVisibility visibility;
};

// The given rows of `descriptors`, in that order.
Descriptors CopyRows(const Descriptors& descriptors, const std::vector<int>& rows) {
  Descriptors copy;
  copy.values.create(static_cast<int>(rows.size()), descriptors.values.cols, descriptors.values.type());
  const size_t row_bytes = static_cast<size_t>(descriptors.values.cols) * descriptors.values.elemSize();
  copy.primitive.reserve(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    std::memcpy(copy.values.ptr(static_cast<int>(i)), descriptors.values.ptr(rows[i]), row_bytes);
    copy.primitive.push_back(descriptors.primitive[static_cast<size_t>(rows[i])]);
  }
  return copy;
}

// Row numbers of a view's descriptors: a seeded random subset of `count` of its `rows` (all of them when there
// are no more), for the ranking, and the rest; each in row order.
struct RowSplit {
  std::vector<int> ranking, rest;
};

RowSplit SplitRows(size_t rows, size_t count, uint64_t seed) {
  RowSplit split;
  split.ranking.resize(rows);
  std::iota(split.ranking.begin(), split.ranking.end(), 0);
  if (rows <= count) return split;
  std::mt19937_64 random(seed);
  std::shuffle(split.ranking.begin(), split.ranking.end(), random);
  split.rest.assign(split.ranking.begin() + static_cast<std::ptrdiff_t>(count), split.ranking.end());
  split.ranking.resize(count);
  std::sort(split.ranking.begin(), split.ranking.end());
  std::sort(split.rest.begin(), split.rest.end());
  return split;
}

// A verified pose: the detection, the pixels (at dense_stride_px) where its rendered surface lies on the
// scene's, which overlap suppression compares, and the rendered depth (for the frame's camera sampled at
// dense_stride_px), from which ICP takes the model's surface.
struct Verified {
  Detection detection;
  std::vector<cv::Point> surface;
  cv::Mat depth;
};

// A pose hypothesis of a model from one of its views.
struct Hypothesis {
  int view = -1;
  RansacResult ransac;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

// A model view ranked by its consistent correspondences; once tried, its RANSAC pose, verified.
struct ViewCandidate {
  int view = -1;
  int score = 0;
  // The nearest scene primitive of each of its descriptors once `matched`; before, of its ranking subset only.
  std::vector<Correspondence> correspondences;
  bool matched = false;
  bool tried = false;  // RANSAC ran on it (and `verified` is its pose, if any)
  std::optional<Hypothesis> hypothesis;
  std::optional<Verified> verified;
};

// Calls work(i) for every i in [0, count) on `threads` threads, this one included, and waits for them; the
// first exception thrown is rethrown here.
void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& work) {
  std::atomic<size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto run = [&] {
    for (size_t i = next++; i < count; i = next++) {
      try {
        work(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = count;
      }
    }
  };
  std::vector<std::thread> workers;
  for (size_t t = 1; t < std::min(count, static_cast<size_t>(threads)); ++t) workers.emplace_back(run);
  run();
  for (std::thread& worker : workers) worker.join();
  if (failure) std::rethrow_exception(failure);
}

// Marks on `covered` (CV_8UC1, the frame's size) the pixels of a verified surface, sampled every `stride`
// pixels, with the gaps between the samples closed.
void CoverSurface(const std::vector<cv::Point>& surface, int stride, cv::Mat* covered) {
  cv::Mat samples = cv::Mat::zeros(covered->size(), CV_8UC1);
  for (const cv::Point& p : surface) samples.at<uchar>(p) = 1;
  cv::dilate(samples, samples, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * stride + 1, 2 * stride + 1)));
  *covered |= samples;
}

// The share of a verified surface's pixels that are non-zero on `covered` (0 when it is empty).
double CoveredShare(const std::vector<cv::Point>& surface, const cv::Mat& covered) {
  if (covered.empty() || surface.empty()) return 0.0;
  const auto on =
      std::count_if(surface.begin(), surface.end(), [&](const cv::Point& p) { return covered.at<uchar>(p) != 0; });
  return static_cast<double>(on) / static_cast<double>(surface.size());
}

}  // namespace

RansacOptions RecognizerOptions::DefaultRansac() {
  RansacOptions options;           // the paper's numbers
  options.adaptive = true;         // beyond the paper: stop once the best pose shows the sampled views are easy
  options.prefer_agreeing = true;  // and rank poses by agreeing (appearance-bearing) correspondences
  // At most 10 000 samples per view instead of the paper's 37 000 (w = 0.05), spent on more views instead: on
  // the 30 YCB-Video frames, 5 views at 10 000 found 49 of 70 objects in the RANSAC time of 3 views at 37 000
  // (45 of 70); 5 views at 5000 found 41.
  options.max_iterations = 10000;
  // A sample's pose is counted only when besides the sample one correspondence in a hundred (at least one)
  // agrees with it: most poses from wrong samples are agreed with by their own three alone, and in a cluttered
  // frame they would still pass the inlier test, one nearest-point search per object point. On the 30 YCB-Video
  // frames (seeds 1/2/3) the detections and scores are the same as without the test in all 90 frame runs, and
  // RANSAC took 363-387 instead of 704 ms per frame (median, one thread), the whole frame 1.6-1.7 instead of
  // 2.0 s; on the LM-O frame the same 2 objects. Stricter bars lose objects with few correspondences: 2 in a
  // hundred the LM-O duck, and so does a flat 2 (5 on YCB-Video still changed nothing, 7 lost a banana).
  options.min_support = 1;
  options.min_support_share = 0.01;
  return options;
}

MatchOptions RecognizerOptions::DefaultMatch() {
  MatchOptions options;
  // A frame's segments (900-1300 on YCB-Video) fell under MatchOptions' 1000 and were searched linearly, at
  // about 13 us per query against 7 us in the kd-trees. On the 30 YCB-Video frames (seeds 1/2/3): match 890-940
  // -> 550-590 ms per frame (median), 46/44/44 of 70 objects found against 49/43/44, and view ranking as good
  // (a view with 6 or more right correspondences among the best 5 for 56 of the 70 objects either way).
  options.exact_below = 100;
  // A KdForest with leaves of 8 rows and 128 checks instead of FLANN's 32 (4 trees either way): the exact
  // neighbour for 71 instead of 50 % of the queries at 0.76x the time, the index built in 0.39x
  // (bench/matching_bench), and a good view ranked first for 58 instead of 51 of the 70 objects (ranking_bench).
  // On the 30 YCB-Video frames (seeds 1-3) the same 58/55/56 of 70 objects found, 13 false positives against
  // 14; the mustard bottle alone (videos 0001 and 0002, seeds 1-10) 167 of 200 against 160. 2 trees and 64
  // checks (FLANN's 50 % at 0.36x its time) found 152 of those 200 bottles, the demo frame's 3 objects 27 times
  // over seeds 1-10 instead of 30. The LM-O duck is lost, but FLANN finds it only at exactly 4 trees and 32
  // checks: not at 64 or 128, nor with 2 trees.
  options.index = MatchIndex::kKdForest;
  options.trees = 4;
  options.leaf_size = 8;
  options.checks = 128;
  return options;
}

void RecognizerOptions::Check() const {
  match.Check();
  ransac.Check();
  icp.Check();
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("recognizer options", field, expected);
  };
  require(views_per_model >= 1, "views_per_model", "at least 1");
  require(good_enough_score >= 0.0, "good_enough_score", ">= 0 (0: try every ranked view)");
  require(give_up_after_views >= 0, "give_up_after_views", ">= 0 (0: never give up)");
  require(give_up_below_score >= 0.0, "give_up_below_score", ">= 0");
  consistency.Check();
  plane_patch.Check();
  require(consistency_max_correspondences >= 3, "consistency_max_correspondences", "at least 3");
  require(preselect_models >= 0, "preselect_models", ">= 0 (0: search every model)");
  require(preselect_view_stride >= 1, "preselect_view_stride", "at least 1");
  require(preselect_rows >= 3, "preselect_rows", "at least 3");
  require(ranking_checks >= 0, "ranking_checks", "0 (match.checks) or more");
  require(dense_stride_px >= 1, "dense_stride_px", "at least 1");
  require(ransac_stride_px >= 1, "ransac_stride_px", "at least 1");
  require(icp_max_points >= 0, "icp_max_points", ">= 0 (0: all)");
  require(sample_radius_diameters >= 0.0, "sample_radius_diameters", ">= 0 (0: sample anywhere)");
  require(depth_tolerance_m > 0.0, "depth_tolerance_m", "> 0 m");
  require(scene_max_neighbours >= 0, "scene_max_neighbours", ">= 0 (0: the library's setting)");
  require(scene_max_descriptors >= 0, "scene_max_descriptors", ">= 0 (0: every primitive)");
  require(max_overlap >= 0.0 && max_overlap <= 1.0, "max_overlap", "in [0, 1]");
  require(max_instances >= 1, "max_instances", "at least 1");
  require(later_instance_views >= 0, "later_instance_views", ">= 0 (0: views_per_model)");
  require(color_blur_px >= 0.0, "color_blur_px", ">= 0 pixels");
  require(residual_free_m >= 0.0, "residual_free_m", ">= 0 m");
  require(residual_falloff_m >= 0.0, "residual_falloff_m", ">= 0 m (0: no residual factor)");
  require(contour_free >= 0.0 && contour_free <= 1.0, "contour_free", "in [0, 1]");
  require(contour_falloff >= 0.0, "contour_falloff", ">= 0 (0: no contour factor)");
  require(depth_step_m > 0.0, "depth_step_m", "> 0 m");
  require(min_outline_samples >= 0, "min_outline_samples", ">= 0");
  require(min_score >= 0.0 && min_score <= 1.0, "min_score", "in [0, 1]");
  require(min_track_start_score >= 0.0 && min_track_start_score <= 1.0, "min_track_start_score", "in [0, 1]");
  require(min_visible_fraction >= 0.0 && min_visible_fraction <= 1.0, "min_visible_fraction", "in [0, 1]");
  require(max_texture_size >= 1, "max_texture_size", "at least 1 pixel");
  require(edge_weight >= 0.0 && edge_weight <= 1.0, "edge_weight", "in [0, 1] (0: colour alone)");
  require(min_edge_pixels >= 1, "min_edge_pixels", "at least 1");
  edge.Check();
  require(rival_min_ratio >= 0.0 && rival_min_ratio <= 1.0, "rival_min_ratio", "in [0, 1] (0: no rival refined)");
}

class Recognizer::Impl {
 public:
  Impl(const ModelLibrary& library, const RecognizerOptions& options)
      : library_(library), options_(options), renderer_(VerificationRenderer(options)) {
    options_.match.k = 1;
    const std::vector<LibraryModel>& models = library_.models();
    records_.resize(models.size());
    // Colour mapping, stored meshes (or mesh files) and texture decoding on every thread, a batch of models at a time
    // (only a batch's meshes are held at once); the GL uploads on this thread, whose GL context it is.
    const size_t batch = static_cast<size_t>(options_.ransac.threads);
    std::vector<char> closed(models.size(), 0);  // per model: TriangleMesh::IsClosedOutward
    for (size_t first = 0; first < models.size(); first += batch) {
      std::vector<TriangleMesh> meshes(std::min(batch, models.size() - first));
      ParallelFor(meshes.size(), options_.ransac.threads, [&](size_t i) {
        records_[first + i] = PreparedRecord(models[first + i]);
        meshes[i] = ModelMesh(models[first + i].record);
        records_[first + i].mesh_blob = {};  // the copy's bytes: the renderer holds the mesh
        closed[first + i] = meshes[i].IsClosedOutward() ? 1 : 0;
      });
      for (const TriangleMesh& mesh : meshes) meshes_.push_back(renderer_.AddMesh(mesh));
    }
    for (size_t m = 0; m < models.size(); ++m) {
      RenderOptions& render = render_options_.emplace_back();
      render.shading = StoredViewShading(models[m].record.build_options_json);
      render.cull_back_faces = options_.cull_back_faces && closed[m] != 0;
    }
  }

  // Every model's views, best ranked first, with their ranking correspondences (Recognizer::RankViews).
  std::map<std::string, std::vector<RankedView>> RankViews(const RgbdFrame& frame) {
    frame.Check();
    Scene scene = PrepareScene(frame);
    RecognitionResult unused;
    DescribeScene(&scene, &unused);
    std::vector<std::vector<ViewCandidate>> scored(records_.size());
    ParallelFor(records_.size(), options_.ransac.threads, [&](size_t m) { scored[m] = ScoreViews(m, scene); });
    std::map<std::string, std::vector<RankedView>> ranked;
    for (size_t m = 0; m < records_.size(); ++m) {
      std::vector<RankedView>& views = ranked[records_[m].name];
      for (const ViewCandidate& candidate : scored[m]) {
        RankedView view{candidate.view, candidate.score, {}};
        const std::vector<Primitive>& primitives = records_[m].views[static_cast<size_t>(candidate.view)].primitives;
        for (const Correspondence& c : candidate.correspondences) {
          view.correspondences.emplace_back(primitives[static_cast<size_t>(c.object)],
                                            scene.primitives[static_cast<size_t>(c.scene)]);
        }
        views.push_back(std::move(view));
      }
    }
    return ranked;
  }

  RecognitionResult Recognize(const RgbdFrame& frame, const std::vector<Detection>& priors, SearchScope scope) {
    frame.Check();
    const Clock::time_point start = Clock::now();
    RecognitionResult result;
    Scene scene = PrepareScene(frame);
    // Per model: the instances found so far (tracked, then recognised) and the scene pixels their surfaces cover.
    const size_t models = library_.models().size();
    std::vector<std::vector<Verified>> found(models);
    std::vector<cv::Mat> covered(models);
    auto add_instance = [&](size_t m, Verified verified) {
      if (covered[m].empty()) covered[m] = cv::Mat::zeros(frame.depth.size(), CV_8UC1);
      CoverSurface(verified.surface, options_.dense_stride_px, &covered[m]);
      found[m].push_back(std::move(verified));
    };
    auto instances = [&](size_t m) { return static_cast<int>(found[m].size()); };
    // The priors to follow, a model's in their order, the models on the workers (as the search below). A model
    // whose prior fails, or is a first detection below min_track_start_score, is `lost`: it was seen, so even a
    // frame that searches only for lost tracks searches for it.
    std::vector<std::vector<const Detection*>> model_priors(models);
    std::vector<char> lost(models, 0);  // not vector<bool>: written by the workers
    for (const Detection& prior : priors) {
      const std::optional<size_t> m = ModelIndex(prior.model);
      if (!m) continue;
      if (prior.tracked || prior.score >= options_.min_track_start_score) {
        model_priors[*m].push_back(&prior);
      } else {
        lost[*m] = 1;
      }
    }
    Clock::time_point stage = Clock::now();
    ParallelFor(models, options_.ransac.threads, [&](size_t m) {
      for (const Detection* prior : model_priors[m]) {
        if (instances(m) >= options_.max_instances) break;
        Verified tracked = Track(m, *prior, scene);
        if (Accepted(tracked.detection)) {
          add_instance(m, std::move(tracked));
        } else {
          lost[m] = 1;
        }
      }
    });
    if (!priors.empty()) result.timings_ms["track"] = MillisecondsSince(stage);
    std::vector<bool> done(models);
    for (size_t m = 0; m < models; ++m) {
      done[m] = instances(m) >= options_.max_instances || (scope == SearchScope::kLostTracks && lost[m] == 0);
    }
    if (std::count(done.begin(), done.end(), false) > 0) DescribeScene(&scene, &result);  // none when all tracked
    if (options_.preselect_models > 0 && std::count(done.begin(), done.end(), false) > options_.preselect_models) {
      stage = Clock::now();
      Preselect(scene, &done);
      result.timings_ms["preselect"] = MillisecondsSince(stage);
    }
    // The models on RansacOptions::threads workers: a model's search depends on nothing
    // of the others', so the detections do not depend on the count. Stage times are summed over the workers.
    // Fewer models to search than workers (a one-model library, say): the spare ones share each RANSAC's blocks.
    const auto searched = static_cast<int>(std::count(done.begin(), done.end(), false));
    ransac_threads_ = std::max(1, options_.ransac.threads / std::max(1, searched));
    std::vector<std::map<std::string, double>> model_timings(models);
    std::vector<int> views_tried(models, -1);  // -1: not searched
    ParallelFor(models, options_.ransac.threads, [&](size_t m) {
      if (done[m]) return;
      const Clock::time_point ranking = Clock::now();
      // A view's other descriptors are matched when it is tried (Try): views after a good enough one are not.
      std::vector<ViewCandidate> ranked = ScoreViews(m, scene);
      model_timings[m]["rank"] += MillisecondsSince(ranking);
      while (instances(m) < options_.max_instances) {
        // Once an instance is found the model is known to be in the frame: more of its views are worth trying.
        const int views = instances(m) == 0 || options_.later_instance_views == 0 ? options_.views_per_model
                                                                                  : options_.later_instance_views;
        const int give_up_after = instances(m) == 0 ? options_.give_up_after_views : 0;
        std::optional<Verified> best =
            BestDetection(m, views, give_up_after, scene, covered[m], &ranked, &model_timings[m]);
        if (!best || !Accepted(best->detection)) break;
        add_instance(m, std::move(*best));
      }
      views_tried[m] = static_cast<int>(
          std::count_if(ranked.begin(), ranked.end(), [](const ViewCandidate& view) { return view.tried; }));
    });
    std::vector<Verified> candidates;
    for (size_t m = 0; m < models; ++m) {
      for (auto& [name, ms] : model_timings[m]) result.timings_ms[name] += ms;
      if (views_tried[m] >= 0) result.views_tried[records_[m].name] = views_tried[m];
      for (Verified& verified : found[m]) candidates.push_back(std::move(verified));
    }
    stage = Clock::now();
    result.detections = SuppressOverlaps(frame.depth.size(), std::move(candidates));
    result.timings_ms["verify"] += MillisecondsSince(stage);
    result.timings_ms["total"] = MillisecondsSince(start);
    return result;
  }

 private:
  std::optional<size_t> ModelIndex(const std::string& name) const {
    for (size_t m = 0; m < records_.size(); ++m) {
      if (records_[m].name == name) return m;
    }
    return std::nullopt;
  }

  bool Accepted(const Detection& detection) const {
    return detection.score >= options_.min_score && detection.visible_fraction >= options_.min_visible_fraction;
  }

  // A prior's model at the prior's pose, refined by ICP when that raises the score (its RANSAC fields stay 0).
  Verified Track(size_t model, const Detection& prior, const Scene& scene) {
    Hypothesis hypothesis;
    hypothesis.view = prior.view;
    hypothesis.pose = prior.camera_from_object;
    Verified best = Verify(model, scene, hypothesis);
    if (options_.refine) {
      Refine(model, scene, best.depth, &hypothesis);
      Verified refined = Verify(model, scene, hypothesis);
      if (refined.detection.score >= best.detection.score) best = std::move(refined);
    }
    best.detection.tracked = true;
    return best;
  }

  // What every model needs of the frame: the dense points, colours and visibility (no primitives yet).
  Scene PrepareScene(const RgbdFrame& frame) const {
    Scene scene;
    scene.frame = &frame;
    scene.points = DepthPoints(frame, options_.dense_stride_px);
    // Into a new image: scene.color must not share the frame's pixels, or the blur would change the caller's frame.
    if (options_.color_blur_px > 0.0) {
      cv::GaussianBlur(frame.color, scene.color, cv::Size(0, 0), options_.color_blur_px);
    } else {
      scene.color = frame.color;
    }
    if (options_.refine && options_.projective_icp) {
      scene.organized = MakeOrganizedScene(frame.depth, frame.camera, options_.dense_stride_px);
    }
    scene.visibility.depth = frame.depth;
    scene.visibility.camera = frame.camera;
    // Grown by 2 pixels, so that the outline of a pose a pixel or two off still lies on its object's step.
    scene.depth_steps = DepthSteps(frame.depth, options_.depth_step_m, 2);
    // The verification renders' pixel (u, v) is the frame's (stride u, stride v): the blurred grey image sampled so.
    const int stride = options_.dense_stride_px;
    cv::Mat grey, sampled((frame.color.rows + stride - 1) / stride, (frame.color.cols + stride - 1) / stride, CV_8UC1);
    cv::cvtColor(scene.color, grey, cv::COLOR_RGB2GRAY);
    for (int v = 0; v < sampled.rows; ++v) {
      for (int u = 0; u < sampled.cols; ++u) sampled.at<uchar>(v, u) = grey.at<uchar>(v * stride, u * stride);
    }
    scene.gradient = GreyGradient(sampled);
    return scene;
  }

  // The frame's primitives (put before the depth points in scene->ransac_points, so that a primitive's index is
  // its point's), their descriptors and a matcher over them: what view ranking and RANSAC need.
  void DescribeScene(Scene* scene, RecognitionResult* result) const {
    const RgbdFrame& frame = *scene->frame;
    Clock::time_point stage = Clock::now();
    const FeatureSettings& settings = library_.feature_settings();
    scene->primitives = ExtractPrimitives(frame, settings.ecv).primitives;
    result->scene_primitives = static_cast<int>(scene->primitives.size());
    const std::vector<Eigen::Vector3f> positions = PrimitivePositions(scene->primitives);
    scene->ransac_points = positions;
    if (!options_.projective_inliers) {
      const std::vector<Eigen::Vector3f> depth_points = DepthPoints(frame, options_.ransac_stride_px);
      scene->ransac_points.insert(scene->ransac_points.end(), depth_points.begin(), depth_points.end());
      scene->ransac_grid =
          std::make_unique<RadiusGrid>(scene->ransac_points, static_cast<float>(options_.ransac.inlier_threshold_m));
    }
    result->timings_ms["extract"] = MillisecondsSince(stage);

    stage = Clock::now();
    // The surface context's support (if any): the whole frame's surface.
    const SurfaceSamples surface = DescriptorSurface(frame, settings.descriptor);
    scene->descriptors = ComputeSceneDescriptors(scene->primitives, settings.descriptor, options_, &surface);
    if (scene->descriptors.values.rows > 0) {
      scene->matcher = std::make_unique<DescriptorMatcher>(scene->primitives, scene->descriptors, options_.match);
    }
    result->timings_ms["describe"] = MillisecondsSince(stage);
  }

  // The model's best pose over its best `count` ranked views (fewer once one is good enough, or when the first
  // `give_up_after` show none at give_up_below_score; 0: never give up): RANSAC per view, each pose verified as it is
  // (both once per view and frame, kept in `ranked`), the best one not lying mostly (max_overlap) on `covered`
  // pixels (earlier instances) refined by ICP and verified again (kept only if ICP does not lower its score), and so
  // is its rival turned away from it (TurnedRival), the better of the two kept. Adds stage times.
  std::optional<Verified> BestDetection(size_t model, int count, int give_up_after, const Scene& scene,
                                        const cv::Mat& covered, std::vector<ViewCandidate>* ranked,
                                        std::map<std::string, double>* timings_ms) {
    const ViewCandidate* best_view = nullptr;
    for (size_t i = 0; i < std::min(ranked->size(), static_cast<size_t>(count)); ++i) {
      if (give_up_after > 0 && i == static_cast<size_t>(give_up_after) &&
          (best_view == nullptr || best_view->verified->detection.score < options_.give_up_below_score)) {
        break;
      }
      ViewCandidate& candidate = (*ranked)[i];
      Try(model, scene, &candidate, timings_ms);
      if (!candidate.verified || CoveredShare(candidate.verified->surface, covered) > options_.max_overlap) continue;
      if (best_view == nullptr || candidate.verified->detection.score > best_view->verified->detection.score) {
        best_view = &candidate;
      }
      if (options_.good_enough_score > 0.0 && best_view->verified->detection.score >= options_.good_enough_score) {
        break;
      }
    }
    if (best_view == nullptr) return std::nullopt;
    std::optional<Verified> best = best_view->verified;
    if (!options_.refine) return best;

    // The best verified pose is refined, and so is its rival (TurnedRival), if any: of a bottle's front and back,
    // coarse RANSAC poses that score alike, the one ICP refines usually wins. Refining the best three poses instead
    // found 44 rather than 45 of the 70 YCB-Video objects, for 3x the ICP time (before the edge term).
    const ViewCandidate* rival = TurnedRival(*ranked, count, *best_view, covered);
    for (const ViewCandidate* view : {best_view, rival}) {
      if (view == nullptr) continue;
      Clock::time_point stage = Clock::now();
      Hypothesis refined = *view->hypothesis;
      Refine(model, scene, view->verified->depth, &refined);
      (*timings_ms)["refine"] += MillisecondsSince(stage);
      stage = Clock::now();
      Verified verified = Verify(model, scene, refined);
      (*timings_ms)["verify"] += MillisecondsSince(stage);
      // A refined pose is kept only if ICP did not lower its score.
      const Verified& pose = verified.detection.score >= view->verified->detection.score ? verified : *view->verified;
      if (view == best_view || pose.detection.score > best->detection.score) best = pose;
    }
    return best;
  }

  // Of the first `count` tried views in `ranked`, the one whose verified pose is turned more than 90 degrees from
  // `best`'s and scores highest, at least rival_min_ratio of `best`'s score, not lying mostly on `covered` pixels;
  // nullptr when there is none.
  const ViewCandidate* TurnedRival(const std::vector<ViewCandidate>& ranked, int count, const ViewCandidate& best,
                                   const cv::Mat& covered) const {
    if (options_.rival_min_ratio <= 0.0) return nullptr;
    const Detection& best_detection = best.verified->detection;
    const Eigen::Matrix3d best_rotation = best_detection.camera_from_object.linear();
    const ViewCandidate* rival = nullptr;
    for (size_t i = 0; i < std::min(ranked.size(), static_cast<size_t>(count)); ++i) {
      const ViewCandidate& candidate = ranked[i];
      if (&candidate == &best || !candidate.verified) continue;
      const Detection& detection = candidate.verified->detection;
      if (detection.score <= 0.0 || detection.score < options_.rival_min_ratio * best_detection.score) continue;
      if (rival != nullptr && detection.score <= rival->verified->detection.score) continue;
      const Eigen::AngleAxisd turn(best_rotation.transpose() * detection.camera_from_object.linear());
      if (turn.angle() <= M_PI / 2.0) continue;
      if (CoveredShare(candidate.verified->surface, covered) > options_.max_overlap) continue;
      rival = &candidate;
    }
    return rival;
  }

  // Marks done all but the preselect_models models (of those not done) with the largest consistent set over every
  // preselect_view_stride-th view, on the first preselect_rows of each view's ranking rows; ties go to the earlier.
  void Preselect(const Scene& scene, std::vector<bool>* done) const {
    std::vector<size_t> candidates;
    for (size_t m = 0; m < done->size(); ++m) {
      if (!(*done)[m]) candidates.push_back(m);
    }
    std::vector<int> quick(candidates.size(), 0);
    if (scene.matcher) {
      ParallelFor(candidates.size(), options_.ransac.threads, [&](size_t i) {
        const ModelRecord& record = records_[candidates[i]];
        ConsistencyOptions consistency = options_.consistency;
        consistency.max_distance_m = record.diameter_m;
        for (size_t v = 0; v < record.views.size(); v += static_cast<size_t>(options_.preselect_view_stride)) {
          const ModelView& view = record.views[v];
          if (view.descriptors.values.rows == 0) continue;
          std::vector<int> rows = RankingRows(candidates[i], v).ranking;
          rows.resize(std::min(rows.size(), static_cast<size_t>(options_.preselect_rows)));
          const std::vector<Correspondence> matches =
              Correspondences(view, CopyRows(view.descriptors, rows), scene, options_.RankingChecks());
          quick[i] = std::max(quick[i], ConsistentSetSize(view.primitives, scene.primitives, matches, consistency));
        }
      });
    }
    std::vector<size_t> order(candidates.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return quick[a] > quick[b]; });
    for (size_t i = static_cast<size_t>(options_.preselect_models); i < order.size(); ++i) {
      (*done)[candidates[order[i]]] = true;
    }
  }

  // The model's views, best ranked first, each with the correspondences of its ranking subset of descriptors.
  std::vector<ViewCandidate> ScoreViews(size_t model, const Scene& scene) const {
    std::vector<ViewCandidate> views;
    if (!scene.matcher) return views;
    const ModelRecord& record = records_[model];
    for (size_t v = 0; v < record.views.size(); ++v) {
      const ModelView& view = record.views[v];
      if (view.descriptors.values.rows == 0) continue;
      ViewCandidate candidate;
      candidate.view = static_cast<int>(v);
      // Scored on a seeded subset of the view's descriptors, for speed.
      candidate.correspondences = Correspondences(view, CopyRows(view.descriptors, RankingRows(model, v).ranking),
                                                  scene, options_.RankingChecks());
      ConsistencyOptions consistency = options_.consistency;
      consistency.max_distance_m = record.diameter_m;
      candidate.score = ConsistentSetSize(view.primitives, scene.primitives, candidate.correspondences, consistency);
      views.push_back(std::move(candidate));
    }
    std::stable_sort(views.begin(), views.end(),
                     [](const ViewCandidate& a, const ViewCandidate& b) { return a.score > b.score; });
    return views;
  }

  // A view's ranking subset of descriptor rows (consistency_max_correspondences of them) and the other rows.
  RowSplit RankingRows(size_t model, size_t view) const {
    return SplitRows(static_cast<size_t>(records_[model].views[view].descriptors.values.rows),
                     static_cast<size_t>(options_.consistency_max_correspondences), options_.ransac.seed + view);
  }

  // Gives `candidate` its correspondences, once: the nearest scene descriptor of each of its descriptors (paper:
  // object to scene). The ranking has matched a subset of them; when it searched as matching does (or the search
  // is exact, MatchIndex::kBytes), only the others are searched here. The correspondences are put in the order in which
  // matching all the rows at once gives them (MatchOrderLess), so that RANSAC draws the same samples.
  void Match(size_t model, const Scene& scene, ViewCandidate* candidate) const {
    if (candidate->matched) return;
    const auto view = static_cast<size_t>(candidate->view);
    const ModelView& model_view = records_[model].views[view];
    const bool reuse_ranking =
        options_.RankingChecks() == options_.match.checks || options_.match.index == MatchIndex::kBytes;
    std::vector<Correspondence> found;
    if (reuse_ranking) {
      found = Correspondences(model_view, CopyRows(model_view.descriptors, RankingRows(model, view).rest), scene);
      found.insert(found.end(), candidate->correspondences.begin(), candidate->correspondences.end());
    } else {
      found = Correspondences(model_view, model_view.descriptors, scene);
    }
    std::sort(found.begin(), found.end(), [&](const Correspondence& a, const Correspondence& b) {
      return MatchOrderLess(model_view.primitives, options_.match.structure_specific, a.object, b.object);
    });
    candidate->correspondences = std::move(found);
    candidate->matched = true;
  }

  // The nearest scene primitive of each of `descriptors` (rows of the view's); `checks` > 0 replaces match.checks.
  static std::vector<Correspondence> Correspondences(const ModelView& view, const Descriptors& descriptors,
                                                     const Scene& scene, int checks = 0) {
    std::vector<Correspondence> found;
    for (const DescriptorMatch& match : scene.matcher->Match(view.primitives, descriptors, checks)) {
      if (match.rank == 0) found.push_back({match.query, match.train});
    }
    return found;
  }

  // Matches, RANSAC and verification of one view, once per frame (a later instance of the model reuses them).
  void Try(size_t model, const Scene& scene, ViewCandidate* candidate, std::map<std::string, double>* timings_ms) {
    if (candidate->tried) return;
    candidate->tried = true;
    Clock::time_point stage = Clock::now();
    Match(model, scene, candidate);
    (*timings_ms)["match"] += MillisecondsSince(stage);

    stage = Clock::now();
    const ModelRecord& record = records_[model];
    RansacOptions ransac = options_.ransac;
    ransac.threads = ransac_threads_;  // the models share the workers out (Recognize)
    ransac.sample_radius_m = options_.sample_radius_diameters * record.diameter_m;
    Hypothesis hypothesis;
    hypothesis.view = candidate->view;
    const std::vector<Eigen::Vector3f> object_points =
        PrimitivePositions(record.views[static_cast<size_t>(candidate->view)].primitives);
    if (options_.projective_inliers) {
      ransac.projective_stride_px = options_.ransac_stride_px;
      hypothesis.ransac =
          EstimatePoseRansac(object_points, scene.ransac_points, candidate->correspondences, ransac, &scene.visibility);
    } else {
      hypothesis.ransac = EstimatePoseRansac(object_points, scene.ransac_points, *scene.ransac_grid,
                                             candidate->correspondences, ransac, &scene.visibility);
    }
    hypothesis.pose = hypothesis.ransac.scene_from_object;
    (*timings_ms)["ransac"] += MillisecondsSince(stage);
    if (!hypothesis.ransac.success) return;

    stage = Clock::now();
    candidate->verified = Verify(model, scene, hypothesis);
    candidate->hypothesis = hypothesis;
    (*timings_ms)["verify"] += MillisecondsSince(stage);
  }

  // Point-to-plane ICP of the model's surface as rendered at the pose (`rendered_depth`, from Verify) against
  // the scene points near it.
  void Refine(size_t model, const Scene& scene, const cv::Mat& rendered_depth, Hypothesis* hypothesis) const {
    const PinholeCamera camera = scene.frame->camera.Sampled(options_.dense_stride_px);
    const Eigen::Isometry3f object_from_camera = hypothesis->pose.inverse().cast<float>();
    std::vector<Eigen::Vector3f> object_points;
    for (int v = 0; v < rendered_depth.rows; ++v) {
      for (int u = 0; u < rendered_depth.cols; ++u) {
        const float z = rendered_depth.at<float>(v, u);
        if (z > 0.0F) object_points.push_back(object_from_camera * camera.BackProject({u, v}, z).cast<float>());
      }
    }
    if (options_.icp_max_points > 0 && object_points.size() > static_cast<size_t>(options_.icp_max_points)) {
      const size_t step = (object_points.size() + options_.icp_max_points - 1) / options_.icp_max_points;
      for (size_t i = 0; i * step < object_points.size(); ++i) object_points[i] = object_points[i * step];
      object_points.resize((object_points.size() + step - 1) / step);
    }
    if (object_points.size() < 10) return;
    if (options_.projective_icp) {
      const IcpResult icp =
          RefinePointToPlaneProjective(object_points, scene.organized, hypothesis->pose, options_.icp);
      if (icp.success) hypothesis->pose = icp.scene_from_object;
      return;
    }
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const Eigen::Vector3f& point : object_points) centre += point;
    centre = hypothesis->pose.cast<float>() * (centre / static_cast<float>(object_points.size()));
    const float radius = 0.5F * static_cast<float>(library_.models()[model].record.diameter_m) + 0.03F;
    std::vector<Eigen::Vector3f> near;
    for (size_t i = 0; i < scene.points.size(); i += 2) {  // half the dense points suffice
      if ((scene.points[i] - centre).squaredNorm() < radius * radius) near.push_back(scene.points[i]);
    }
    const IcpResult icp = RefinePointToPlane(object_points, near, hypothesis->pose, options_.icp);
    if (icp.success) hypothesis->pose = icp.scene_from_object;
  }

  // The detections, best first, without those whose rendered surface lies mostly (max_overlap) on scene
  // pixels that a better detection of another model already explains: one surface, one object.
  std::vector<Detection> SuppressOverlaps(const cv::Size& image_size, std::vector<Verified> candidates) const {
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Verified& a, const Verified& b) { return a.detection.score > b.detection.score; });
    cv::Mat explained = cv::Mat::zeros(image_size, CV_8UC1);
    std::vector<Detection> kept;
    for (const Verified& candidate : candidates) {
      const std::vector<cv::Point>& surface = candidate.surface;
      const auto taken = std::count_if(surface.begin(), surface.end(),
                                       [&](const cv::Point& p) { return explained.at<uchar>(p) != 0; });
      if (!surface.empty() && static_cast<double>(taken) > options_.max_overlap * static_cast<double>(surface.size())) {
        continue;
      }
      for (const cv::Point& p : surface) explained.at<uchar>(p) = 1;
      kept.push_back(candidate.detection);
    }
    return kept;
  }

  Verified Verify(size_t model, const Scene& scene, const Hypothesis& hypothesis) {
    const LibraryModel& library_model = library_.models()[model];
    const RgbdFrame& frame = *scene.frame;
    const int stride = options_.dense_stride_px;
    const PinholeCamera camera = frame.camera.Sampled(stride);
    RenderResult rendered;
    {
      const std::lock_guard<std::mutex> lock(render_mutex_);  // one GL context: one render at a time
      rendered = renderer_.Render(meshes_[model], camera, hypothesis.pose, render_options_[model]);
    }
    cv::Mat model_color;
    if (options_.color_blur_px > 0.0) {
      cv::GaussianBlur(rendered.color, model_color, cv::Size(0, 0), options_.color_blur_px / stride);
    } else {
      model_color = rendered.color;
    }
    Eigen::Matrix3f to_scene = Eigen::Matrix3f::Identity();
    if (options_.use_color_matrix && library_model.color_matrix) {
      to_scene = library_model.color_matrix->model_to_scene.cast<float>();
    }
    int rendered_pixels = 0, visible = 0;
    double residual_sum = 0.0;
    Verified verified;
    std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> colors;  // (model through A, scene) on the surface
    const float tolerance = static_cast<float>(options_.depth_tolerance_m);
    // The texture edges are compared 2 samples inside the silhouette, where the render's own outline (against its
    // black background) does not reach.
    cv::Mat interior;
    cv::erode(rendered.depth > 0.0F, interior, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
    std::vector<cv::Point> interior_surface;  // surface pixels inside, at dense_stride_px
    for (int v = 0; v < rendered.depth.rows; ++v) {
      for (int u = 0; u < rendered.depth.cols; ++u) {
        const float model_z = rendered.depth.at<float>(v, u);
        if (model_z <= 0.0F) continue;
        ++rendered_pixels;
        const int scene_u = u * stride, scene_v = v * stride;
        const float scene_z = frame.depth.at<float>(scene_v, scene_u);
        if (scene_z <= 0.0F || scene_z < model_z - tolerance) continue;  // no measurement, or hidden
        ++visible;
        if (std::abs(scene_z - model_z) > tolerance) continue;
        residual_sum += std::abs(scene_z - model_z);
        verified.surface.emplace_back(scene_u, scene_v);
        if (interior.at<uchar>(v, u) != 0) interior_surface.emplace_back(u, v);
        const cv::Vec3b& m = model_color.at<cv::Vec3b>(v, u);
        const cv::Vec3b& s = scene.color.at<cv::Vec3b>(scene_v, scene_u);
        colors.emplace_back(to_scene * Eigen::Vector3f(m[0], m[1], m[2]) / 255.0F,
                            Eigen::Vector3f(s[0], s[1], s[2]) / 255.0F);
      }
    }
    verified.depth = rendered.depth;
    const int on_surface = static_cast<int>(verified.surface.size());
    Detection& detection = verified.detection;
    detection.color_agreement = ColorCorrelation(colors);
    cv::Mat model_grey;
    cv::cvtColor(model_color, model_grey, cv::COLOR_RGB2GRAY);
    const EdgeAgreement edges = CompareEdges(GreyGradient(model_grey), scene.gradient, interior_surface, options_.edge);
    detection.edge_agreement = edges.Share();
    detection.edge_pixels = edges.predicted;
    detection.model = library_model.record.name;
    detection.camera_from_object = hypothesis.pose;
    detection.inlier_fraction = hypothesis.ransac.inlier_fraction;
    detection.fit_error_m = hypothesis.ransac.fit_error_m;
    detection.view = hypothesis.view;
    detection.visible_fraction = rendered_pixels > 0 ? static_cast<double>(visible) / rendered_pixels : 0.0;
    detection.depth_agreement = visible > 0 ? static_cast<double>(on_surface) / visible : 0.0;
    detection.surface_error_m = on_surface > 0 ? residual_sum / on_surface : 0.0;
    const OutlineOnSteps outline =
        OutlineOnDepthSteps(rendered.depth, stride, frame.depth, scene.depth_steps, options_.depth_tolerance_m);
    detection.contour_agreement = outline.Share();
    const double contour_factor =
        ContourFactor(outline, options_.contour_free, options_.contour_falloff, options_.min_outline_samples);
    detection.score = detection.depth_agreement *
                      Appearance(detection.color_agreement, edges, options_.edge_weight, options_.min_edge_pixels) *
                      ResidualFactor(detection.surface_error_m) * contour_factor;
    if (options_.reject_plane_patches && detection.score > 0.0 &&
        OnLargerPlane(frame, rendered.depth, verified.surface)) {
      detection.score = 0.0;
    }
    return verified;
  }

  // 1 for a surface that fits the scene depth as closely as a right pose does (mean residual up to
  // residual_free_m), falling linearly to 0 over residual_falloff_m beyond.
  double ResidualFactor(double residual_m) const {
    if (options_.residual_falloff_m <= 0.0) return 1.0;
    return std::clamp(1.0 - (residual_m - options_.residual_free_m) / options_.residual_falloff_m, 0.0, 1.0);
  }

  // PatchOfLargerPlane for a rendered pose: its surface pixels against the scene points of a ring of
  // kPlaneRingSamples samples (at dense_stride_px) around its silhouette.
  bool OnLargerPlane(const RgbdFrame& frame, const cv::Mat& rendered_depth,
                     const std::vector<cv::Point>& surface) const {
    constexpr int kPlaneRingSamples = 3;
    const int stride = options_.dense_stride_px;
    auto scene_point = [&](int u, int v) -> Eigen::Vector3f {
      return frame.camera.BackProject({u, v}, frame.depth.at<float>(v, u)).cast<float>();
    };
    std::vector<Eigen::Vector3f> surface_points, ring_points;
    for (const cv::Point& p : surface) surface_points.push_back(scene_point(p.x, p.y));
    const cv::Mat silhouette = rendered_depth > 0.0F;
    cv::Mat grown;
    cv::dilate(
        silhouette, grown,
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * kPlaneRingSamples + 1, 2 * kPlaneRingSamples + 1)));
    for (int v = 0; v < grown.rows; ++v) {
      for (int u = 0; u < grown.cols; ++u) {
        if (grown.at<uchar>(v, u) == 0 || silhouette.at<uchar>(v, u) != 0) continue;
        if (frame.depth.at<float>(v * stride, u * stride) > 0.0F)
          ring_points.push_back(scene_point(u * stride, v * stride));
      }
    }
    return PatchOfLargerPlane(surface_points, ring_points, options_.plane_patch);
  }

 public:
  cv::Mat DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections) {
    std::vector<SceneObject> objects;
    for (const Detection& detection : detections) {
      if (const std::optional<size_t> m = ModelIndex(detection.model)) {
        objects.push_back({meshes_[*m], detection.camera_from_object});
      }
    }
    const OverlayOptions overlay;
    RenderResult rendered = renderer_.RenderScene(objects, frame.camera, OverlayRenderOptions(overlay));
    // Scene surfaces in front of a model hide it; so do pixels without a scene depth next to hidden ones (holes
    // in the depth of a shiny surface in front would otherwise let specks of the model show through).
    cv::Mat hidden = cv::Mat::zeros(rendered.depth.size(), CV_8UC1);
    for (int v = 0; v < rendered.depth.rows; ++v) {
      for (int u = 0; u < rendered.depth.cols; ++u) {
        const float scene_z = frame.depth.at<float>(v, u), model_z = rendered.depth.at<float>(v, u);
        if (model_z > 0.0F && scene_z > 0.0F && scene_z < model_z - static_cast<float>(options_.depth_tolerance_m)) {
          hidden.at<uchar>(v, u) = 1;
        }
      }
    }
    cv::Mat near_hidden;
    cv::dilate(hidden, near_hidden, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(21, 21)));
    for (int v = 0; v < rendered.depth.rows; ++v) {
      for (int u = 0; u < rendered.depth.cols; ++u) {
        if (hidden.at<uchar>(v, u) != 0 || (frame.depth.at<float>(v, u) <= 0.0F && near_hidden.at<uchar>(v, u) != 0)) {
          rendered.mask.at<uchar>(v, u) = 0;
          rendered.labels.at<uint16_t>(v, u) = 0;
        }
      }
    }
    cv::Mat picture = DrawOverlay(frame.color, rendered, overlay);
    for (const Detection& detection : detections) {
      const Eigen::Vector3d centre = detection.camera_from_object.translation();
      if (centre.z() <= 0.0) continue;
      const Eigen::Vector2d pixel = frame.camera.Project(centre);
      const cv::Point at(static_cast<int>(pixel.x()) - 40, static_cast<int>(pixel.y()));
      char label[160];
      std::snprintf(label, sizeof(label), "%s %.2f", detection.model.c_str(), detection.score);
      cv::putText(picture, label, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
      cv::putText(picture, label, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    }
    return picture;
  }

 private:
  static RendererOptions VerificationRenderer(const RecognizerOptions& options) {
    options.Check();  // before anything is made of them
    RendererOptions renderer;
    renderer.max_texture_size = options.max_texture_size;
    return renderer;
  }

  // The library's record of a model, its views' colours mapped by its colour matrix (if any and used) and their
  // descriptors recomputed (paper Sect. IV-C: A c_model = c_scene before matching).
  ModelRecord PreparedRecord(const LibraryModel& model) const {
    ModelRecord record = model.record;
    if (!options_.use_color_matrix || !model.color_matrix) return record;
    // Scaled to keep grey's brightness: a gain below 1 shrinks the colour differences the descriptor bins, which
    // are not smaller in real frames (bench/RESULTS.md, colour calibration). Matrices stored by `ecvpose colorcal`
    // keep the brightness already; this covers --no-keep-brightness and older libraries.
    const Eigen::Matrix3d to_scene = BrightnessPreserving(model.color_matrix->model_to_scene);
    DescriptorOptions describe = library_.feature_settings().descriptor;
    const bool surface_shape = describe.shape == DescriptorShape::kSurface;
    describe.shape = DescriptorShape::kPrimitives;  // the surface context's half is kept: colours do not change it
    for (ModelView& view : record.views) {
      ApplyColorMatrix(to_scene, &view.primitives);
      Descriptors recoloured = ComputeDescriptors(view.primitives, describe);
      if (surface_shape) {
        if (recoloured.primitive != view.descriptors.primitive) {
          ThrowInputError("model " + model.record.name, "descriptors",
                          "one row per primitive with a context, as the library's feature settings give");
        }
        const cv::Range shape(0, 3 * kDescriptorBins);
        view.descriptors.values.colRange(shape).copyTo(recoloured.values.colRange(shape));
      }
      view.descriptors = std::move(recoloured);
    }
    return record;
  }

  const ModelLibrary& library_;
  RecognizerOptions options_;
  std::vector<ModelRecord> records_;  // per model: the library's, colours mapped by its colour matrix if any
  Renderer renderer_;
  std::mutex render_mutex_;  // Verify runs on the model workers
  int ransac_threads_ = 1;   // per RANSAC, set by Recognize for the frame
  std::vector<MeshId> meshes_;
  std::vector<RenderOptions> render_options_;  // per model: shaded as its library views are
};

Recognizer::Recognizer(const ModelLibrary& library, const RecognizerOptions& options)
    : impl_(std::make_unique<Impl>(library, options)) {}

Recognizer::~Recognizer() = default;

RecognitionResult Recognizer::Recognize(const RgbdFrame& frame) {
  return impl_->Recognize(frame, {}, SearchScope::kAllModels);
}

RecognitionResult Recognizer::Recognize(const RgbdFrame& frame, const std::vector<Detection>& priors,
                                        SearchScope scope) {
  return impl_->Recognize(frame, priors, scope);
}

std::map<std::string, std::vector<RankedView>> Recognizer::RankViews(const RgbdFrame& frame) {
  return impl_->RankViews(frame);
}

cv::Mat Recognizer::DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections) {
  return impl_->DrawDetections(frame, detections);
}

nlohmann::json RecognitionToJson(const RecognitionResult& result) {
  nlohmann::json detections = nlohmann::json::array();
  for (const Detection& d : result.detections) {
    detections.push_back({{"model", d.model},
                          {"score", d.score},
                          {"camera_from_object", PoseToJson(d.camera_from_object)},
                          {"inlier_fraction", d.inlier_fraction},
                          {"fit_error", d.fit_error_m},
                          {"view", d.view},
                          {"depth_agreement", d.depth_agreement},
                          {"color_agreement", d.color_agreement},
                          {"visible_fraction", d.visible_fraction},
                          {"surface_error", d.surface_error_m},
                          {"contour_agreement", d.contour_agreement},
                          {"edge_agreement", d.edge_agreement},
                          {"edge_pixels", d.edge_pixels},
                          {"tracked", d.tracked}});
  }
  return {{"detections", detections},
          {"timings_ms", result.timings_ms},
          {"scene_primitives", result.scene_primitives},
          {"views_tried", result.views_tried}};
}

std::vector<Detection> DetectionsFromJson(const nlohmann::json& json, const std::string& source) {
  if (!json.contains("detections") || !json["detections"].is_array()) {
    ThrowInputError(source, "detections", "an array of detections (ecvpose recognize --out-json)");
  }
  std::vector<Detection> detections;
  for (size_t i = 0; i < json["detections"].size(); ++i) {
    const nlohmann::json& item = json["detections"][i];
    const std::string field = "detections[" + std::to_string(i) + "]";
    if (!item.contains("model") || !item["model"].is_string()) ThrowInputError(source, field + ".model", "a string");
    Detection detection;
    detection.model = item["model"].get<std::string>();
    detection.camera_from_object =
        PoseFromJson(item.value("camera_from_object", nlohmann::json()), source, field + ".camera_from_object");
    detection.score = item.value("score", 0.0);
    detections.push_back(detection);
  }
  return detections;
}

Descriptors ComputeSceneDescriptors(const std::vector<Primitive>& primitives, const DescriptorOptions& descriptor,
                                    const RecognizerOptions& options, const SurfaceSamples* surface) {
  DescriptorOptions describe = descriptor;
  if (options.scene_max_neighbours > 0 &&
      (describe.max_neighbours == 0 || describe.max_neighbours > options.scene_max_neighbours)) {
    describe.max_neighbours = options.scene_max_neighbours;
  }
  const size_t count = primitives.size(), most = static_cast<size_t>(options.scene_max_descriptors);
  const int source_step = most > 0 && count > most ? static_cast<int>((count + most - 1) / most) : 1;
  return ComputeDescriptors(primitives, describe, options.ransac.threads, source_step, surface);
}

}  // namespace ecv
