#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "ecv/primitives.h"
#include "registration/ransac.h"

namespace ecv {

/// When two object-to-scene correspondences can both be true (a rigid motion keeps distances and angles).
struct ConsistencyOptions {
  /// Their object and their scene primitives lie equally far apart, within this (each true correspondence
  /// is within RANSAC's 1 cm, so a true pair's distances differ by up to 2 cm), metres ...
  double tolerance_m = 0.015;
  /// ... and the |cosines| between their orientations, and between each orientation and the line joining
  /// them, differ by at most this (unitless, as |cosines| lie in [0, 1]); tighter rejects true pairs as well.
  double angle_tolerance = 0.4;
  double min_distance_m = 0.02;  ///< pairs closer than this say little and are not counted, metres
  double max_distance_m = 1.0;   ///< nor pairs further apart than this (the recognizer: the model diameter)

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// The size of a large set of pairwise-consistent correspondences among `correspondences` (object
/// primitives in `object`, scene primitives in `scene`), grown greedily from each one in turn, its
/// consistent partners taken by how many of the others they agree with. True correspondences all agree with
/// one another; false ones rarely do, so the size tracks the number of true ones even when they are few.
/// Cost: quadratic in the number of correspondences.
int ConsistentSetSize(const std::vector<Primitive>& object, const std::vector<Primitive>& scene,
                      const std::vector<Correspondence>& correspondences, const ConsistencyOptions& options = {});

/// When a pose only explains a patch of a larger plane (see PatchOfLargerPlane).
struct PlanePatchOptions {
  double distance_m = 0.01;  ///< a point lies on the surface points' plane (least squares) within this, metres
  double min_share = 0.8;    ///< the surface is planar, and the ring on its plane, when this share of each lies on it
  int min_points = 20;       ///< fewer surface or ring points decide nothing (false)

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// Whether `surface` (scene points where a posed model lies on the scene) lies on one plane and most of `ring`
/// (scene points just outside the model's silhouette) lies on that plane too. The depth then shows nothing of
/// the object: e.g. a can sunk into a table with its lid flush with the table top, which fits the depth
/// perfectly. A box face seen head-on is not such a patch: the scene around it lies elsewhere.
bool PatchOfLargerPlane(const std::vector<Eigen::Vector3f>& surface, const std::vector<Eigen::Vector3f>& ring,
                        const PlanePatchOptions& options = {});

/// The pixels of a depth image (CV_32FC1, metres, 0 = no measurement) at a depth step: a right or lower neighbour
/// more than `step_m` nearer or further, or measured where this one is not (or the reverse); both pixels of a step
/// are marked, then grown by `grow_px` pixels. CV_8UC1, 255 on them. Throws InputError on another image type or a
/// step or growth out of range.
cv::Mat DepthSteps(const cv::Mat& depth, double step_m, int grow_px);

/// Outline pixels of a rendered pose that the scene shows, and how many of them lie on a depth step.
struct OutlineOnSteps {
  int seen = 0;
  int on_step = 0;
  double Share() const { return seen > 0 ? static_cast<double>(on_step) / seen : 0.0; }
};

/// How much of an object's outline the scene shows as a depth step: of the pixels on the outline of
/// `rendered_depth` (the object rendered at a pose, CV_32FC1 metres, 0 off the object; pixel (u, v) is scene pixel
/// (stride u, stride v)) those the scene does not hide (no scene surface more than `hidden_margin_m` in front), and
/// how many lie on `scene_steps` (DepthSteps of the scene). Where the image cuts the object off is not outline. An
/// object lifts off what is behind it, so a right pose's outline runs along depth steps; a pose that lies flat on a
/// larger surface (a small box on a big box's face) has no step along its outline. Throws InputError when the
/// images do not fit.
OutlineOnSteps OutlineOnDepthSteps(const cv::Mat& rendered_depth, int stride, const cv::Mat& scene_depth,
                                   const cv::Mat& scene_steps, double hidden_margin_m);

/// When the scene's surface runs on across a pose's outline (SurfaceContinuation): the model would then explain only
/// part of a larger surface, as a small box laid flush on a bigger box's face does.
struct ContinuationOptions {
  /// A plane is fitted to the scene's surface samples within this of an outline pixel; frame pixels.
  int window_px = 12;
  /// The scene samples tested lie this far from the silhouette: not closer, where a pose a pixel or two off still
  /// has its own object and a crease has not yet turned far from the plane, nor further; frame pixels.
  int min_gap_px = 3;
  int max_gap_px = 12;
  /// A scene sample beyond the outline continues the surface when its depth lies within this of the plane; metres.
  double tolerance_m = 0.004;
  /// Where the surface inside is not one plane within this (rms of depth), the outline pixel decides nothing
  /// (a crease or a curve under the window); metres.
  double max_fit_rms_m = 0.002;
  int min_samples = 6;  ///< on each side of the outline pixel; fewer decide nothing

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// Seen outline pixels of a rendered pose that could be judged, and across how many of them the scene's surface
/// continues.
struct OutlineContinuation {
  int tested = 0;
  int continued = 0;
  double Share() const { return tested > 0 ? static_cast<double>(continued) / tested : 0.0; }
};

/// Whether the scene's surface ends where a posed model's outline says the object ends. For each outline pixel of
/// `rendered_depth` (as in OutlineOnDepthSteps) that the scene shows on the model's surface (within
/// `surface_tolerance_m`), a plane is fitted to the scene's surface samples around it, and the scene samples just
/// beyond the outline are tested against it: most of them on the plane means the surface continues there. A right
/// pose's outline runs along depth steps and creases (an object standing on a table meets it at an angle); a model
/// laid over part of a larger surface has the rest of that surface all round it. Throws InputError when the images
/// do not fit.
OutlineContinuation SurfaceContinuation(const cv::Mat& rendered_depth, int stride, const cv::Mat& scene_depth,
                                        double surface_tolerance_m, const ContinuationOptions& options = {});

/// Unit surface normals of a depth image (CV_32FC1 metres, 0 = no depth) that `camera` sees: from the points `reach`
/// pixels to either side and above and below, turned to face the camera. CV_32FC3 (camera frame); (0, 0, 0) where a
/// neighbour has no depth or lies more than `max_step_m` nearer or further than the pixel (a depth step, not a
/// surface). Throws InputError on another image type, a reach below 1 or a camera of another size.
cv::Mat DepthNormals(const cv::Mat& depth, const PinholeCamera& camera, int reach, double max_step_m);

/// Outline pixels of a rendered pose that the scene shows, and at how many of them its surface ends: it steps back
/// behind the object, or else it turns (a crease, where an object stands on a table).
struct OccludingContour {
  int seen = 0;
  int stepping_back = 0;
  int creased = 0;
  double SteppingBack() const { return seen > 0 ? static_cast<double>(stepping_back) / seen : 0.0; }
  double Creased() const { return seen > 0 ? static_cast<double>(creased) / seen : 0.0; }
};

/// Where OccludingContourSteps takes the scene's surface to end at an outline pixel.
struct OccludingContourOptions {
  double step_m = 0.01;  ///< it steps back by more than this (or has no depth), metres, ...
  int gap = 3;           ///< ... within this many samples beyond the outline; ...
  /// ... or its normals this many samples inside and beyond differ by more than this, degrees.
  double crease_angle_deg = 30.0;

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// Whether a pose's outline is where the scene's surface ends, with its orientation. For each outline pixel of
/// `rendered_depth` (as in OutlineOnDepthSteps) the scene does not hide and shows on the model's surface (within
/// `surface_tolerance_m`): the scene steps back behind the object there, or else it creases (`scene_normals`,
/// DepthNormals at the render's size; empty: no creases). A right pose's outline is where the object hides what lies
/// behind it or meets what it stands on; a pose laid flat on a larger surface, or shifted over a table, has the same
/// surface on both sides of its outline, and an outline along another object's edge has that edge the wrong way
/// round. Throws InputError when the images do not fit.
OccludingContour OccludingContourSteps(const cv::Mat& rendered_depth, int stride, const cv::Mat& scene_depth,
                                       const cv::Mat& scene_normals, double surface_tolerance_m,
                                       const OccludingContourOptions& options = {});

/// Verification's contour factor: 1 when fewer than `min_seen` outline pixels are seen (an object cut off by the
/// image all round, or hidden but for a patch: the outline cannot tell), else 1 from a share of `free` on the
/// steps, falling linearly to 0 over `falloff` below; `falloff` 0: always 1.
double ContourFactor(const OutlineOnSteps& outline, double free, double falloff, int min_seen);

/// Verification's continuation factor: 1 when fewer than `min_tested` outline pixels could be judged, else 1 up to a
/// continued share of `free`, falling linearly to 0 over `falloff` above; `falloff` 0: always 1.
double ContinuationFactor(const OutlineContinuation& continuation, double free, double falloff, int min_tested);

/// Image gradients of a grey image (CV_8UC1): 3x3 Sobel, CV_32FC2 (d/du, d/dv). Throws InputError on another type.
cv::Mat GreyGradient(const cv::Mat& grey);

/// What counts as a texture edge and as the same edge in CompareEdges, in 3x3 Sobel units (a step of h grey
/// levels gives up to 4h).
struct EdgeOptions {
  double strong = 60.0;  ///< the model shows an edge: gradient magnitude at least this
  double weak = 20.0;    ///< the scene shows it: gradient magnitude at least this (lower: its contrast may be less) ...
  double min_cos = 0.9;  ///< ... at the same orientation: |cos| of the angle between the gradients at least this

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// A posed model's texture edges and how many of them the scene shows.
struct EdgeAgreement {
  int predicted = 0;  ///< strong gradients of the rendered model
  int shown = 0;      ///< ... where the scene has a weak one at the same orientation
  double Share() const { return predicted > 0 ? static_cast<double>(shown) / predicted : 0.0; }
};

/// The model's texture edges on `pixels` (where its rendered surface lies on the scene's, away from its outline) and
/// those the scene shows: `model_gradient` and `scene_gradient` (GreyGradient, same size) at the same pixel. A pose
/// turned 180 degrees puts printed text where the scene shows a plain side, or the reverse, and most of its edges
/// find no partner, while the colours on a small patch may still correlate. Throws InputError when the images do
/// not fit.
EdgeAgreement CompareEdges(const cv::Mat& model_gradient, const cv::Mat& scene_gradient,
                           const std::vector<cv::Point>& pixels, const EdgeOptions& options = {});

/// Verification's appearance term: `color` (ColorCorrelation) to the power 1 - `weight` times edges.Share() to the
/// power `weight`; `color` alone when fewer than `min_edges` edges are predicted (a plain surface: too few to
/// tell) or `weight` is 0.
double Appearance(double color, const EdgeAgreement& edges, double weight, int min_edges);

/// Normalised cross-correlation of (model, scene) colour pairs in [0, 1]; 0 for fewer than 10 pairs. High when
/// the model's texture lies where the scene shows it, whatever the brightness and white balance of the light:
/// the smaller of the correlation per channel (averaged; each channel's own gain and offset) and the
/// correlation over all channels at once (one gain and offset, so a pattern in another hue scores low).
double ColorCorrelation(const std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>>& colors);

}  // namespace ecv
