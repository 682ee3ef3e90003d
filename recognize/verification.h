#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/frame.h"
#include "recognize/scoring.h"

namespace ecv {

struct Detection;

/// How a pose is verified: the model is rendered at it and compared with the frame (beyond the paper). The score
/// is depth agreement x appearance x fit, contour and continuation factors; bench/RESULTS.md, "Recognizer defaults",
/// says how each default was chosen.
struct VerifyOptions {
  /// A rendered pixel lies on the scene surface when their depths differ by at most this; a scene surface further
  /// than this in front hides it. Metres.
  double depth_tolerance_m = 0.015;
  /// Gaussian sigma of both colour images before their correlation, pixels of the frame: forgives a pose a pixel
  /// or two off.
  double color_blur_px = 1.5;
  /// Fit factor: 1 while the mean |rendered - scene depth| on the surface pixels is at most residual_free_m, falling
  /// linearly to 0 over residual_falloff_m beyond (0: no factor). A right pose after ICP fits to the sensor's noise.
  double residual_free_m = 0.0035;
  double residual_falloff_m = 0.003;
  /// Contour factor: 1 from a share of contour_free of the seen outline on a scene depth step (more than
  /// depth_step_m to a neighbour), falling linearly to 0 over contour_falloff below (0: no factor, for objects
  /// thinner than depth_step_m lying flat); 1 when fewer than min_outline_samples outline samples are seen.
  double contour_free = 0.3;
  double contour_falloff = 0.2;
  double depth_step_m = 0.01;
  int min_outline_samples = 20;
  /// Continuation factor: 1 up to a share of continuation_free of the judged outline across which the scene's surface
  /// runs on (SurfaceContinuation), falling linearly to 0 over continuation_falloff above (0: no factor); 1 when
  /// fewer than min_outline_samples outline samples could be judged. A model that covers part of a surface loses to
  /// one that covers all of it.
  double continuation_free = 0.4;
  double continuation_falloff = 0.3;
  ContinuationOptions continuation;
  /// Appearance: colour correlation^(1 - edge_weight) x share of the model's texture edges the scene shows^edge_weight
  /// (CompareEdges), colour alone when fewer than min_edge_pixels edges are predicted.
  double edge_weight = 0.5;
  int min_edge_pixels = 50;
  EdgeOptions edge;
  /// A model painted in one colour (no texture, one vertex or material colour: a grey CAD mesh) says nothing of the
  /// object's print: its appearance term is this instead, and it is judged by its geometry (0: by its colours, as
  /// any model).
  double plain_appearance = 0.0;
  /// The geometric evidence a pose's record carries (not yet part of the score): a visible rendered point is
  /// explained by the scene point on its ray within explain_distance_m (metres) whose normal lies within
  /// explain_angle_deg (degrees) of the rendered surface's ...
  double explain_distance_m = 0.005;
  double explain_angle_deg = 30.0;
  /// ... normals from the points normal_reach_px samples away (at the dense stride), not across a depth step;
  int normal_reach_px = 2;
  /// ... the scene violates the pose's free space where it is seen more than free_space_margin_m behind the model's
  /// surface, metres; ...
  double free_space_margin_m = 0.03;
  /// ... and where the scene's surface ends at the pose's outline.
  OccludingContourOptions occluding;
  double min_score = 0.3;             ///< poses below are not detections
  double min_visible_fraction = 0.1;  ///< nor poses of which the scene can show less than this share
  /// A pose whose surface is one patch of a larger scene plane scores 0 (PatchOfLargerPlane): the depth shows
  /// nothing of the object there (a can sunk into a table, its lid flush with the table top).
  bool reject_plane_patches = true;
  PlanePatchOptions plane_patch;
  /// Render the model's colours through its stored colour matrix (when it has one).
  bool use_color_matrix = true;
  /// Textures larger than this (pixels per side) are downscaled for verification renders: a model covers a few
  /// hundred pixels there, and decoding and uploading YCB's 4096 px textures dominated the set-up.
  int max_texture_size = 2048;
  /// Skip the faces turned away from the camera for meshes that close outwards: the same images, a third faster.
  bool cull_back_faces = true;

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// The frame as verification compares rendered poses with it; made once per frame (MakeVerificationFrame).
struct VerificationFrame {
  cv::Mat depth;         ///< the frame's depth, CV_32FC1 metres
  cv::Mat color;         ///< the frame's colours blurred by color_blur_px, CV_8UC3 RGB
  cv::Mat depth_steps;   ///< DepthSteps of the frame, grown by 2 pixels
  cv::Mat gradient;      ///< GreyGradient of `color` sampled every `stride` pixels
  int stride = 1;        ///< renders are compared at every stride-th pixel of the frame
  PinholeCamera camera;  ///< the frame's camera at the stride (PinholeCamera::Sampled)
  cv::Mat normals;       ///< DepthNormals of the frame's depth at the stride, CV_32FC3
};

/// The frame's verification images for renders at every `stride`-th pixel.
VerificationFrame MakeVerificationFrame(const RgbdFrame& frame, const VerifyOptions& options, int stride);

/// A model rendered at a pose with the frame's camera sampled every `stride` pixels: pixel (u, v) is the frame's
/// (stride u, stride v).
struct RenderedPose {
  cv::Mat color;  ///< CV_8UC3 RGB, the model's colours (before its colour matrix)
  cv::Mat depth;  ///< CV_32FC1 metres, 0 off the model
};

/// What the frame shows of a rendered pose (MeasurePose); ScorePose turns it into a score.
struct PoseEvidence {
  int rendered_pixels = 0;  ///< the model's rendered pixels (at the stride)
  int visible = 0;          ///< ... of them with a scene depth that does not hide them
  /// Frame pixels where the rendered surface lies on the scene's (within depth_tolerance_m), at the stride.
  std::vector<cv::Point> surface;
  double surface_error_m = 0.0;      ///< mean |rendered - scene depth| on `surface`, metres
  double color_agreement = 0.0;      ///< ColorCorrelation of the rendered colours with the scene's on `surface`
  EdgeAgreement edges;               ///< the model's texture edges inside its silhouette, and those the scene shows
  OutlineOnSteps outline;            ///< the seen outline, and how much of it lies on scene depth steps
  OutlineContinuation continuation;  ///< the judged outline, and across how much of it the scene's surface runs on
  /// Visible pixels with a rendered normal, and those the scene explains (explain_distance_m, explain_angle_deg).
  int normal_pixels = 0;
  int explained = 0;
  int behind = 0;              ///< visible pixels where the scene lies more than free_space_margin_m behind the model
  OccludingContour occluding;  ///< the seen outline, and where the scene steps back behind it
};

/// Compares `rendered` with `frame` (made with the same stride); `model_to_scene` maps the rendered colours (a
/// model's colour matrix, or the identity). Pure: no GL, no state.
PoseEvidence MeasurePose(const RenderedPose& rendered, const VerificationFrame& frame,
                         const Eigen::Matrix3f& model_to_scene, const VerifyOptions& options);

/// Fills `detection`'s verification terms (depth, colour and edge agreement, surface error, contour agreement,
/// continuation, visible fraction) and its score from `evidence`: depth agreement x Appearance x FitFactor x
/// ContourFactor x ContinuationFactor; for a `plain` model (one painted in one colour) with
/// options.plain_appearance > 0, that value stands for Appearance.
void ScorePose(const PoseEvidence& evidence, const VerifyOptions& options, bool plain, Detection* detection);

/// Verification's fit factor of a mean surface residual (metres): 1 up to residual_free_m, falling linearly to 0
/// over residual_falloff_m beyond; always 1 when residual_falloff_m is 0.
double FitFactor(double residual_m, const VerifyOptions& options);

/// PatchOfLargerPlane for a rendered pose: its surface pixels (`surface`, frame pixels) against the scene points of
/// a ring of 3 samples (at the stride) around the silhouette of `rendered_depth`.
bool OnLargerPlane(const RgbdFrame& frame, const cv::Mat& rendered_depth, const std::vector<cv::Point>& surface,
                   int stride, const PlanePatchOptions& options);

}  // namespace ecv
