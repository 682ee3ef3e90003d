#include "recognize/verification.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "recognize/detection.h"

namespace ecv {
namespace {

constexpr double kRadiansPerDegree = 3.14159265358979323846 / 180.0;

}  // namespace

void VerifyOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("verification options", field, expected);
  };
  require(depth_tolerance_m > 0.0, "depth_tolerance_m", "> 0 m");
  require(color_blur_px >= 0.0, "color_blur_px", ">= 0 pixels");
  require(residual_free_m >= 0.0, "residual_free_m", ">= 0 m");
  require(residual_falloff_m >= 0.0, "residual_falloff_m", ">= 0 m (0: no fit factor)");
  require(contour_free >= 0.0 && contour_free <= 1.0, "contour_free", "in [0, 1]");
  require(contour_falloff >= 0.0, "contour_falloff", ">= 0 (0: no contour factor)");
  require(depth_step_m > 0.0, "depth_step_m", "> 0 m");
  require(min_outline_samples >= 0, "min_outline_samples", ">= 0");
  require(continuation_free >= 0.0 && continuation_free <= 1.0, "continuation_free", "in [0, 1]");
  require(continuation_falloff >= 0.0, "continuation_falloff", ">= 0 (0: no continuation factor)");
  continuation.Check();
  require(edge_weight >= 0.0 && edge_weight <= 1.0, "edge_weight", "in [0, 1] (0: colour alone)");
  require(min_edge_pixels >= 1, "min_edge_pixels", "at least 1");
  edge.Check();
  require(plain_appearance >= 0.0 && plain_appearance <= 1.0, "plain_appearance", "in [0, 1] (0: by colours)");
  require(explain_distance_m > 0.0, "explain_distance_m", "> 0 m");
  require(explain_angle_deg > 0.0 && explain_angle_deg <= 90.0, "explain_angle_deg", "in (0, 90] degrees");
  require(normal_reach_px >= 1 && normal_reach_px <= 20, "normal_reach_px", "in [1, 20] samples");
  require(free_space_margin_m > 0.0, "free_space_margin_m", "> 0 m");
  occluding.Check();
  require(min_score >= 0.0 && min_score <= 1.0, "min_score", "in [0, 1]");
  require(min_visible_fraction >= 0.0 && min_visible_fraction <= 1.0, "min_visible_fraction", "in [0, 1]");
  plane_patch.Check();
  require(max_texture_size >= 1, "max_texture_size", "at least 1 pixel");
}

VerificationFrame MakeVerificationFrame(const RgbdFrame& frame, const VerifyOptions& options, int stride) {
  if (stride < 1) ThrowInputError("verification", "stride", "at least 1 pixel", std::to_string(stride));
  VerificationFrame verification;
  verification.depth = frame.depth;
  verification.stride = stride;
  // Into a new image: the blur must not change the caller's frame.
  if (options.color_blur_px > 0.0) {
    cv::GaussianBlur(frame.color, verification.color, cv::Size(0, 0), options.color_blur_px);
  } else {
    verification.color = frame.color;
  }
  // Grown by 2 pixels, so that the outline of a pose a pixel or two off still lies on its object's step.
  verification.depth_steps = DepthSteps(frame.depth, options.depth_step_m, 2);
  // A render's pixel (u, v) is the frame's (stride u, stride v): the blurred grey image sampled so.
  cv::Mat grey, sampled((frame.color.rows + stride - 1) / stride, (frame.color.cols + stride - 1) / stride, CV_8UC1);
  cv::cvtColor(verification.color, grey, cv::COLOR_RGB2GRAY);
  for (int v = 0; v < sampled.rows; ++v) {
    for (int u = 0; u < sampled.cols; ++u) sampled.at<uchar>(v, u) = grey.at<uchar>(v * stride, u * stride);
  }
  verification.gradient = GreyGradient(sampled);
  verification.camera = frame.camera.Sampled(stride);
  cv::Mat sampled_depth(sampled.size(), CV_32FC1);
  for (int v = 0; v < sampled.rows; ++v) {
    for (int u = 0; u < sampled.cols; ++u)
      sampled_depth.at<float>(v, u) = frame.depth.at<float>(v * stride, u * stride);
  }
  verification.normals =
      DepthNormals(sampled_depth, verification.camera, options.normal_reach_px, options.depth_step_m);
  return verification;
}

PoseEvidence MeasurePose(const RenderedPose& rendered, const VerificationFrame& frame,
                         const Eigen::Matrix3f& model_to_scene, const VerifyOptions& options) {
  const int stride = frame.stride;
  if (rendered.depth.type() != CV_32FC1 || rendered.color.type() != CV_8UC3 ||
      rendered.color.size() != rendered.depth.size() ||
      rendered.depth.rows != (frame.depth.rows + stride - 1) / stride ||
      rendered.depth.cols != (frame.depth.cols + stride - 1) / stride) {
    ThrowInputError("verification", "rendered pose", "CV_8UC3 colour and CV_32FC1 depth of the frame's size / stride");
  }
  if (frame.normals.size() != rendered.depth.size()) {
    ThrowInputError("verification", "frame", "normals at the stride (MakeVerificationFrame)");
  }
  cv::Mat model_color;
  if (options.color_blur_px > 0.0) {
    cv::GaussianBlur(rendered.color, model_color, cv::Size(0, 0), options.color_blur_px / stride);
  } else {
    model_color = rendered.color;
  }
  PoseEvidence evidence;
  double residual_sum = 0.0;
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> colors;  // (model through the matrix, scene) on the surface
  const float tolerance = static_cast<float>(options.depth_tolerance_m);
  // The texture edges are compared 2 samples inside the silhouette, where the render's own outline (against its
  // black background) does not reach.
  cv::Mat interior;
  cv::erode(rendered.depth > 0.0F, interior, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  std::vector<cv::Point> interior_surface;  // surface pixels inside, at the stride
  const cv::Mat model_normals =
      DepthNormals(rendered.depth, frame.camera, options.normal_reach_px, options.depth_step_m);
  const auto explain_distance = static_cast<float>(options.explain_distance_m);
  const auto min_cos = static_cast<float>(std::cos(options.explain_angle_deg * kRadiansPerDegree));
  const auto free_space_margin = static_cast<float>(options.free_space_margin_m);
  for (int v = 0; v < rendered.depth.rows; ++v) {
    for (int u = 0; u < rendered.depth.cols; ++u) {
      const float model_z = rendered.depth.at<float>(v, u);
      if (model_z <= 0.0F) continue;
      ++evidence.rendered_pixels;
      const int scene_u = u * stride, scene_v = v * stride;
      const float scene_z = frame.depth.at<float>(scene_v, scene_u);
      if (scene_z <= 0.0F || scene_z < model_z - tolerance) continue;  // no measurement, or hidden
      ++evidence.visible;
      if (scene_z > model_z + free_space_margin) ++evidence.behind;
      const cv::Vec3f& model_normal = model_normals.at<cv::Vec3f>(v, u);
      if (model_normal != cv::Vec3f()) {
        ++evidence.normal_pixels;
        if (std::abs(scene_z - model_z) <= explain_distance &&
            model_normal.dot(frame.normals.at<cv::Vec3f>(v, u)) >= min_cos) {
          ++evidence.explained;
        }
      }
      if (std::abs(scene_z - model_z) > tolerance) continue;
      residual_sum += std::abs(scene_z - model_z);
      evidence.surface.emplace_back(scene_u, scene_v);
      if (interior.at<uchar>(v, u) != 0) interior_surface.emplace_back(u, v);
      const cv::Vec3b& m = model_color.at<cv::Vec3b>(v, u);
      const cv::Vec3b& s = frame.color.at<cv::Vec3b>(scene_v, scene_u);
      colors.emplace_back(model_to_scene * Eigen::Vector3f(m[0], m[1], m[2]) / 255.0F,
                          Eigen::Vector3f(s[0], s[1], s[2]) / 255.0F);
    }
  }
  const auto on_surface = static_cast<int>(evidence.surface.size());
  evidence.surface_error_m = on_surface > 0 ? residual_sum / on_surface : 0.0;
  evidence.color_agreement = ColorCorrelation(colors);
  cv::Mat model_grey;
  cv::cvtColor(model_color, model_grey, cv::COLOR_RGB2GRAY);
  evidence.edges = CompareEdges(GreyGradient(model_grey), frame.gradient, interior_surface, options.edge);
  evidence.outline =
      OutlineOnDepthSteps(rendered.depth, stride, frame.depth, frame.depth_steps, options.depth_tolerance_m);
  evidence.occluding = OccludingContourSteps(rendered.depth, stride, frame.depth, frame.normals,
                                             options.depth_tolerance_m, options.occluding);
  if (options.continuation_falloff > 0.0) {
    evidence.continuation =
        SurfaceContinuation(rendered.depth, stride, frame.depth, options.depth_tolerance_m, options.continuation);
  }
  return evidence;
}

double FitFactor(double residual_m, const VerifyOptions& options) {
  if (options.residual_falloff_m <= 0.0) return 1.0;
  return std::clamp(1.0 - (residual_m - options.residual_free_m) / options.residual_falloff_m, 0.0, 1.0);
}

void ScorePose(const PoseEvidence& evidence, const VerifyOptions& options, bool plain, Detection* detection) {
  const auto on_surface = static_cast<int>(evidence.surface.size());
  detection->color_agreement = evidence.color_agreement;
  detection->edge_agreement = evidence.edges.Share();
  detection->edge_pixels = evidence.edges.predicted;
  detection->visible_fraction =
      evidence.rendered_pixels > 0 ? static_cast<double>(evidence.visible) / evidence.rendered_pixels : 0.0;
  detection->depth_agreement = evidence.visible > 0 ? static_cast<double>(on_surface) / evidence.visible : 0.0;
  detection->surface_error_m = evidence.surface_error_m;
  detection->contour_agreement = evidence.outline.Share();
  detection->continuation = evidence.continuation.Share();
  detection->explained_surface =
      evidence.normal_pixels > 0 ? static_cast<double>(evidence.explained) / evidence.normal_pixels : 0.0;
  detection->free_space_violation =
      evidence.visible > 0 ? static_cast<double>(evidence.behind) / evidence.visible : 0.0;
  detection->occluding_contour = evidence.occluding.SteppingBack();
  detection->creased_contour = evidence.occluding.Creased();
  const double contour =
      ContourFactor(evidence.outline, options.contour_free, options.contour_falloff, options.min_outline_samples);
  const double appearance =
      plain && options.plain_appearance > 0.0
          ? options.plain_appearance
          : Appearance(evidence.color_agreement, evidence.edges, options.edge_weight, options.min_edge_pixels);
  detection->score = detection->depth_agreement * appearance * FitFactor(evidence.surface_error_m, options) * contour *
                     ContinuationFactor(evidence.continuation, options.continuation_free, options.continuation_falloff,
                                        options.min_outline_samples);
}

bool OnLargerPlane(const RgbdFrame& frame, const cv::Mat& rendered_depth, const std::vector<cv::Point>& surface,
                   int stride, const PlanePatchOptions& options) {
  constexpr int kRingSamples = 3;
  auto scene_point = [&](int u, int v) -> Eigen::Vector3f {
    return frame.camera.BackProject({u, v}, frame.depth.at<float>(v, u)).cast<float>();
  };
  std::vector<Eigen::Vector3f> surface_points, ring_points;
  for (const cv::Point& p : surface) surface_points.push_back(scene_point(p.x, p.y));
  const cv::Mat silhouette = rendered_depth > 0.0F;
  cv::Mat grown;
  cv::dilate(silhouette, grown,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * kRingSamples + 1, 2 * kRingSamples + 1)));
  for (int v = 0; v < grown.rows; ++v) {
    for (int u = 0; u < grown.cols; ++u) {
      if (grown.at<uchar>(v, u) == 0 || silhouette.at<uchar>(v, u) != 0) continue;
      if (frame.depth.at<float>(v * stride, u * stride) > 0.0F)
        ring_points.push_back(scene_point(u * stride, v * stride));
    }
  }
  return PatchOfLargerPlane(surface_points, ring_points, options);
}

}  // namespace ecv
