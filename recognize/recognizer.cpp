#include "recognize/recognizer.h"

#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

#include <opencv2/imgproc.hpp>

#include "colorcal/color_matrix.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/pose.h"
#include "core/timing.h"
#include "ecv/descriptor.h"
#include "modeldb/model_builder.h"
#include "recognize/acceptance.h"
#include "recognize/detection_overlay.h"
#include "recognize/model_search.h"
#include "recognize/scene.h"
#include "recognize/tracking.h"
#include "recognize/verification.h"
#include "registration/ppf.h"
#include "render/renderer.h"
#include "render/view_sampling.h"

namespace ecv {
namespace {

// What searching a model found besides its instances.
struct ModelSearchResult {
  int views_tried = -1;  // -1: not searched
  StageTimes times;
};

// Whether `mesh` is painted in one colour (no texture; its vertex and material colours all within 2 % of one
// another): a grey CAD mesh, whose render says nothing of the object's print (VerifyOptions::plain_appearance).
bool OneColoured(const TriangleMesh& mesh) {
  constexpr float kSame = 0.02F;  // RGB in [0, 1]
  std::optional<Eigen::Vector3f> first;
  const auto same = [&](const Eigen::Vector3f& color) {
    if (!first) first = color;
    return (color - *first).cwiseAbs().maxCoeff() <= kSame;
  };
  for (const MeshPart& part : mesh.parts) {
    switch (mesh.Coloring(part)) {
      case MeshColoring::kTexture: return false;
      case MeshColoring::kVertexColor:
        if (!std::all_of(part.colors.begin(), part.colors.end(), same)) return false;
        break;
      case MeshColoring::kMaterialColor:
        const bool known = part.material >= 0 && part.material < static_cast<int>(mesh.materials.size());
        if (!same(known ? mesh.materials[static_cast<size_t>(part.material)].diffuse_color
                        : MeshMaterial().diffuse_color)) {
          return false;
        }
        break;
    }
  }
  return true;
}

// A library model as the recognizer holds it.
struct LoadedModel {
  ModelRecord record;  // the library's, its colours mapped by its colour matrix if any
  MeshId mesh;
  RenderOptions render;                 // shaded as its library views are
  std::optional<PpfModel> point_pairs;  // with point pair hypotheses: its table, if any
  std::string point_pair_refusal;       // without a table: why
  // A table of the library's stored points is built when the model first reaches the point pair stage (most models
  // of a frame are found by the context, or never reach it): once, whichever worker gets there first.
  bool point_pairs_deferred = false;
  std::unique_ptr<std::once_flag> point_pairs_built = std::make_unique<std::once_flag>();
  // A coarse table of its stored points, voted when it is a shape candidate (PreselectOptions::shape_models).
  std::optional<PpfModel> coarse_pairs;
  std::unique_ptr<std::once_flag> coarse_built = std::make_unique<std::once_flag>();
  // With lazy meshes (a pre-selected library), its mesh is loaded when first needed: EnsureMesh.
  std::unique_ptr<std::once_flag> mesh_loaded = std::make_unique<std::once_flag>();
  double diameter_m = 0.0;  // of its mesh
  bool plain = false;       // painted in one colour alone (VerifyOptions::plain_appearance)
  PrincipalBox axes;        // about which its poses are turned (TwinOptions)
};

RendererOptions VerificationRenderer(const RecognizerOptions& options) {
  options.Check();  // before anything is made of them
  RendererOptions renderer;
  renderer.max_texture_size = options.verify.max_texture_size;
  return renderer;
}

}  // namespace

class Recognizer::Impl {
 public:
  Impl(const ModelLibrary& library, const RecognizerOptions& options)
      : library_(library),
        options_(options),
        learned_(options.acceptance == Acceptance::kLearned ? &AcceptanceModel::Learned() : nullptr),
        renderer_(VerificationRenderer(options)) {
    if (library.models().empty()) ThrowInputError("model library", "models", "at least one model", "none");
    options_.match.k = 1;
    const std::vector<LibraryModel>& library_models = library_.models();
    models_.resize(library_models.size());
    ParallelFor(models_.size(), options_.threads, [&](size_t m) {
      models_[m].record = PreparedRecord(library_models[m]);
      models_[m].record.mesh_blob = {};  // the copy's bytes: the library's are decoded, the renderer holds the mesh
      models_[m].render.shading = StoredViewShading(library_models[m].record.build_options_json);
      if (options_.point_pairs.source != HypothesisSource::kContext) PreparePointPairs(&models_[m]);
    });
    // A library larger than the pre-selection: each model's mesh when it is first verified (most never are).
    lazy_meshes_ = options_.preselect.models > 0 && models_.size() > static_cast<size_t>(options_.preselect.models);
    // Stored meshes (or mesh files) and texture decoding on every thread, a batch of models at a time (only a batch's
    // meshes are held at once); the GL uploads on this thread, whose GL context it is.
    const size_t batch = static_cast<size_t>(options_.threads);
    for (size_t first = 0; first < models_.size() && !lazy_meshes_; first += batch) {
      std::vector<TriangleMesh> meshes(std::min(batch, models_.size() - first));
      ParallelFor(meshes.size(), options_.threads, [&](size_t i) {
        meshes[i] = ModelMesh(library_models[first + i].record);
        TakeMesh(meshes[i], &models_[first + i]);
      });
      for (size_t i = 0; i < meshes.size(); ++i) models_[first + i].mesh = renderer_.AddMesh(meshes[i]);
    }
    for (const LoadedModel& model : models_) model_names_.push_back(model.record.name);
  }

  std::map<std::string, std::vector<RankedView>> RankViews(const RgbdFrame& frame) {
    frame.Check();
    Scene scene = PrepareScene(frame, options_);
    StageTimes unused;
    DescribeScene(library_.feature_settings(), options_, &scene, &unused);
    std::vector<std::vector<ViewCandidate>> scored(models_.size());
    ParallelFor(models_.size(), options_.threads, [&](size_t m) { scored[m] = Search(m, scene, 1).RankViews(); });
    std::map<std::string, std::vector<RankedView>> ranked;
    for (size_t m = 0; m < models_.size(); ++m) {
      std::vector<RankedView>& views = ranked[models_[m].record.name];
      for (const ViewCandidate& candidate : scored[m]) {
        RankedView view{candidate.view, candidate.score, {}};
        const std::vector<Primitive>& primitives =
            models_[m].record.views[static_cast<size_t>(candidate.view)].primitives;
        for (const Correspondence& c : candidate.correspondences) {
          view.correspondences.emplace_back(primitives[static_cast<size_t>(c.object)],
                                            scene.primitives[static_cast<size_t>(c.scene)]);
        }
        views.push_back(std::move(view));
      }
    }
    return ranked;
  }

  // Follow the priors, choose the models to search, search each (one per worker), suppress overlaps.
  // With `targets` (model name -> instances), only those models are searched, each for its instances, and each
  // reports its best rejected pose when it found fewer (RecognizeTargets).
  RecognitionResult Recognize(const RgbdFrame& frame, const std::vector<Detection>& priors, SearchScope scope,
                              const std::map<std::string, int>* targets = nullptr) {
    frame.Check();
    const Clock::time_point start = Clock::now();
    RecognitionResult result;
    StageTimes times;
    Scene scene = PrepareScene(frame, options_);
    if (options_.keep_verified) scene.verified_log = std::make_unique<Scene::VerifiedLog>();
    std::vector<ModelInFrame> models = AssignPriors(priors, model_names_, options_.tracking);
    for (size_t m = 0; m < models.size(); ++m) {
      models[m].max_instances = targets ? TargetCount(*targets, model_names_[m]) : options_.max_instances;
    }
    if (!priors.empty()) {
      const Clock::time_point stage = Clock::now();
      FollowPriors(scene, &models);
      times.Add(Stage::kTrack, MillisecondsSince(stage));
    }
    int searched = ChooseModels(scope, options_.tracking, options_.max_instances, &models);
    if (targets) {
      for (ModelInFrame& model : models) model.search = model.search && model.max_instances > 0;
      searched =
          static_cast<int>(std::count_if(models.begin(), models.end(), [](const ModelInFrame& m) { return m.search; }));
    }
    const bool context = options_.point_pairs.source != HypothesisSource::kPpf;
    if (context && searched > 0) {  // none when all are tracked
      DescribeScene(library_.feature_settings(), options_, &scene, &times);
      result.scene_primitives = static_cast<int>(scene.primitives.size());
    }
    std::vector<size_t> left_out;  // by the pre-selection, best ranked first
    if (context && options_.preselect.models > 0 && searched > options_.preselect.models) {
      const Clock::time_point stage = Clock::now();
      left_out = Preselect(scene, &models);
      times.Add(Stage::kPreselect, MillisecondsSince(stage));
    }
    // A model's search depends on nothing of the others', so the detections do not depend on the thread count.
    // Fewer models to search than workers (a one-model library, say): the spare ones share each RANSAC's blocks.
    const auto to_search =
        static_cast<int>(std::count_if(models.begin(), models.end(), [](const ModelInFrame& m) { return m.search; }));
    const int ransac_threads = std::max(1, options_.threads / std::max(1, to_search));
    std::vector<ModelSearchResult> searches(models.size());
    if (context) {
      ParallelFor(models.size(), options_.threads, [&](size_t m) {
        if (models[m].search) searches[m] = SearchModel(m, scene, ransac_threads, &models[m]);
      });
    }
    if (options_.point_pairs.source != HypothesisSource::kContext) SearchByPointPairs(scene, left_out, &models, &times);
    std::vector<VerifiedPose> candidates;
    for (size_t m = 0; m < models.size(); ++m) {
      MergeConfirmation(frame.depth.size(), options_.max_overlap, options_.max_instances, options_.dense_stride_px,
                        &models[m]);
      times += searches[m].times;
      if (searches[m].views_tried >= 0) result.views_tried[models_[m].record.name] = searches[m].views_tried;
      for (VerifiedPose& verified : models[m].instances) candidates.push_back(std::move(verified));
      for (JudgedPose& judged : models[m].judged) result.judged.push_back(std::move(judged));
    }
    const Clock::time_point stage = Clock::now();
    result.detections = SuppressOverlaps(frame.depth.size(), std::move(candidates));
    if (targets) AddBestRejected(&models, &result.detections);
    if (scene.verified_log) result.verified = SortedByModel(std::move(scene.verified_log->poses));
    times.Add(Stage::kVerify, MillisecondsSince(stage));
    times.Add(Stage::kTotal, MillisecondsSince(start));
    result.timings_ms = times.Map();
    return result;
  }

  cv::Mat DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections);

  std::vector<std::string> PointPairWarnings() const {
    std::vector<std::string> warnings;
    for (const LoadedModel& model : models_) {
      if (!model.point_pair_refusal.empty()) {
        warnings.push_back("model " + model.record.name + ": no point pair hypotheses (" + model.point_pair_refusal +
                           ")");
      }
    }
    return warnings;
  }

 private:
  bool Accepted(const Detection& detection) const {
    if (detection.visible_fraction < options_.verify.min_visible_fraction) return false;
    return options_.acceptance == Acceptance::kLearned ? detection.acceptance >= learned_->threshold()
                                                       : detection.score >= options_.verify.min_score;
  }

  // Accepted, the verdict kept in `model` with keep_judged; the best rejected pose kept in it.
  bool Judge(const VerifiedPose& pose, ModelInFrame* model) const {
    const bool accepted = Accepted(pose.detection);
    if (options_.keep_judged) model->judged.push_back({pose.detection, accepted});
    if (!accepted && (!model->best_rejected || pose.detection.score > model->best_rejected->detection.score)) {
      model->best_rejected = pose;
    }
    return accepted;
  }

  // The instances a target model is looked for: its count, none for a model not among the targets.
  static int TargetCount(const std::map<std::string, int>& targets, const std::string& model) {
    const auto target = targets.find(model);
    return target == targets.end() ? 0 : target->second;
  }

  // Per model that found fewer instances than it was looked for, its best rejected pose (accepted false), appended
  // to `detections` after them in score order.
  static void AddBestRejected(std::vector<ModelInFrame>* models, std::vector<Detection>* detections) {
    std::vector<Detection> rejected;
    for (ModelInFrame& model : *models) {
      if (!model.best_rejected) continue;
      const std::string& name = model.best_rejected->detection.model;
      const auto found = std::count_if(detections->begin(), detections->end(),
                                       [&](const Detection& detection) { return detection.model == name; });
      if (found >= model.max_instances) continue;
      rejected.push_back(std::move(model.best_rejected->detection));
      rejected.back().accepted = false;
    }
    std::stable_sort(rejected.begin(), rejected.end(),
                     [](const Detection& a, const Detection& b) { return a.score > b.score; });
    detections->insert(detections->end(), rejected.begin(), rejected.end());
  }

  ModelSearch Search(size_t model, const Scene& scene, int ransac_threads) {
    return ModelSearch(
        models_[model].record, options_, scene,
        [this, model, &scene](const Hypothesis& hypothesis) { return Verify(model, scene, hypothesis); },
        ransac_threads);
  }

  // Each model's priors tried at their poses (Track), the models on the workers, the best of them kept
  // (KeepBestFollowed); a prior that fails makes its model lost.
  void FollowPriors(const Scene& scene, std::vector<ModelInFrame>* models) {
    ParallelFor(models->size(), options_.threads, [&](size_t m) {
      ModelInFrame& model = (*models)[m];
      std::vector<Followed> followed;
      for (const Detection* prior : model.priors) {
        VerifiedPose tracked = Track(m, *prior, scene);
        if (Judge(tracked, &model)) {
          followed.push_back({std::move(tracked), !prior->tracked});
        } else {
          model.lost = true;
        }
      }
      KeepBestFollowed(std::move(followed), scene.frame->depth.size(), options_.max_overlap, options_.max_instances,
                       options_.dense_stride_px, &model);
    });
  }

  // Ranks every searched model's views quickly (PreselectOptions::rows and checks) and keeps searching only the
  // preselect.models models whose best view ranks highest (the larger consistent set); ties go to the earlier model.
  // The models left out, best ranked first.
  std::vector<size_t> Preselect(const Scene& scene, std::vector<ModelInFrame>* models) {
    RecognizerOptions quick = options_;
    quick.ranking.max_correspondences = options_.preselect.rows;
    quick.ranking.checks = options_.preselect.checks;
    std::vector<size_t> candidates;
    for (size_t m = 0; m < models->size(); ++m) {
      if ((*models)[m].search) candidates.push_back(m);
    }
    std::vector<int> best(models->size(), 0);
    ParallelFor(candidates.size(), options_.threads, [&](size_t i) {
      const size_t m = candidates[i];
      const ModelSearch search(models_[m].record, quick, scene, nullptr, 1);  // ranking only: nothing verified
      const std::vector<ViewCandidate> ranked = search.RankViews();
      best[m] = ranked.empty() ? 0 : ranked.front().score;
    });
    std::stable_sort(candidates.begin(), candidates.end(), [&](size_t a, size_t b) { return best[a] > best[b]; });
    const auto kept = static_cast<std::ptrdiff_t>(options_.preselect.models);
    for (auto m = candidates.begin() + kept; m != candidates.end(); ++m) (*models)[*m].search = false;
    return {candidates.begin() + kept, candidates.end()};
  }

  // View ranking, then the best pose over the ranked views for each instance up to max_instances.
  ModelSearchResult SearchModel(size_t m, const Scene& scene, int ransac_threads, ModelInFrame* model) {
    ModelSearchResult result;
    const ModelSearch search = Search(m, scene, ransac_threads);
    const Clock::time_point ranking = Clock::now();
    // A view's other descriptors are matched when it is tried: views after a good enough one are not.
    std::vector<ViewCandidate> ranked = search.RankViews();
    result.times.Add(Stage::kRank, MillisecondsSince(ranking));
    while (static_cast<int>(model->instances.size()) < model->max_instances) {
      // Once an instance is found the model is known to be in the frame: more of its views are worth trying.
      const bool first = model->instances.empty();
      const int views =
          first || options_.later_instance_views == 0 ? options_.views_per_model : options_.later_instance_views;
      std::optional<VerifiedPose> best =
          search.BestPose(views, first ? options_.give_up_after_views : 0, model->covered, &ranked, &result.times);
      if (best && options_.twins.enabled) best = BestTwin(m, scene, std::move(*best), &result.times);
      if (!best || !Judge(*best, model)) break;
      AddInstance(std::move(*best), options_.dense_stride_px, scene.frame->depth.size(), model);
    }
    result.views_tried = static_cast<int>(
        std::count_if(ranked.begin(), ranked.end(), [](const ViewCandidate& view) { return view.tried; }));
    return result;
  }

  // `hypothesis` refined by ICP from `verified` (its verification) and verified again; both are replaced when that
  // does not lower the score. Adds ICP and verification times.
  void RefineIfBetter(size_t model, const Scene& scene, const ModelSearch& search, Hypothesis* hypothesis,
                      VerifiedPose* verified, StageTimes* times) {
    Hypothesis refined_hypothesis = *hypothesis;
    Clock::time_point stage = Clock::now();
    search.Refine(verified->depth, &refined_hypothesis);
    times->Add(Stage::kRefine, MillisecondsSince(stage));
    stage = Clock::now();
    VerifiedPose refined = Verify(model, scene, refined_hypothesis);
    times->Add(Stage::kVerify, MillisecondsSince(stage));
    if (refined.detection.score >= verified->detection.score) {
      *hypothesis = refined_hypothesis;
      *verified = std::move(refined);
    }
  }

  // Geometry first: whether `turned` fits the frame's depth as well as `pose` (TwinOptions::fit_margin_m,
  // contour_margin), so that its appearance may decide between them.
  bool FitsAsWell(const Detection& turned, const Detection& pose) const {
    return turned.surface_error_m <= pose.surface_error_m + options_.twins.fit_margin_m &&
           turned.contour_agreement >= pose.contour_agreement - options_.twins.contour_margin;
  }

  // `pose`, or the best of its turns by 180 degrees about the model's principal axes (each refined by ICP when it
  // scored rival_min_ratio of `pose`) that beats it (TwinOptions); a pose below give_up_below_score is not turned.
  // Adds verification and ICP times.
  VerifiedPose BestTwin(size_t model, const Scene& scene, VerifiedPose pose, StageTimes* times) {
    if (pose.search_score < options_.give_up_below_score) return pose;
    const PrincipalBox& principal = models_[model].axes;
    const Detection original = pose.detection;
    const ModelSearch search = Search(model, scene, 1);
    for (int axis = 0; axis < 3; ++axis) {
      Hypothesis hypothesis;
      hypothesis.view = original.view;
      hypothesis.ransac.inlier_fraction = original.inlier_fraction;
      hypothesis.ransac.fit_error_m = original.fit_error_m;
      hypothesis.pose = TurnedHalfWayAbout(original.camera_from_object, principal.centre, principal.axes.col(axis));
      const Clock::time_point stage = Clock::now();
      VerifiedPose turned = Verify(model, scene, hypothesis);
      times->Add(Stage::kVerify, MillisecondsSince(stage));
      if (options_.refine && turned.search_score > 0.0 &&
          turned.search_score >= options_.rival_min_ratio * pose.search_score) {
        RefineIfBetter(model, scene, search, &hypothesis, &turned, times);
      }
      if (turned.detection.score > options_.twins.min_gain * pose.detection.score &&
          FitsAsWell(turned.detection, pose.detection)) {
        turned.detection.hypothesis_source = original.hypothesis_source;
        pose = std::move(turned);
      }
    }
    return pose;
  }

  // A prior's model at the prior's pose refined by ICP (from the model's surface rendered there) and verified. The
  // prior's own pose is verified only when the refined one is not accepted, and the better kept (RANSAC fields 0).
  VerifiedPose Track(size_t model, const Detection& prior, const Scene& scene) {
    Hypothesis hypothesis;
    hypothesis.view = prior.view;
    hypothesis.pose = prior.camera_from_object;
    std::optional<VerifiedPose> best;
    if (options_.refine) {
      Hypothesis refined = hypothesis;
      Search(model, scene, 1).Refine(Render(model, scene, hypothesis.pose).depth, &refined);
      best = Verify(model, scene, refined);
    }
    if (!best || !Accepted(best->detection)) {
      VerifiedPose at_prior = Verify(model, scene, hypothesis);
      if (!best || at_prior.detection.score > best->detection.score) best = std::move(at_prior);
    }
    best->detection.tracked = true;
    best->detection.frames_followed = prior.frames_followed + 1;
    best->detection.confirmed = prior.confirmed;
    best->detection.hypothesis_source = prior.hypothesis_source;
    return std::move(*best);
  }

  // What the recognizer keeps of a model's `mesh` besides the upload: its shape and colouring, its point pairs.
  void TakeMesh(const TriangleMesh& mesh, LoadedModel* model) const {
    model->render.cull_back_faces = options_.verify.cull_back_faces && mesh.IsClosedOutward();
    model->plain = OneColoured(mesh);
    model->axes = mesh.PrincipalAxesBox();
    model->diameter_m = mesh.Diameter();
    if (options_.point_pairs.source != HypothesisSource::kContext && NeedsMeshPointPairs(*model)) {
      MeshPointPairs(mesh, model);
    }
  }

  // With lazy meshes, the model's mesh decoded and uploaded now if it is not yet: once, whichever worker gets there
  // first. Never called while render_mutex_ is held.
  void EnsureMesh(size_t m) {
    if (!lazy_meshes_) return;
    LoadedModel& model = models_[m];
    std::call_once(*model.mesh_loaded, [&] {
      const TriangleMesh mesh = ModelMesh(library_.models()[m].record);
      TakeMesh(mesh, &model);
      const std::lock_guard<std::mutex> lock(render_mutex_);
      model.mesh = renderer_.AddMesh(mesh);
    });
  }

  // A model's point pair table as far as its library record decides it, at load: of its stored points when they were
  // drawn as the options draw them (deferred to its first use: PointPairTable); none (point_pair_refusal says why)
  // when the library holds no points for it or refused them; otherwise left to its mesh (MeshPointPairs).
  void PreparePointPairs(LoadedModel* model) const {
    const ModelRecord& record = model->record;
    if (!record.point_pairs) {
      model->point_pair_refusal =
          "the library holds no point pair points for it: built with --no-ppf, or migrated without a stored "
          "mesh; build the model again to add them";
    } else if (record.point_pairs->sampling == PointPairSampling()) {
      if (record.point_pairs->refusal.empty()) {
        model->point_pairs_deferred = true;
      } else {
        model->point_pair_refusal = record.point_pairs->refusal;
      }
    }
  }

  // The point pair sampling of the options.
  PpfModelSampling PointPairSampling() const {
    return PpfModelSampling::Of(options_.point_pairs.ppf, options_.point_pairs.model_samples);
  }

  // Whether the model's point pair table has to be drawn from its mesh (PreparePointPairs left it undecided).
  static bool NeedsMeshPointPairs(const LoadedModel& model) {
    return model.record.point_pairs && !model.point_pairs_deferred && model.point_pair_refusal.empty() &&
           !model.point_pairs;
  }

  // A table of points drawn from the model's `mesh` now (NeedsMeshPointPairs); the refusal kept when it is too
  // small, flat or coarse for point pairs.
  void MeshPointPairs(const TriangleMesh& mesh, LoadedModel* model) const {
    try {
      model->point_pairs = PpfModel::FromSampledPoints(SampleModelPoints(mesh, PointPairSampling()), mesh.Diameter(),
                                                       options_.point_pairs.ppf);
    } catch (const InputError& error) {
      model->point_pair_refusal = error.what();
    }
  }

  // The points of the model's point pair table, built or deferred (0: none, or not drawn yet).
  static size_t PointPairPoints(const LoadedModel& model) {
    if (model.point_pairs) return model.point_pairs->points().size();
    return model.point_pairs_deferred ? model.record.point_pairs->points.size() : 0;
  }

  // The model's point pair table, built now if deferred; nullptr when it has none.
  const PpfModel* PointPairTable(size_t m) {
    LoadedModel& model = models_[m];
    if (model.point_pairs_deferred) {
      std::call_once(*model.point_pairs_built, [&] {
        try {
          model.point_pairs =
              PpfModel::FromSampledPoints(model.record.point_pairs->points, model.diameter_m, options_.point_pairs.ppf);
        } catch (const InputError& error) {
          model.point_pair_refusal = error.what();
        }
      });
    }
    return model.point_pairs ? &*model.point_pairs : nullptr;
  }

  // Point pair hypotheses for every model still searched and not found (under kBoth: not found by the context), and
  // for the shape candidates among the models `left_out` by the pre-selection (ShapeCandidates); the models on the
  // workers. Adds the workers' times: voting (point_pairs), verification and ICP.
  void SearchByPointPairs(const Scene& scene, const std::vector<size_t>& left_out, std::vector<ModelInFrame>* models,
                          StageTimes* times) {
    const bool shapes = options_.preselect.shape_models > 0 && !left_out.empty();
    std::vector<size_t> wanted;
    for (size_t m = 0; m < models->size(); ++m) {
      // A lazy mesh not loaded yet whose table is to be drawn from it: known once it is (BestPointPairPose).
      if ((*models)[m].search && (*models)[m].instances.empty() &&
          (models_[m].point_pairs || models_[m].point_pairs_deferred || NeedsMeshPointPairs(models_[m]))) {
        wanted.push_back(m);
      }
    }
    if (wanted.empty() && !shapes) return;
    const std::vector<OrientedPoint> points =
        options_.point_pairs.remove_plane
            ? WithoutDominantPlane(OrientedScenePoints(scene.organized), options_.point_pairs.plane)
            : OrientedScenePoints(scene.organized);
    // Points on the surface of a detection made already (the context's, a followed prior's) lead no vote.
    std::vector<OrientedPoint> open, explained;
    const cv::Mat taken = DetectedSurface(*models, scene.frame->depth.size());
    for (const OrientedPoint& point : points) {
      const Eigen::Vector2d pixel = scene.frame->camera.Project(point.position.cast<double>());
      const int u = static_cast<int>(std::lround(pixel.x())), v = static_cast<int>(std::lround(pixel.y()));
      const bool inside = u >= 0 && v >= 0 && u < taken.cols && v < taken.rows;
      (inside && taken.at<uchar>(v, u) != 0 ? explained : open).push_back(point);
    }
    if (shapes) {
      const Clock::time_point stage = Clock::now();
      for (const size_t m : ShapeCandidates(left_out, open)) {
        (*models)[m].search = true;
        wanted.push_back(m);
      }
      times->Add(Stage::kPointPairs, MillisecondsSince(stage));
    }
    // The dearest first (a model's voting grows with its table, points squared), so that no worker is left with a
    // long one at the end while the other waits.
    std::stable_sort(wanted.begin(), wanted.end(),
                     [&](size_t a, size_t b) { return PointPairPoints(models_[a]) > PointPairPoints(models_[b]); });
    std::vector<StageTimes> model_times(wanted.size());
    ParallelFor(wanted.size(), options_.threads, [&](size_t i) {
      EnsureMesh(wanted[i]);
      std::optional<VerifiedPose> best = BestPointPairPose(wanted[i], scene, open, explained, &model_times[i]);
      if (best && options_.twins.enabled) best = BestTwin(wanted[i], scene, std::move(*best), &model_times[i]);
      if (best && Judge(*best, &(*models)[wanted[i]])) {
        AddInstance(std::move(*best), options_.dense_stride_px, scene.frame->depth.size(), &(*models)[wanted[i]]);
      }
    });
    for (const StageTimes& model : model_times) *times += model;
  }

  // Of the models `left_out` by the pre-selection, the shape_models whose coarse point pair table (CoarseTable)
  // gathers the most votes among the `open` scene points (those of no detection), most first; none without votes.
  // Votes per point of the table: a larger or busier model gathers more on any surface.
  std::vector<size_t> ShapeCandidates(const std::vector<size_t>& left_out, const std::vector<OrientedPoint>& open) {
    // Thinned once for all models to a 4 mm voxel (each sub-samples them again at its own coarse voxel).
    constexpr double kThinVoxelM = 0.004;
    const std::vector<OrientedPoint> thinned =
        SubsampleByNormals(open, kThinVoxelM, options_.point_pairs.ppf.keep_normal_deg);
    std::vector<double> votes(left_out.size(), 0.0);  // per table point
    ParallelFor(left_out.size(), options_.threads, [&](size_t i) {
      const PpfModel* table = CoarseTable(left_out[i]);
      if (table == nullptr) return;
      const std::vector<PpfPose> poses = FindPpfPoses(*table, thinned);
      if (!poses.empty()) votes[i] = poses.front().votes / static_cast<double>(table->points().size());
    });
    std::vector<size_t> order(left_out.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return votes[a] > votes[b]; });
    std::vector<size_t> chosen;
    for (const size_t i : order) {
      if (static_cast<int>(chosen.size()) == options_.preselect.shape_models || votes[i] <= 0.0) break;
      chosen.push_back(left_out[i]);
    }
    return chosen;
  }

  // A coarse point pair table of the model's stored points, to rank models by: twice the voxel and distance bin of
  // its own table (about a quarter of its points, a sixteenth of its pairs), 100 reference points voting. Built on
  // first use, once; nullptr when the model has no stored points or too few for a table.
  const PpfModel* CoarseTable(size_t m) {
    LoadedModel& model = models_[m];
    std::call_once(*model.coarse_built, [&] {
      const std::optional<PointPairRecord>& stored = model.record.point_pairs;
      if (!stored || !stored->refusal.empty() || stored->points.empty()) return;
      PpfOptions coarse = options_.point_pairs.ppf;
      coarse.sampling = std::min(0.5, 2.0 * coarse.sampling);
      coarse.distance_step = std::min(0.5, 2.0 * coarse.distance_step);
      coarse.max_references = 100;
      try {
        model.coarse_pairs = PpfModel(stored->points, model.record.diameter_m, coarse);
      } catch (const InputError&) {
        // too few points or pairs at this voxel: not a shape candidate
      }
    });
    return model.coarse_pairs ? &*model.coarse_pairs : nullptr;
  }

  // The pixels of the frame (`size`) on the rendered surface of the detections in `models`, each surface sample
  // (every dense_stride_px-th pixel) standing for its stride's square.
  cv::Mat DetectedSurface(const std::vector<ModelInFrame>& models, const cv::Size& size) const {
    cv::Mat taken = cv::Mat::zeros(size, CV_8UC1);
    const int stride = options_.dense_stride_px;
    for (const ModelInFrame& model : models) {
      for (const VerifiedPose& instance : model.instances) {
        for (const cv::Point& p : instance.surface) {
          cv::rectangle(taken, cv::Rect(p.x - stride / 2, p.y - stride / 2, stride, stride), 255, cv::FILLED);
        }
      }
    }
    return taken;
  }

  // The model's best point pair pose clusters among the scene's oriented `points` (the `explained` ones only paired
  // with), each verified; those that scored rival_min_ratio of the best of them refined by ICP and verified again (the
  // better kept): ICP is the dearest step, and a coarse pose far below the best rarely wins after it. The best of them.
  std::optional<VerifiedPose> BestPointPairPose(size_t model, const Scene& scene,
                                                const std::vector<OrientedPoint>& points,
                                                const std::vector<OrientedPoint>& explained, StageTimes* times) {
    Clock::time_point stage = Clock::now();
    const PpfModel* table = PointPairTable(model);
    if (table == nullptr) return std::nullopt;
    const std::vector<PpfPose> poses = FindPpfPoses(*table, points, explained);
    times->Add(Stage::kPointPairs, MillisecondsSince(stage));
    const size_t count = std::min(poses.size(), static_cast<size_t>(options_.point_pairs.clusters));
    std::vector<Hypothesis> hypotheses(count);
    std::vector<VerifiedPose> verified(count);
    double best_coarse = 0.0;
    for (size_t c = 0; c < count; ++c) {
      hypotheses[c].pose = poses[c].camera_from_object;
      stage = Clock::now();
      verified[c] = Verify(model, scene, hypotheses[c]);
      times->Add(Stage::kVerify, MillisecondsSince(stage));
      best_coarse = std::max(best_coarse, verified[c].search_score);
    }
    const ModelSearch search = Search(model, scene, 1);
    std::optional<VerifiedPose> best;
    for (size_t c = 0; c < count; ++c) {
      if (options_.refine && verified[c].search_score > 0.0 &&
          verified[c].search_score >= options_.rival_min_ratio * best_coarse) {
        RefineIfBetter(model, scene, search, &hypotheses[c], &verified[c], times);
      }
      verified[c].detection.hypothesis_source = HypothesisSource::kPpf;
      if (!best || verified[c].detection.score > best->detection.score) best = std::move(verified[c]);
    }
    return best;
  }

  // `poses` by model in library order, then best score first (ties by pose), whatever order the workers added them in.
  std::vector<Detection> SortedByModel(std::vector<Detection> poses) const {
    std::map<std::string, size_t> order;
    for (size_t m = 0; m < model_names_.size(); ++m) order[model_names_[m]] = m;
    std::sort(poses.begin(), poses.end(), [&](const Detection& a, const Detection& b) {
      if (a.model != b.model) return order[a.model] < order[b.model];
      if (a.score != b.score) return a.score > b.score;
      const Eigen::Vector3d ta = a.camera_from_object.translation(), tb = b.camera_from_object.translation();
      return std::lexicographical_compare(ta.data(), ta.data() + 3, tb.data(), tb.data() + 3);
    });
    return poses;
  }

  // The detections, best first, without those whose rendered surface lies mostly (max_overlap) on scene pixels
  // that a better detection of another model already explains: one surface, one object.
  std::vector<Detection> SuppressOverlaps(const cv::Size& image_size, std::vector<VerifiedPose> candidates) const {
    std::stable_sort(candidates.begin(), candidates.end(), [](const VerifiedPose& a, const VerifiedPose& b) {
      return a.detection.score > b.detection.score;
    });
    cv::Mat explained = cv::Mat::zeros(image_size, CV_8UC1);
    std::vector<Detection> kept;
    for (const VerifiedPose& candidate : candidates) {
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

  // The model rendered at `pose` at the frame's dense stride (one render at a time: one GL context).
  RenderResult Render(size_t model, const Scene& scene, const Eigen::Isometry3d& pose) {
    EnsureMesh(model);
    const PinholeCamera camera = scene.frame->camera.Sampled(options_.dense_stride_px);
    const std::lock_guard<std::mutex> lock(render_mutex_);
    return renderer_.Render(models_[model].mesh, camera, pose, models_[model].render);
  }

  // The model rendered at the pose, measured against the frame and scored.
  VerifiedPose Verify(size_t model, const Scene& scene, const Hypothesis& hypothesis) {
    const LibraryModel& library_model = library_.models()[model];
    const RenderResult rendered = Render(model, scene, hypothesis.pose);
    Eigen::Matrix3f to_scene = Eigen::Matrix3f::Identity();
    if (options_.verify.use_color_matrix && library_model.color_matrix) {
      to_scene = library_model.color_matrix->model_to_scene.cast<float>();
    }
    PoseEvidence evidence =
        MeasurePose({rendered.color, rendered.depth}, scene.verification, to_scene, options_.verify);
    VerifiedPose verified;
    Detection& detection = verified.detection;
    ScorePose(evidence, options_.verify, models_[model].plain, &detection);
    detection.model = library_model.record.name;
    detection.camera_from_object = hypothesis.pose;
    detection.inlier_fraction = hypothesis.ransac.inlier_fraction;
    detection.fit_error_m = hypothesis.ransac.fit_error_m;
    detection.view = hypothesis.view;
    VerifyOptions search = options_.verify;  // the search's score: without the continuation factor
    search.continuation_falloff = 0.0;
    Detection unjudged;
    ScorePose(evidence, search, models_[model].plain, &unjudged);
    verified.search_score = unjudged.score;
    if (options_.verify.reject_plane_patches && verified.search_score > 0.0 &&
        OnLargerPlane(*scene.frame, rendered.depth, evidence.surface, options_.dense_stride_px,
                      options_.verify.plane_patch)) {
      detection.score = verified.search_score = 0.0;
    }
    if (learned_ != nullptr) detection.acceptance = learned_->Probability(detection);
    if (scene.verified_log) {
      const std::lock_guard<std::mutex> lock(scene.verified_log->mutex);
      scene.verified_log->poses.push_back(detection);
    }
    verified.surface = std::move(evidence.surface);
    verified.depth = rendered.depth;
    return verified;
  }

  // The library's record of a model, its views' colours mapped by its colour matrix (if any and used) and their
  // descriptors recomputed (paper Sect. IV-C: A c_model = c_scene before matching).
  ModelRecord PreparedRecord(const LibraryModel& model) const {
    ModelRecord record = model.record;
    if (!options_.verify.use_color_matrix || !model.color_matrix) return record;
    // Scaled to keep grey's brightness: a gain below 1 shrinks the colour differences the descriptor bins, which are
    // not smaller in real frames. Matrices stored by `ecvpose colorcal` keep the brightness already.
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
  const AcceptanceModel* learned_;  // with Acceptance::kLearned, else null
  Renderer renderer_;
  std::mutex render_mutex_;               // Verify runs on the model workers
  std::vector<LoadedModel> models_;       // in the library's order
  std::vector<std::string> model_names_;  // the same order
  bool lazy_meshes_ = false;              // each model's mesh loaded on its first render (EnsureMesh)
};

cv::Mat Recognizer::Impl::DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections) {
  std::vector<SceneObject> objects;
  std::vector<Detection> drawn;
  for (const Detection& detection : detections) {
    const auto name = std::find(model_names_.begin(), model_names_.end(), detection.model);
    if (name != model_names_.end()) {
      const auto m = static_cast<size_t>(name - model_names_.begin());
      EnsureMesh(m);
      objects.push_back({models_[m].mesh, detection.camera_from_object});
      drawn.push_back(detection);
    }
  }
  return DrawDetectionOverlay(renderer_, objects, drawn, frame, options_.verify.depth_tolerance_m);
}

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

RecognitionResult Recognizer::RecognizeTargets(const RgbdFrame& frame, const std::map<std::string, int>& targets) {
  for (const auto& [model, count] : targets) {
    if (count < 1) ThrowInputError("targets", model, "at least 1 instance", std::to_string(count));
  }
  return impl_->Recognize(frame, {}, SearchScope::kAllModels, &targets);
}

std::map<std::string, std::vector<RankedView>> Recognizer::RankViews(const RgbdFrame& frame) {
  return impl_->RankViews(frame);
}

std::vector<std::string> Recognizer::PointPairWarnings() const {
  return impl_->PointPairWarnings();
}

cv::Mat Recognizer::DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections) {
  return impl_->DrawDetections(frame, detections);
}

}  // namespace ecv
