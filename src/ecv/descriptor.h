#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "ecv/primitives.h"

namespace ecv {

/// Length of an ECV context descriptor: six 16-bin histograms.
inline constexpr int kDescriptorBins = 16;
inline constexpr int kDescriptorSize = 6 * kDescriptorBins;

/// The ECV context descriptor (paper Sect. II-B; DESIGN.md "Context descriptor"). Defaults chosen by the
/// correspondence score on YCB-Video videos 0000 and 0001 (bench/RESULTS.md, ablations); the paper's own
/// descriptor is soft_binning = false, hellinger = false.
struct DescriptorOptions {
  double radius_m = 0.025;  ///< context radius around each primitive, metres
  /// Context = at most this many of the primitives within the radius (the source included), spread evenly
  /// over their distance ranks so that the context still spans the radius; 0 = all, as in the paper.
  /// Pairs grow with its square: the cap bounds the cost in dense views.
  int max_neighbours = 0;
  bool unsigned_segments = false;  ///< a segment's direction has no sign: use |cosines| that involve one
  bool soft_binning = true;        ///< share each value between its two nearest bins (linear)
  bool use_color = true;           ///< false: shape only (the three colour histograms stay zero)
  /// Grey-world balance before the colour differences: each channel scaled so that the mean over the
  /// primitives is 0.5 (beyond the paper: cancels white balance and exposure between views).
  bool balance_colors = false;
  bool hellinger = true;  ///< store square roots of the histogram values (L2 then = Hellinger)

  void Check() const;
};

/// Descriptors of the primitives that have a context (at least one other primitive within the radius).
struct Descriptors {
  cv::Mat values;              ///< one row of kDescriptorSize CV_32F per described primitive
  std::vector<int> primitive;  ///< index into the input primitives of each row
};

/// For each primitive s, every pair {a, b} of the primitives within `radius_m` of s (s included), ordered
/// so that a is the closer to s, d = (p_b - p_a) / |p_b - p_a|, adds R_G1 = o_a.o_b, R_G2 = o_a.d,
/// R_G3 = o_b.d and R_Ak = c_b[k] - c_a[k] to six 16-bin histograms over [-1, 1] (over [0, 1] for
/// unsigned cosines), each normalised to sum 1. Neighbours of both types form the context.
Descriptors ComputeDescriptors(const std::vector<Primitive>& primitives, const DescriptorOptions& options = {});

}  // namespace ecv
