#include "recognize/recognizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "colorcal/color_matrix.h"
#include "core/error.h"
#include "core/timing.h"
#include "ecv/descriptor.h"
#include "ecv/primitives.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
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
  std::vector<Eigen::Vector3f> points;  // primitive positions first, then the dense depth points
  SceneVisibility visibility;
};

// The views of one model, or of all, in one index: each scene descriptor votes, through its nearest
// descriptor there, for one view of one model.
struct LibraryIndex {
  std::vector<Primitive> primitives;   // every view's primitives, view after view, model after model
  std::vector<int> model_of, view_of;  // the model and view of each
  std::unique_ptr<DescriptorMatcher> matcher;
};

// An index over the views of records[first .. last).
LibraryIndex BuildVoteIndex(const std::vector<ModelRecord>& records, size_t first, size_t last,
                            const MatchOptions& options) {
  LibraryIndex index;
  Descriptors all;
  std::vector<cv::Mat> rows;
  for (size_t m = first; m < last; ++m) {
    for (size_t v = 0; v < records[m].views.size(); ++v) {
      const ModelView& view = records[m].views[v];
      const int offset = static_cast<int>(index.primitives.size());
      index.primitives.insert(index.primitives.end(), view.primitives.begin(), view.primitives.end());
      index.model_of.insert(index.model_of.end(), view.primitives.size(), static_cast<int>(m));
      index.view_of.insert(index.view_of.end(), view.primitives.size(), static_cast<int>(v));
      if (view.descriptors.values.rows == 0) continue;
      rows.push_back(view.descriptors.values);
      for (const int primitive : view.descriptors.primitive) all.primitive.push_back(primitive + offset);
    }
  }
  if (rows.empty()) return index;
  cv::vconcat(rows, all.values);
  index.matcher = std::make_unique<DescriptorMatcher>(index.primitives, all, options);
  return index;
}

// A model view ranked by its distinctive matches, with the correspondences for RANSAC.
struct ViewCandidate {
  int view = -1;
  int votes = 0;
  std::vector<Correspondence> correspondences;
};

// A pose hypothesis of a model from one of its views.
struct Hypothesis {
  int view = -1;
  RansacResult ransac;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

}  // namespace

RansacOptions RecognizerOptions::DefaultRansac() {
  RansacOptions options;           // the paper's numbers
  options.adaptive = true;         // beyond the paper: stop once the best pose shows the sampled views are easy
  options.prefer_agreeing = true;  // and rank poses by agreeing (appearance-bearing) correspondences
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
  require(ratio_test > 0.0 && ratio_test <= 1.0, "ratio_test", "in (0, 1]");
  require(dense_stride_px >= 1, "dense_stride_px", "at least 1");
  require(depth_tolerance_m > 0.0, "depth_tolerance_m", "> 0 m");
  require(color_tolerance > 0.0, "color_tolerance", "> 0");
  require(min_score >= 0.0 && min_score <= 1.0, "min_score", "in [0, 1]");
  require(min_visible_fraction >= 0.0 && min_visible_fraction <= 1.0, "min_visible_fraction", "in [0, 1]");
}

class Recognizer::Impl {
 public:
  Impl(const ModelLibrary& library, const RecognizerOptions& options) : library_(library), options_(options) {
    options_.Check();
    options_.match.k = 2;
    for (const LibraryModel& model : library_.models()) {
      // With a colour matrix, the views' colours are mapped into the scene camera's colours and their
      // descriptors recomputed (paper Sect. IV-C: A c_model = c_scene before matching).
      records_.push_back(model.record);
      ModelRecord& record = records_.back();
      if (options_.use_color_matrix && model.color_matrix) {
        for (ModelView& view : record.views) {
          ApplyColorMatrix(model.color_matrix->model_to_scene, &view.primitives);
          view.descriptors = ComputeDescriptors(view.primitives, library_.feature_settings().descriptor);
        }
      }
      MeshLoadOptions load;
      load.metres_per_unit = MetresPerUnit(record.unit);
      load.object_from_mesh = record.object_from_mesh;
      load.allow_missing_textures = true;
      meshes_.push_back(renderer_.AddMesh(LoadMesh(record.mesh_path, load)));
    }
    if (options_.library_wide_votes) {
      vote_indices_.push_back(BuildVoteIndex(records_, 0, records_.size(), options_.match));
    } else {
      for (size_t m = 0; m < records_.size(); ++m)
        vote_indices_.push_back(BuildVoteIndex(records_, m, m + 1, options_.match));
    }
  }

  RecognitionResult Recognize(const RgbdFrame& frame) {
    frame.Check();
    const Clock::time_point start = Clock::now();
    RecognitionResult result;
    const Scene scene = PrepareScene(frame, &result);
    Clock::time_point stage = Clock::now();
    const std::vector<std::vector<int>> votes = CountVotes(scene);
    result.timings_ms["match"] += MillisecondsSince(stage);
    for (size_t m = 0; m < library_.models().size(); ++m) {
      stage = Clock::now();
      const std::vector<ViewCandidate> views = RankViews(m, votes[m], scene);
      result.timings_ms["match"] += MillisecondsSince(stage);

      stage = Clock::now();
      std::vector<Hypothesis> hypotheses = EstimatePoses(records_[m], views, scene);
      result.timings_ms["ransac"] += MillisecondsSince(stage);

      // Every hypothesis is verified as it is; the best one is refined and verified again.
      stage = Clock::now();
      std::optional<Detection> best;
      Hypothesis* best_hypothesis = nullptr;
      for (Hypothesis& hypothesis : hypotheses) {
        Detection detection = Verify(m, scene, hypothesis);
        if (!best || detection.score > best->score) {
          best = detection;
          best_hypothesis = &hypothesis;
        }
      }
      result.timings_ms["verify"] += MillisecondsSince(stage);
      if (best_hypothesis != nullptr && options_.refine) {
        stage = Clock::now();
        Hypothesis refined = *best_hypothesis;
        Refine(m, scene, &refined);
        result.timings_ms["refine"] += MillisecondsSince(stage);
        stage = Clock::now();
        const Detection detection = Verify(m, scene, refined);
        if (detection.score >= best->score) best = detection;  // ICP must not make the pose worse
        result.timings_ms["verify"] += MillisecondsSince(stage);
      }
      if (best && (best->score < options_.min_score || best->visible_fraction < options_.min_visible_fraction)) {
        best.reset();
      }
      if (best) result.detections.push_back(*best);
    }
    std::sort(result.detections.begin(), result.detections.end(),
              [](const Detection& a, const Detection& b) { return a.score > b.score; });
    result.timings_ms["total"] = MillisecondsSince(start);
    return result;
  }

 private:
  Scene PrepareScene(const RgbdFrame& frame, RecognitionResult* result) const {
    Scene scene;
    scene.frame = &frame;
    Clock::time_point stage = Clock::now();
    const FeatureSettings& settings = library_.feature_settings();
    scene.primitives = ExtractPrimitives(frame, settings.ecv).primitives;
    result->scene_primitives = static_cast<int>(scene.primitives.size());
    result->timings_ms["extract"] = MillisecondsSince(stage);

    stage = Clock::now();
    scene.descriptors = ComputeDescriptors(scene.primitives, settings.descriptor);
    if (scene.descriptors.values.rows > 0) {
      scene.matcher = std::make_unique<DescriptorMatcher>(scene.primitives, scene.descriptors, options_.match);
    }
    result->timings_ms["describe"] = MillisecondsSince(stage);

    scene.points = PrimitivePositions(scene.primitives);
    const int stride = options_.dense_stride_px;
    for (int v = 0; v < frame.depth.rows; v += stride) {
      for (int u = 0; u < frame.depth.cols; u += stride) {
        const float z = frame.depth.at<float>(v, u);
        if (z > 0.0F) scene.points.push_back(frame.camera.BackProject({u, v}, z).cast<float>());
      }
    }
    scene.visibility.depth = frame.depth;
    scene.visibility.camera = frame.camera;
    return scene;
  }

  // Votes per model and view: scene descriptors whose nearest library descriptor lies in the view and
  // passes the ratio test against the second nearest.
  std::vector<std::vector<int>> CountVotes(const Scene& scene) const {
    std::vector<std::vector<int>> votes;
    for (const ModelRecord& record : records_) votes.emplace_back(record.views.size(), 0);
    if (!scene.matcher) return votes;
    for (const LibraryIndex& index : vote_indices_) {
      if (!index.matcher) continue;
      const std::vector<DescriptorMatch> matches = index.matcher->Match(scene.primitives, scene.descriptors);
      for (size_t i = 0; i + 1 < matches.size(); ++i) {
        const DescriptorMatch& nearest = matches[i];
        const DescriptorMatch& second = matches[i + 1];
        if (nearest.rank != 0 || second.rank != 1 || second.query != nearest.query) continue;
        if (nearest.distance < options_.ratio_test * second.distance) {
          const size_t train = static_cast<size_t>(nearest.train);
          ++votes[static_cast<size_t>(index.model_of[train])][static_cast<size_t>(index.view_of[train])];
        }
      }
    }
    return votes;
  }

  // The model's views with the most votes, each with its correspondences: the nearest scene descriptor of
  // each of its descriptors (paper: object to scene).
  std::vector<ViewCandidate> RankViews(size_t model, const std::vector<int>& votes, const Scene& scene) const {
    std::vector<ViewCandidate> views;
    if (!scene.matcher) return views;
    const ModelRecord& record = records_[model];
    std::vector<int> order(record.views.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return votes[static_cast<size_t>(a)] > votes[static_cast<size_t>(b)]; });
    order.resize(std::min(order.size(), static_cast<size_t>(options_.views_per_model)));
    for (const int v : order) {
      const ModelView& view = record.views[static_cast<size_t>(v)];
      if (view.descriptors.values.rows == 0) continue;
      ViewCandidate candidate;
      candidate.view = v;
      candidate.votes = votes[static_cast<size_t>(v)];
      for (const DescriptorMatch& match : scene.matcher->Match(view.primitives, view.descriptors)) {
        if (match.rank == 0) candidate.correspondences.push_back({match.query, match.train});
      }
      views.push_back(std::move(candidate));
    }
    return views;
  }

  std::vector<Hypothesis> EstimatePoses(const ModelRecord& model, const std::vector<ViewCandidate>& views,
                                        const Scene& scene) const {
    std::vector<Hypothesis> hypotheses;
    for (const ViewCandidate& candidate : views) {
      const ModelView& view = model.views[static_cast<size_t>(candidate.view)];
      const std::vector<Eigen::Vector3f> object_points = PrimitivePositions(view.primitives);
      Hypothesis hypothesis;
      hypothesis.view = candidate.view;
      hypothesis.ransac = EstimatePoseRansac(object_points, scene.points, candidate.correspondences, options_.ransac,
                                             &scene.visibility);
      hypothesis.pose = hypothesis.ransac.scene_from_object;
      if (hypothesis.ransac.success) hypotheses.push_back(hypothesis);
    }
    return hypotheses;
  }

  // Point-to-plane ICP of the model's visible surface (rendered at the pose) against the scene points near it.
  void Refine(size_t model, const Scene& scene, Hypothesis* hypothesis) {
    const RgbdFrame& frame = *scene.frame;
    const RenderResult rendered = renderer_.Render(meshes_[model], frame.camera, hypothesis->pose);
    const Eigen::Isometry3f object_from_camera = hypothesis->pose.inverse().cast<float>();
    std::vector<Eigen::Vector3f> object_points;
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (int v = 0; v < rendered.depth.rows; v += options_.dense_stride_px) {
      for (int u = 0; u < rendered.depth.cols; u += options_.dense_stride_px) {
        const float z = rendered.depth.at<float>(v, u);
        if (z <= 0.0F) continue;
        const Eigen::Vector3f point = frame.camera.BackProject({u, v}, z).cast<float>();
        centre += point;
        object_points.push_back(object_from_camera * point);
      }
    }
    if (object_points.size() < 10) return;
    centre /= static_cast<float>(object_points.size());
    const float radius = 0.5F * static_cast<float>(library_.models()[model].record.diameter_m) + 0.03F;
    std::vector<Eigen::Vector3f> near;
    for (size_t i = scene.primitives.size(); i < scene.points.size(); i += 2) {  // half the dense points suffice
      if ((scene.points[i] - centre).squaredNorm() < radius * radius) near.push_back(scene.points[i]);
    }
    const IcpResult icp = RefinePointToPlane(object_points, near, hypothesis->pose, options_.icp);
    if (icp.success) hypothesis->pose = icp.scene_from_object;
  }

  Detection Verify(size_t model, const Scene& scene, const Hypothesis& hypothesis) {
    const LibraryModel& library_model = library_.models()[model];
    const RgbdFrame& frame = *scene.frame;
    const RenderResult rendered = renderer_.Render(meshes_[model], frame.camera, hypothesis.pose);
    Eigen::Matrix3f to_scene = Eigen::Matrix3f::Identity();
    if (options_.use_color_matrix && library_model.color_matrix) {
      to_scene = library_model.color_matrix->model_to_scene.cast<float>();
    }
    int rendered_pixels = 0, visible = 0, on_surface = 0;
    std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> colors;  // (model through A, scene) on the surface
    const float tolerance = static_cast<float>(options_.depth_tolerance_m);
    for (int v = 0; v < rendered.depth.rows; v += options_.dense_stride_px) {
      for (int u = 0; u < rendered.depth.cols; u += options_.dense_stride_px) {
        const float model_z = rendered.depth.at<float>(v, u);
        if (model_z <= 0.0F) continue;
        ++rendered_pixels;
        const float scene_z = frame.depth.at<float>(v, u);
        if (scene_z <= 0.0F || scene_z < model_z - tolerance) continue;  // no measurement, or hidden
        ++visible;
        if (std::abs(scene_z - model_z) > tolerance) continue;
        ++on_surface;
        const cv::Vec3b& m = rendered.color.at<cv::Vec3b>(v, u);
        const cv::Vec3b& s = frame.color.at<cv::Vec3b>(v, u);
        colors.emplace_back(to_scene * Eigen::Vector3f(m[0], m[1], m[2]) / 255.0F,
                            Eigen::Vector3f(s[0], s[1], s[2]) / 255.0F);
      }
    }
    // Colours compared after one gain (scene brightness over model brightness, 0.5 .. 2): exposure and
    // light level differ between the texture capture and the scene even when the colours are right.
    float model_sum = 0.0F, scene_sum = 0.0F;
    for (const auto& [m, s] : colors) {
      model_sum += m.sum();
      scene_sum += s.sum();
    }
    const float gain = model_sum > 0.0F ? std::clamp(scene_sum / model_sum, 0.5F, 2.0F) : 1.0F;
    const auto same_color = std::count_if(colors.begin(), colors.end(), [&](const auto& pair) {
      return (gain * pair.first - pair.second).norm() < static_cast<float>(options_.color_tolerance);
    });

    Detection detection;
    detection.model = library_model.record.name;
    detection.camera_from_object = hypothesis.pose;
    detection.inlier_fraction = hypothesis.ransac.inlier_fraction;
    detection.fit_error_m = hypothesis.ransac.fit_error_m;
    detection.view = hypothesis.view;
    detection.visible_fraction = rendered_pixels > 0 ? static_cast<double>(visible) / rendered_pixels : 0.0;
    detection.depth_agreement = visible > 0 ? static_cast<double>(on_surface) / visible : 0.0;
    detection.color_agreement = on_surface > 0 ? static_cast<double>(same_color) / on_surface : 0.0;
    detection.score = detection.depth_agreement * detection.color_agreement;
    return detection;
  }

 public:
  cv::Mat DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections) {
    std::vector<SceneObject> objects;
    for (const Detection& detection : detections) {
      for (size_t m = 0; m < library_.models().size(); ++m) {
        if (library_.models()[m].record.name == detection.model) {
          objects.push_back({meshes_[m], detection.camera_from_object});
        }
      }
    }
    const OverlayOptions overlay;
    RenderResult rendered = renderer_.RenderScene(objects, frame.camera, OverlayRenderOptions(overlay));
    for (int v = 0; v < rendered.depth.rows; ++v) {  // scene surfaces in front of a model hide it
      for (int u = 0; u < rendered.depth.cols; ++u) {
        const float scene_z = frame.depth.at<float>(v, u), model_z = rendered.depth.at<float>(v, u);
        if (model_z > 0.0F && scene_z > 0.0F && scene_z < model_z - static_cast<float>(options_.depth_tolerance_m)) {
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
  const ModelLibrary& library_;
  RecognizerOptions options_;
  std::vector<ModelRecord> records_;  // per model: the library's, colours mapped by its colour matrix if any
  Renderer renderer_;
  std::vector<MeshId> meshes_;
  std::vector<LibraryIndex> vote_indices_;  // one per model, or one for all (library_wide_votes)
};

Recognizer::Recognizer(const ModelLibrary& library, const RecognizerOptions& options)
    : impl_(std::make_unique<Impl>(library, options)) {}

Recognizer::~Recognizer() = default;

RecognitionResult Recognizer::Recognize(const RgbdFrame& frame) {
  return impl_->Recognize(frame);
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
                          {"visible_fraction", d.visible_fraction}});
  }
  return {{"detections", detections}, {"timings_ms", result.timings_ms}, {"scene_primitives", result.scene_primitives}};
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

}  // namespace ecv
