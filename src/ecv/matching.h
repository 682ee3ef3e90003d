#pragma once

#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "ecv/descriptor.h"

namespace ecv {

/// The nearest-neighbour index a DescriptorMatcher searches.
enum class MatchIndex {
  kFlann,     ///< OpenCV's FLANN: randomised kd-trees with a row per leaf (the paper's matcher)
  kKdForest,  ///< ecvpose's KdForest: the same trees with leaves of leaf_size rows, much less time per check
  /// ByteNeighbours: every train descriptor compared, values quantised to 7 bits (exact up to that; checks,
  /// trees and exact_below unused)
  kBytes,
};

/// Nearest-neighbour matching of context descriptors.
struct MatchOptions {
  int k = 1;                       ///< neighbours returned per query descriptor
  bool structure_specific = true;  ///< segments only against segments, texlets only against texlets
  int exact_below = 1000;          ///< a train set smaller than this is searched exactly (linear scan)
  MatchIndex index = MatchIndex::kFlann;
  int trees = 4;      ///< randomised kd-trees of the approximate index
  int checks = 128;   ///< train descriptors compared per query by the approximate search
  int leaf_size = 8;  ///< most train descriptors in a leaf (kKdForest only)

  void Check() const;
};

/// A query primitive matched to a train primitive (indices into the primitive vectors).
struct DescriptorMatch {
  int query = -1;
  int train = -1;
  float distance = 0.0F;  ///< Euclidean distance between the descriptors
  int rank = 0;           ///< 0 for the nearest, 1 for the second, ...
};

/// An index over the descriptors of one primitive set (e.g. the scene), queried with another's (a model
/// view's). Built once, queried many times.
class DescriptorMatcher {
 public:
  DescriptorMatcher(const std::vector<Primitive>& train_primitives, const Descriptors& train,
                    const MatchOptions& options = {});
  ~DescriptorMatcher();
  DescriptorMatcher(const DescriptorMatcher&) = delete;
  DescriptorMatcher& operator=(const DescriptorMatcher&) = delete;

  /// The k nearest train descriptors of each query descriptor (of the same type when structure-specific), in
  /// MatchOrderLess order: a query set matched in parts gives the same matches once sorted by it.
  /// `checks` > 0 replaces MatchOptions::checks for these queries.
  std::vector<DescriptorMatch> Match(const std::vector<Primitive>& query_primitives, const Descriptors& query,
                                     int checks = 0) const;

 private:
  struct Index;
  MatchOptions options_;
  std::vector<std::unique_ptr<Index>> indices_;  // one per primitive type, or one for all
};

/// True when DescriptorMatcher::Match lists the matches of query primitive `a` before those of `b`: segments
/// before texlets when structure-specific, then by primitive index (as ComputeDescriptors orders its rows).
bool MatchOrderLess(const std::vector<Primitive>& query_primitives, bool structure_specific, int a, int b);

/// The paper's correspondence score (Sect. IV-A) of some matches.
struct CorrespondenceScore {
  int hypotheses = 0;    ///< C_hyp: matches scored
  int true_matches = 0;  ///< C_true: matches whose points lie within the threshold after alignment
  double Score() const { return hypotheses > 0 ? static_cast<double>(true_matches) / hypotheses : 0.0; }
};

/// Scores the rank-0 matches: true when |train_from_query * p_query - p_train| < `threshold_m`.
CorrespondenceScore ScoreCorrespondences(const std::vector<Primitive>& query, const std::vector<Primitive>& train,
                                         const std::vector<DescriptorMatch>& matches,
                                         const Eigen::Isometry3d& train_from_query, double threshold_m = 0.01);

/// Ceiling of the score: the fraction of `query_indices` whose primitive has any train primitive within
/// `threshold_m` after alignment.
double TruePartnerFraction(const std::vector<Primitive>& query, const std::vector<int>& query_indices,
                           const std::vector<Primitive>& train, const Eigen::Isometry3d& train_from_query,
                           double threshold_m = 0.01);

}  // namespace ecv
