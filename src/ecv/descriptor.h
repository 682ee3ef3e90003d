#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "ecv/primitives.h"
#include "ecv/surface_shape.h"

namespace ecv {

/// Length of an ECV context descriptor: six 16-bin histograms.
inline constexpr int kDescriptorBins = 16;
inline constexpr int kDescriptorSize = 6 * kDescriptorBins;

/// Which pairs of a primitive's context are histogrammed.
enum class DescriptorPairs : int {
  kAll = 0,     ///< every pair {a, b} of the context (the paper; O(k^2) per primitive)
  kSource = 1,  ///< only the source with each neighbour, {s, n} (O(k), as FPFH's SPFH against PFH)
};

/// What the three appearance histograms hold, for a pair {a, b} (a closer to the source). Stored in
/// libraries as its integer value.
enum class DescriptorAppearance : int {
  kRgbDifference = 0,  ///< c_b[k] - c_a[k], k = R, G, B (the paper)
  /// ln(c_b[k] / c_a[k]) / ln 4, k = R, G, B: cancels a gain per channel (white balance, exposure).
  kRgbLogRatio = 1,
  /// The paper's future work: ln(m_b / m_a) / ln 8 of the monogenic magnitudes, theta_b - theta_a of the
  /// image orientations (wrapped to [-pi/2, pi/2), over pi/2), and ln(l_b / l_a) / ln 4 of the lightness
  /// l = (R + G + B) / 3. Ratios cancel contrast and exposure.
  kMonogenic = 2,
};

/// Where the three shape histograms come from. Stored in libraries as its integer value.
enum class DescriptorShape : int {
  /// R_G1..3: cosines of the primitives' orientations and offsets within the context (the paper).
  kPrimitives = 0,
  /// The surface context, a hybrid beyond the paper: the depth image's surface (SurfaceSamples) within the radius,
  /// in the source's local reference frame (the axes of the surface's covariance, z along its normal, x towards most
  /// of the surface, as SHOT's), split into 2 radial shells x 4 azimuthal sectors; each region holds a 6-bin
  /// histogram of the cosine of the samples' normals with z. It needs no primitive's orientation, so it does not
  /// change with the camera's roll, and the dense surface gives a steadier frame than the sparse primitives.
  kSurface = 1,
};

/// The ECV context descriptor (paper Sect. II-B). Defaults chosen by the correspondence score on YCB-Video videos
/// 0000 and 0001 (discriminative_bench's ablations, bench/EXPERIMENTS.md, 2026-11-21); the paper's own descriptor is
/// soft_binning = false, hellinger = false with the pairs, appearance and weighting below at their defaults and
/// max_neighbours 0.
///
/// The field defaults below are the paper's context (all pairs of a 2.5 cm ball, one shell) with this
/// project's soft bins and Hellinger distance; model libraries are built with SourceShells() instead.
struct DescriptorOptions {
  double radius_m = 0.025;  ///< context radius around each primitive, metres
  /// Context = at most this many of the primitives within the radius (the source included), spread evenly
  /// over their distance ranks so that the context still spans the radius; 0 = all, as in the paper.
  /// Pairs grow with its square: the cap bounds the cost in dense views.
  int max_neighbours = 0;
  /// A segment's direction has no sign: use |cosines| that involve one. A segment's sign follows the image axes
  /// (Primitive::orientation), so signed directions change with the camera's roll about its optical axis and
  /// unsigned ones do not; signed ones find more objects of a camera held level, unsigned ones suit a camera that
  /// is not (bench/EXPERIMENTS.md, 2026-11-26, "unsigned segment directions").
  bool unsigned_segments = false;
  bool soft_binning = true;  ///< share each value between its two nearest bins (linear)
  bool use_color = true;     ///< false: shape only (the three colour histograms stay zero)
  /// Grey-world balance before the colour differences: each channel scaled so that the mean over the
  /// primitives is 0.5 (beyond the paper: cancels white balance and exposure between views).
  bool balance_colors = false;
  bool hellinger = true;  ///< store square roots of the histogram values (L2 then = Hellinger)
  /// Which pairs (see the enum). Source pairs cost a small fraction of all pairs' time; with radial shells they
  /// also describe better.
  DescriptorPairs pairs = DescriptorPairs::kAll;
  /// Appearance histograms: RGB differences; the alternatives lost on held-out recognition in every form tried.
  DescriptorAppearance appearance = DescriptorAppearance::kRgbDifference;
  /// Weight of a pair = 1 - closeness_weight * (distance of its farther member from the source) / radius_m,
  /// in [0, 1]: 0 = every pair counts the same (the paper); 1 = pairs at the rim count nothing (no clear effect).
  double closeness_weight = 0.0;
  /// 1: each histogram has 16 bins over its value (the paper). 2 or 4: radial shells of 16 / shells bins
  /// each, by the distance of the pair's farther member from the source (shells of equal area: split at
  /// radius_m / sqrt 2 for two), so that the histograms also say where the pairs lie (as SHOT's grid does): the
  /// largest gain of the ablations.
  int shells = 1;
  /// The shape histograms (see the enum). kSurface needs the views' SurfaceSamples in ComputeDescriptors.
  DescriptorShape shape = DescriptorShape::kPrimitives;
  /// kSurface: squared length of the shape half against the three colour histograms' (3 with Hellinger).
  double surface_weight = 2.0;

  /// The context model libraries are built with (FeatureSettings): pairs of the source with each neighbour
  /// (kSource) in 4 radial shells over 4.5 cm. It scores about twice the field defaults' correspondence score at
  /// 1/27 of their time, and finds more objects end to end (bench/RESULTS.md, "Discriminative power of
  /// descriptors"; bench/EXPERIMENTS.md, 2026-11-23, "the paper's all-pairs context").
  static DescriptorOptions SourceShells();
  /// SourceShells() with the surface context for its shape histograms (DescriptorShape::kSurface).
  static DescriptorOptions SurfaceShells();

  void Check() const;
};

/// Descriptors of the primitives that have a context (at least one other primitive within the radius).
struct Descriptors {
  cv::Mat values;              ///< one row of kDescriptorSize CV_32F per described primitive
  std::vector<int> primitive;  ///< index into the input primitives of each row
};

/// For each primitive s, every pair {a, b} of the primitives within `radius_m` of s (s included; with
/// DescriptorPairs::kSource only the pairs {s, n}), ordered so that a is the closer to s,
/// d = (p_b - p_a) / |p_b - p_a|, adds R_G1 = o_a.o_b, R_G2 = o_a.d, R_G3 = o_b.d and three appearance
/// values (R_Ak = c_b[k] - c_a[k] in the paper; see DescriptorAppearance) to six 16-bin histograms over
/// [-1, 1] (over [0, 1] for unsigned cosines), each normalised to sum 1. Neighbours of both types form
/// the context.
/// `threads` worker threads share the primitives out; the result does not depend on their number. With
/// `source_step` n > 1 only every n-th primitive (0, n, 2n, ...) is a source and gets a descriptor, the same
/// one it gets with n = 1; every primitive still belongs to the contexts. With DescriptorShape::kSurface the
/// first three histograms are the surface context over `surface` (in the primitives' frame; InputError when
/// null).
/// The support a frame's descriptors need under `options`: its surface where `mask` (CV_8UC1, optional) is set;
/// empty unless the shape is DescriptorShape::kSurface.
SurfaceSamples DescriptorSurface(const RgbdFrame& frame, const DescriptorOptions& options, const cv::Mat& mask = {});

Descriptors ComputeDescriptors(const std::vector<Primitive>& primitives, const DescriptorOptions& options = {},
                               int threads = 1, int source_step = 1, const SurfaceSamples* surface = nullptr);

}  // namespace ecv
