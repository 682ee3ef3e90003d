#include "ecv/descriptor.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

#include "core/error.h"

namespace ecv {
namespace {

// Adds `value` to a 16-bin histogram over [low, 1].
void AddToHistogram(float value, float low, bool soft, float* histogram) {
  const float position = (value - low) / (1.0F - low) * kDescriptorBins - 0.5F;  // bin centres at integers
  if (!soft) {
    const int bin = std::clamp(static_cast<int>(position + 0.5F), 0, kDescriptorBins - 1);  // position >= -0.5
    histogram[bin] += 1.0F;
    return;
  }
  const float clamped = std::clamp(position, 0.0F, static_cast<float>(kDescriptorBins - 1));
  const int lower = std::min(static_cast<int>(clamped), kDescriptorBins - 2);
  const float upper_share = clamped - static_cast<float>(lower);
  histogram[lower] += 1.0F - upper_share;
  histogram[lower + 1] += upper_share;
}

// Colours scaled per channel so that their mean is 0.5 (grey world), clamped to [0, 1].
std::vector<Primitive> BalanceColors(std::vector<Primitive> primitives) {
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  for (const Primitive& p : primitives) mean += p.color;
  mean /= static_cast<float>(primitives.size());
  const Eigen::Vector3f gain = (0.5F * mean.cwiseMax(1e-3F).cwiseInverse()).cwiseMin(8.0F);
  for (Primitive& p : primitives) p.color = p.color.cwiseProduct(gain).cwiseMin(1.0F);
  return primitives;
}

// Histograms of the pairs of `neighbours` (indices into primitives, sorted by distance to the source).
void DescribeContext(const std::vector<Primitive>& primitives, const std::vector<int>& neighbours,
                     const DescriptorOptions& options, float* descriptor) {
  std::fill(descriptor, descriptor + kDescriptorSize, 0.0F);
  const float cosine_low = options.unsigned_segments ? 0.0F : -1.0F;
  for (size_t i = 0; i < neighbours.size(); ++i) {
    const Primitive& a = primitives[static_cast<size_t>(neighbours[i])];
    for (size_t j = i + 1; j < neighbours.size(); ++j) {
      const Primitive& b = primitives[static_cast<size_t>(neighbours[j])];
      const Eigen::Vector3f offset = b.position - a.position;
      const float length = offset.norm();
      if (length <= 0.0F) continue;
      const Eigen::Vector3f d = offset / length;
      float cosines[3] = {a.orientation.dot(b.orientation), a.orientation.dot(d), b.orientation.dot(d)};
      if (options.unsigned_segments) {
        for (float& cosine : cosines) cosine = std::abs(cosine);
      }
      for (int k = 0; k < 3; ++k)
        AddToHistogram(cosines[k], cosine_low, options.soft_binning, descriptor + k * kDescriptorBins);
      if (!options.use_color) continue;
      for (int k = 0; k < 3; ++k) {
        AddToHistogram(b.color[k] - a.color[k], -1.0F, options.soft_binning, descriptor + (3 + k) * kDescriptorBins);
      }
    }
  }
  for (int h = 0; h < 6; ++h) {
    float* histogram = descriptor + h * kDescriptorBins;
    const float sum = std::accumulate(histogram, histogram + kDescriptorBins, 0.0F);
    if (sum <= 0.0F) continue;
    for (int bin = 0; bin < kDescriptorBins; ++bin) {
      histogram[bin] = options.hellinger ? std::sqrt(histogram[bin] / sum) : histogram[bin] / sum;
    }
  }
}

}  // namespace

void DescriptorOptions::Check() const {
  if (max_neighbours < 0 || max_neighbours == 1) {
    ThrowInputError("descriptor options", "max_neighbours", "0 (all) or at least 2", std::to_string(max_neighbours));
  }
  if (!(radius_m > 0.0) || !std::isfinite(radius_m)) {
    ThrowInputError("descriptor options", "radius_m", "a radius > 0 m", std::to_string(radius_m));
  }
}

Descriptors ComputeDescriptors(const std::vector<Primitive>& input, const DescriptorOptions& options) {
  options.Check();
  const std::vector<Primitive> balanced =
      options.balance_colors && !input.empty() ? BalanceColors(input) : std::vector<Primitive>();
  const std::vector<Primitive>& primitives = options.balance_colors ? balanced : input;
  Descriptors descriptors;
  descriptors.values.create(0, kDescriptorSize, CV_32F);
  if (primitives.size() < 2) return descriptors;

  // Exact kd-tree over the positions (FLANN, single tree).
  std::vector<float> positions(3 * primitives.size());
  for (size_t i = 0; i < primitives.size(); ++i) std::copy_n(primitives[i].position.data(), 3, &positions[3 * i]);
  const flann::Matrix<float> points(positions.data(), primitives.size(), 3);
  flann::KDTreeSingleIndex<flann::L2_Simple<float>> index(points, flann::KDTreeSingleIndexParams(12));
  index.buildIndex();

  flann::SearchParams search;
  search.sorted = true;  // neighbours by distance to the source: the pair order of the paper
  const float squared_radius = static_cast<float>(options.radius_m * options.radius_m);
  std::vector<std::vector<size_t>> neighbour_lists;
  std::vector<std::vector<float>> distances;
  index.radiusSearch(points, neighbour_lists, distances, squared_radius, search);

  cv::Mat values(static_cast<int>(primitives.size()), kDescriptorSize, CV_32F);
  std::vector<int> neighbours;
  for (size_t i = 0; i < primitives.size(); ++i) {
    if (neighbour_lists[i].size() < 2) continue;            // isolated: no context
    const std::vector<size_t>& found = neighbour_lists[i];  // by distance, the source first
    const size_t cap = options.max_neighbours > 0 ? static_cast<size_t>(options.max_neighbours) : found.size();
    neighbours.clear();
    if (found.size() <= cap) {
      neighbours.assign(found.begin(), found.end());
    } else {  // evenly spread over the distance ranks, so that the context still spans the whole radius
      for (size_t j = 0; j < cap; ++j)
        neighbours.push_back(static_cast<int>(found[j * (found.size() - 1) / (cap - 1)]));
    }
    float* row = values.ptr<float>(static_cast<int>(descriptors.primitive.size()));
    DescribeContext(primitives, neighbours, options, row);
    descriptors.primitive.push_back(static_cast<int>(i));
  }
  descriptors.values = values.rowRange(0, static_cast<int>(descriptors.primitive.size())).clone();
  return descriptors;
}

}  // namespace ecv
