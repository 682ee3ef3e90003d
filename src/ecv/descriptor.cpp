#include "ecv/descriptor.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <string>
#include <thread>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

#include "core/error.h"

namespace ecv {
namespace {

// Adds `weight` at `value` to a histogram of `bins` bins over [low, 1].
void AddToHistogram(float value, float low, bool soft, float weight, int bins, float* histogram) {
  const float position = (value - low) / (1.0F - low) * static_cast<float>(bins) - 0.5F;  // bin centres at integers
  if (!soft) {
    const int bin = std::clamp(static_cast<int>(std::max(position, -0.5F) + 0.5F), 0, bins - 1);
    histogram[bin] += weight;
    return;
  }
  const float clamped = std::clamp(position, 0.0F, static_cast<float>(bins - 1));
  const int lower = std::min(static_cast<int>(clamped), bins - 2);
  const float upper_share = clamped - static_cast<float>(lower);
  histogram[lower] += weight * (1.0F - upper_share);
  histogram[lower + 1] += weight * upper_share;
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

constexpr float kLogFloor = 0.02F;                // added before a logarithm: dark colours, weak magnitudes
constexpr float kColorLogRange = 1.3862944F;      // ln 4: colour log ratios over [-ln 4, ln 4]
constexpr float kMagnitudeLogRange = 2.0794415F;  // ln 8: magnitude log ratios over [-ln 8, ln 8]
constexpr float kPi = 3.14159265F;

// The appearance histograms' values of a pair are differences of per-primitive values: value k of the
// pair {a, b} = clamp(wrap_k(v_b[k] - v_a[k]) * scale[k]), wrapped into [-period/2, period/2) when the
// value is an angle (period > 0).
struct AppearanceValues {
  std::vector<Eigen::Vector3f> values;  // one per primitive
  Eigen::Vector3f scale = Eigen::Vector3f::Ones();
  Eigen::Vector3f period = Eigen::Vector3f::Zero();
};

AppearanceValues ComputeAppearance(const std::vector<Primitive>& primitives, DescriptorAppearance kind) {
  AppearanceValues appearance;
  appearance.values.reserve(primitives.size());
  auto log = [](float value) { return std::log(std::max(value, 0.0F) + kLogFloor); };
  for (const Primitive& p : primitives) {
    switch (kind) {
      case DescriptorAppearance::kRgbDifference: appearance.values.push_back(p.color); break;
      case DescriptorAppearance::kRgbLogRatio:
        appearance.values.emplace_back(log(p.color[0]), log(p.color[1]), log(p.color[2]));
        break;
      case DescriptorAppearance::kMonogenic:
        appearance.values.emplace_back(log(p.magnitude), p.image_orientation, log(p.color.mean()));
        break;
    }
  }
  if (kind == DescriptorAppearance::kRgbLogRatio) appearance.scale.setConstant(1.0F / kColorLogRange);
  if (kind == DescriptorAppearance::kMonogenic) {
    appearance.scale = Eigen::Vector3f(1.0F / kMagnitudeLogRange, 2.0F / kPi, 1.0F / kColorLogRange);
    appearance.period = Eigen::Vector3f(0.0F, kPi, 0.0F);  // orientations are modulo pi
  }
  return appearance;
}

// The context of one source: its primitives, appearance values and histogramming options.
struct Context {
  const std::vector<Primitive>& primitives;
  const AppearanceValues& appearance;
  const DescriptorOptions& options;
};

// Adds the pair {a, b} (a the closer to the source) with `weight` to the six histograms, in their radial
// `shell` (0 .. shells - 1) when they are split into radial shells.
void AddPair(const Context& context, int a_index, int b_index, float weight, int shell, float* descriptor) {
  const Primitive& a = context.primitives[static_cast<size_t>(a_index)];
  const Primitive& b = context.primitives[static_cast<size_t>(b_index)];
  const Eigen::Vector3f offset = b.position - a.position;
  const float length = offset.norm();
  if (length <= 0.0F || weight <= 0.0F) return;
  const DescriptorOptions& options = context.options;
  const Eigen::Vector3f d = offset / length;
  float cosines[3] = {a.orientation.dot(b.orientation), a.orientation.dot(d), b.orientation.dot(d)};
  if (options.unsigned_segments) {
    for (float& cosine : cosines) cosine = std::abs(cosine);
  }
  const float cosine_low = options.unsigned_segments ? 0.0F : -1.0F;
  const int bins = kDescriptorBins / options.shells;
  descriptor += shell * bins;
  for (int k = 0; k < 3; ++k)
    AddToHistogram(cosines[k], cosine_low, options.soft_binning, weight, bins, descriptor + k * kDescriptorBins);
  if (!options.use_color) return;
  const AppearanceValues& values = context.appearance;
  const Eigen::Vector3f difference =
      values.values[static_cast<size_t>(b_index)] - values.values[static_cast<size_t>(a_index)];
  for (int k = 0; k < 3; ++k) {
    float value = difference[k];
    if (values.period[k] > 0.0F) value -= values.period[k] * std::floor(value / values.period[k] + 0.5F);
    AddToHistogram(value * values.scale[k], -1.0F, options.soft_binning, weight, bins,
                   descriptor + (3 + k) * kDescriptorBins);
  }
}

// Histograms of the pairs of `neighbours` (indices into primitives, sorted by distance to the source,
// `distances` from it in metres), all pairs or those with the source, then normalised.
void DescribeContext(const Context& context, int source, const std::vector<int>& neighbours,
                     const std::vector<float>& distances, float* descriptor) {
  std::fill(descriptor, descriptor + kDescriptorSize, 0.0F);
  const DescriptorOptions& options = context.options;
  const float falloff = static_cast<float>(options.closeness_weight / options.radius_m);
  const float inverse_squared_radius = static_cast<float>(1.0 / (options.radius_m * options.radius_m));
  auto shell = [&](size_t j) {  // shells of equal area: by the squared distance from the source
    const float share = distances[j] * distances[j] * inverse_squared_radius;
    return std::min(static_cast<int>(share * static_cast<float>(options.shells)), options.shells - 1);
  };
  if (options.pairs == DescriptorPairs::kSource) {
    for (size_t j = 0; j < neighbours.size(); ++j) {
      if (neighbours[j] != source)
        AddPair(context, source, neighbours[j], 1.0F - falloff * distances[j], shell(j), descriptor);
    }
  } else {
    for (size_t i = 0; i < neighbours.size(); ++i) {
      for (size_t j = i + 1; j < neighbours.size(); ++j)
        AddPair(context, neighbours[i], neighbours[j], 1.0F - falloff * distances[j], shell(j), descriptor);
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
  if (pairs != DescriptorPairs::kAll && pairs != DescriptorPairs::kSource) {
    ThrowInputError("descriptor options", "pairs", "0 (all pairs) or 1 (source pairs)",
                    std::to_string(static_cast<int>(pairs)));
  }
  const int kind = static_cast<int>(appearance);
  if (kind < 0 || kind > static_cast<int>(DescriptorAppearance::kMonogenic)) {
    ThrowInputError("descriptor options", "appearance", "0 (RGB differences), 1 (RGB log ratios) or 2 (monogenic)",
                    std::to_string(kind));
  }
  if (shells != 1 && shells != 2 && shells != 4) {
    ThrowInputError("descriptor options", "shells", "1, 2 or 4", std::to_string(shells));
  }
  if (!(closeness_weight >= 0.0 && closeness_weight <= 1.0)) {
    ThrowInputError("descriptor options", "closeness_weight", "a weight in [0, 1]", std::to_string(closeness_weight));
  }
}

Descriptors ComputeDescriptors(const std::vector<Primitive>& input, const DescriptorOptions& options, int threads,
                               int source_step) {
  options.Check();
  if (threads < 1) ThrowInputError("descriptor computation", "threads", "at least 1", std::to_string(threads));
  if (source_step < 1) {
    ThrowInputError("descriptor computation", "source_step", "at least 1", std::to_string(source_step));
  }
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
  // The sources: every source_step-th primitive (all of them are neighbours).
  const size_t step = static_cast<size_t>(source_step);
  const size_t sources = (primitives.size() + step - 1) / step;
  std::vector<float> source_positions(3 * sources);
  for (size_t s = 0; s < sources; ++s) std::copy_n(&positions[3 * s * step], 3, &source_positions[3 * s]);
  std::vector<std::vector<size_t>> neighbour_lists;  // per source
  std::vector<std::vector<float>> distances;
  index.radiusSearch(flann::Matrix<float>(source_positions.data(), sources, 3), neighbour_lists, distances,
                     squared_radius, search);

  const AppearanceValues appearance = ComputeAppearance(primitives, options.appearance);
  const Context context{primitives, appearance, options};
  // Row s describes source s (primitive s * step); the rows of isolated sources are dropped at the end.
  cv::Mat values(static_cast<int>(sources), kDescriptorSize, CV_32F);
  auto describe = [&](size_t s) {
    const size_t i = s * step;
    const std::vector<size_t>& found = neighbour_lists[s];  // by distance, the source first
    const size_t cap = options.max_neighbours > 0 ? static_cast<size_t>(options.max_neighbours) : found.size();
    std::vector<int> neighbours;
    std::vector<float> neighbour_distances;
    for (size_t j = 0; j < std::min(cap, found.size()); ++j) {
      // All, or evenly spread over the distance ranks, so that the context still spans the whole radius.
      const size_t k = found.size() <= cap ? j : j * (found.size() - 1) / (cap - 1);
      neighbours.push_back(static_cast<int>(found[k]));
      neighbour_distances.push_back(std::sqrt(distances[s][k]));
    }
    DescribeContext(context, static_cast<int>(i), neighbours, neighbour_distances,
                    values.ptr<float>(static_cast<int>(s)));
  };
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t s = next++; s < sources; s = next++) {
      if (neighbour_lists[s].size() >= 2) describe(s);  // isolated: no context
    }
  };
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();

  std::vector<int> rows;  // of `values`
  for (size_t s = 0; s < sources; ++s) {
    if (neighbour_lists[s].size() < 2) continue;
    rows.push_back(static_cast<int>(s));
    descriptors.primitive.push_back(static_cast<int>(s * step));
  }
  descriptors.values.create(static_cast<int>(rows.size()), kDescriptorSize, CV_32F);
  for (size_t row = 0; row < rows.size(); ++row) {
    values.row(rows[row]).copyTo(descriptors.values.row(static_cast<int>(row)));
  }
  return descriptors;
}

}  // namespace ecv
