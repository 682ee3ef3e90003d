#include "ecv/matching.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

#include <opencv2/flann.hpp>

#include "core/byte_neighbours.h"
#include "core/error.h"
#include "core/kd_forest.h"
#include "core/point_index.h"

namespace ecv {

// One index over the train descriptors of one type (or of all), with the rows' primitive indices: FLANN
// (OpenCV's) or a KdForest. OpenCV's copy of FLANN is used because its randomised kd-trees draw from seedable
// generators; Debian's libflann shuffles them with std::random_device, so its matches differ from run to run.
struct DescriptorMatcher::Index {
  cv::Mat values;              // owned copy: FLANN keeps pointers into it (released once a KdForest copied it)
  std::vector<int> primitive;  // train primitive of each row
  std::unique_ptr<cv::flann::Index> flann;
  std::unique_ptr<KdForest> forest;
  std::unique_ptr<ByteNeighbours> bytes;

  int rows() const { return forest ? forest->size() : bytes ? bytes->size() : values.rows; }
};

namespace {

// Rows of `descriptors` whose primitive passes `keep`.
template <typename Keep>
void SelectRows(const Descriptors& descriptors, Keep keep, cv::Mat* values, std::vector<int>* primitive) {
  std::vector<int> rows;
  for (size_t row = 0; row < descriptors.primitive.size(); ++row) {
    if (keep(descriptors.primitive[row])) rows.push_back(static_cast<int>(row));
  }
  values->create(static_cast<int>(rows.size()), descriptors.values.cols, CV_32F);
  primitive->clear();
  const size_t row_bytes = static_cast<size_t>(descriptors.values.cols) * sizeof(float);
  for (size_t i = 0; i < rows.size(); ++i) {
    std::memcpy(values->ptr<float>(static_cast<int>(i)), descriptors.values.ptr<float>(rows[i]), row_bytes);
    primitive->push_back(descriptors.primitive[static_cast<size_t>(rows[i])]);
  }
}

}  // namespace

void MatchOptions::Check() const {
  if (k < 1) ThrowInputError("match options", "k", "at least 1 neighbour", std::to_string(k));
  if (trees < 1 || checks < 1 || leaf_size < 1) {
    ThrowInputError("match options", "trees/checks/leaf_size", "positive values");
  }
}

DescriptorMatcher::DescriptorMatcher(const std::vector<Primitive>& train_primitives, const Descriptors& train,
                                     const MatchOptions& options)
    : options_(options) {
  options_.Check();
  const int types = options_.structure_specific ? 2 : 1;
  for (int type = 0; type < types; ++type) {
    auto index = std::make_unique<Index>();
    SelectRows(
        train,
        [&](int i) { return types == 1 || static_cast<int>(train_primitives[static_cast<size_t>(i)].type) == type; },
        &index->values, &index->primitive);
    if (index->values.rows > 0 && options_.index == MatchIndex::kBytes) {
      index->bytes = std::make_unique<ByteNeighbours>(index->values);
      index->values.release();
    } else if (index->values.rows > 0 && options_.index == MatchIndex::kKdForest) {
      KdForestOptions forest;
      forest.trees = options_.trees;
      forest.leaf_size = options_.leaf_size;
      index->forest = std::make_unique<KdForest>(index->values, forest);
      index->values.release();
    } else if (index->values.rows > 0) {
      // The trees draw from std::rand and OpenCV's generator: both seeded, under a lock, so that the same
      // descriptors always give the same trees (and the same matches).
      static std::mutex seed_mutex;
      const std::lock_guard<std::mutex> lock(seed_mutex);
      std::srand(1);
      cv::theRNG().state = 1;
      if (index->values.rows < options_.exact_below) {
        index->flann =
            std::make_unique<cv::flann::Index>(index->values, cv::flann::LinearIndexParams(), cvflann::FLANN_DIST_L2);
      } else {
        index->flann = std::make_unique<cv::flann::Index>(index->values, cv::flann::KDTreeIndexParams(options_.trees),
                                                          cvflann::FLANN_DIST_L2);
      }
    }
    indices_.push_back(std::move(index));
  }
}

DescriptorMatcher::~DescriptorMatcher() = default;

std::vector<DescriptorMatch> DescriptorMatcher::Match(const std::vector<Primitive>& query_primitives,
                                                      const Descriptors& query, int checks) const {
  std::vector<DescriptorMatch> matches;
  for (size_t type = 0; type < indices_.size(); ++type) {
    const Index& index = *indices_[type];
    if (index.rows() == 0) continue;
    cv::Mat values;
    std::vector<int> primitive;
    SelectRows(
        query,
        [&](int i) {
          return indices_.size() == 1 || static_cast<size_t>(query_primitives[static_cast<size_t>(i)].type) == type;
        },
        &values, &primitive);
    if (values.rows == 0) continue;
    const int k = std::min(options_.k, index.rows());
    cv::Mat neighbours, squared;
    const int approximate_checks = checks > 0 ? checks : options_.checks;
    if (index.bytes) {
      index.bytes->Search(values, k, &neighbours, &squared);
    } else if (index.forest) {
      const int compared = index.rows() < options_.exact_below ? index.rows() : approximate_checks;
      index.forest->Search(values, k, compared, &neighbours, &squared);
    } else {
      index.flann->knnSearch(values, neighbours, squared, k, cv::flann::SearchParams(approximate_checks));
    }
    for (int q = 0; q < neighbours.rows; ++q) {
      for (int rank = 0; rank < k; ++rank) {
        const int train = neighbours.at<int>(q, rank);
        if (train < 0) continue;
        matches.push_back({primitive[static_cast<size_t>(q)], index.primitive[static_cast<size_t>(train)],
                           std::sqrt(squared.at<float>(q, rank)), rank});
      }
    }
  }
  return matches;
}

bool MatchOrderLess(const std::vector<Primitive>& query_primitives, bool structure_specific, int a, int b) {
  if (structure_specific) {
    const auto type_a = static_cast<int>(query_primitives[static_cast<size_t>(a)].type);
    const auto type_b = static_cast<int>(query_primitives[static_cast<size_t>(b)].type);
    if (type_a != type_b) return type_a < type_b;
  }
  return a < b;
}

CorrespondenceScore ScoreCorrespondences(const std::vector<Primitive>& query, const std::vector<Primitive>& train,
                                         const std::vector<DescriptorMatch>& matches,
                                         const Eigen::Isometry3d& train_from_query, double threshold_m) {
  CorrespondenceScore score;
  const Eigen::Isometry3f transform = train_from_query.cast<float>();
  const float squared = static_cast<float>(threshold_m * threshold_m);
  for (const DescriptorMatch& match : matches) {
    if (match.rank != 0) continue;
    ++score.hypotheses;
    const Eigen::Vector3f moved = transform * query[static_cast<size_t>(match.query)].position;
    score.true_matches += (moved - train[static_cast<size_t>(match.train)].position).squaredNorm() < squared ? 1 : 0;
  }
  return score;
}

double TruePartnerFraction(const std::vector<Primitive>& query, const std::vector<int>& query_indices,
                           const std::vector<Primitive>& train, const Eigen::Isometry3d& train_from_query,
                           double threshold_m) {
  if (query_indices.empty() || train.empty()) return 0.0;
  std::vector<Eigen::Vector3f> positions;
  for (const Primitive& p : train) positions.push_back(p.position);
  const PointIndex index(positions);
  const Eigen::Isometry3f transform = train_from_query.cast<float>();
  const float squared = static_cast<float>(threshold_m * threshold_m);
  int with_partner = 0;
  for (const int i : query_indices) {
    with_partner += index.Nearest(transform * query[static_cast<size_t>(i)].position).second < squared ? 1 : 0;
  }
  return static_cast<double>(with_partner) / static_cast<double>(query_indices.size());
}

}  // namespace ecv
