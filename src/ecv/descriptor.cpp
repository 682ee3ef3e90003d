#include "ecv/descriptor.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <numeric>
#include <string>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/parallel.h"

namespace ecv {
namespace {

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

// The six histograms of one source's context. Its members are gathered into contiguous arrays first: the
// pair loop reads each of them once per pair, and the scene's dense contexts have up to 128 members.
class ContextHistograms {
 public:
  ContextHistograms(const AppearanceValues& appearance, const DescriptorOptions& options)
      : appearance_(appearance),
        options_(options),
        bins_(kDescriptorBins / options.shells),
        first_histogram_(options.shape == DescriptorShape::kSurface ? 3 : 0),
        histograms_(options.use_color ? 6 : 3) {
    // Value k of a pair lies in [low_k, 1]; (value - low_k) * scale_k is its position in bins. Both factors
    // of the scale are powers of two, so this equals (value - low_k) / (1 - low_k) * bins exactly.
    const float cosine_low = options.unsigned_segments ? 0.0F : -1.0F;
    for (int k = 0; k < 6; ++k) {
      low_[k] = k < 3 ? cosine_low : -1.0F;
      scale_[k] = static_cast<float>(bins_) / (1.0F - low_[k]);
    }
  }

  // Fills `descriptor` with the normalised histograms of the pairs of `neighbours` (indices into primitives,
  // sorted by distance to `source`, `distances` from it in metres): all pairs or those with the source.
  void Describe(const std::vector<Primitive>& primitives, int source, const std::vector<int>& neighbours,
                const std::vector<float>& distances, float* descriptor) {
    Gather(primitives, neighbours, distances);
    std::fill(descriptor, descriptor + kDescriptorSize, 0.0F);
    const size_t count = neighbours.size();
    if (options_.pairs == DescriptorPairs::kSource) {
      const Member member = MemberOf(primitives[static_cast<size_t>(source)], source);
      for (size_t j = 0; j < count; ++j) {
        if (neighbours[j] != source) AddPair(member, j, descriptor);
      }
    } else {
      for (size_t i = 0; i < count; ++i) {
        const Member member{position_[i], orientation_[i], appearance_values_[i]};
        for (size_t j = i + 1; j < count; ++j) AddPair(member, j, descriptor);
      }
    }
    Normalise(descriptor);
  }

 private:
  struct Member {
    Eigen::Vector3f position, orientation, appearance;
  };

  Member MemberOf(const Primitive& primitive, int index) const {
    return {primitive.position, primitive.orientation, appearance_.values[static_cast<size_t>(index)]};
  }

  void Gather(const std::vector<Primitive>& primitives, const std::vector<int>& neighbours,
              const std::vector<float>& distances) {
    const float falloff = static_cast<float>(options_.closeness_weight / options_.radius_m);
    const float inverse_squared_radius = static_cast<float>(1.0 / (options_.radius_m * options_.radius_m));
    position_.clear();
    orientation_.clear();
    appearance_values_.clear();
    weight_.clear();
    shell_offset_.clear();
    for (size_t j = 0; j < neighbours.size(); ++j) {
      const Member member = MemberOf(primitives[static_cast<size_t>(neighbours[j])], neighbours[j]);
      position_.push_back(member.position);
      orientation_.push_back(member.orientation);
      appearance_values_.push_back(member.appearance);
      // A pair is weighted, and put in a radial shell, by its member farther from the source; the shells
      // have equal areas: by the squared distance from the source.
      weight_.push_back(1.0F - falloff * distances[j]);
      const float share = distances[j] * distances[j] * inverse_squared_radius;
      const int shell = std::min(static_cast<int>(share * static_cast<float>(options_.shells)), options_.shells - 1);
      shell_offset_.push_back(shell * bins_);
    }
  }

  // Adds the pair {a, member j} (a the closer to the source) to the six histograms.
  void AddPair(const Member& a, size_t j, float* descriptor) const {
    const float weight = weight_[j];
    const Eigen::Vector3f offset = position_[j] - a.position;
    const float length = offset.norm();
    if (length <= 0.0F || weight <= 0.0F) return;
    const Eigen::Vector3f d = offset / length;
    const Eigen::Vector3f& b_orientation = orientation_[j];
    float values[6] = {a.orientation.dot(b_orientation), a.orientation.dot(d), b_orientation.dot(d)};
    if (options_.unsigned_segments) {
      for (int k = 0; k < 3; ++k) values[k] = std::abs(values[k]);
    }
    if (options_.use_color) {
      const Eigen::Vector3f difference = appearance_values_[j] - a.appearance;
      for (int k = 0; k < 3; ++k) {
        float value = difference[k];
        const float period = appearance_.period[k];
        if (period > 0.0F) value -= period * std::floor(value / period + 0.5F);
        values[3 + k] = value * appearance_.scale[k];
      }
    }
    float* shell = descriptor + shell_offset_[j];
    for (int k = first_histogram_; k < histograms_; ++k) {
      const float position = (values[k] - low_[k]) * scale_[k] - 0.5F;  // in bins, bin centres at integers
      float* histogram = shell + k * kDescriptorBins;
      if (options_.soft_binning) {  // shared linearly between the two nearest bins
        const float clamped = std::clamp(position, 0.0F, static_cast<float>(bins_ - 1));
        const int lower = std::min(static_cast<int>(clamped), bins_ - 2);
        const float upper_share = clamped - static_cast<float>(lower);
        histogram[lower] += weight * (1.0F - upper_share);
        histogram[lower + 1] += weight * upper_share;
      } else {  // the nearest bin
        histogram[std::clamp(static_cast<int>(std::max(position, -0.5F) + 0.5F), 0, bins_ - 1)] += weight;
      }
    }
  }

  void Normalise(float* descriptor) const {
    for (int h = 0; h < 6; ++h) {
      float* histogram = descriptor + h * kDescriptorBins;
      const float sum = std::accumulate(histogram, histogram + kDescriptorBins, 0.0F);
      if (sum <= 0.0F) continue;
      for (int bin = 0; bin < kDescriptorBins; ++bin) {
        histogram[bin] = options_.hellinger ? std::sqrt(histogram[bin] / sum) : histogram[bin] / sum;
      }
    }
  }

  const AppearanceValues& appearance_;
  const DescriptorOptions& options_;
  const int bins_;             // per histogram and radial shell
  const int first_histogram_;  // 3 when the surface context fills the geometric ones (SurfaceHistograms)
  const int histograms_;       // filled up to: 6, or the 3 geometric ones without colour
  float low_[6] = {};          // value k of a pair lies in [low_k, 1]
  float scale_[6] = {};
  std::vector<Eigen::Vector3f> position_, orientation_, appearance_values_;  // of the gathered members
  std::vector<float> weight_;
  std::vector<int> shell_offset_;
};

// Radius searches whose members' order does not matter: FLANN would sort them by distance otherwise.
flann::SearchParams Unsorted() {
  flann::SearchParams params;
  params.sorted = false;
  return params;
}

// The surface context (DescriptorShape::kSurface) of a source: the first three histograms' 48 values.
class SurfaceHistograms {
 public:
  static constexpr int kShells = 2, kSectors = 4, kBins = 3 * kDescriptorBins / (kShells * kSectors);

  // `surface` must hold at least one sample and outlive this. FLANN's matrix takes a mutable pointer; the index only
  // reads the points.
  SurfaceHistograms(const SurfaceSamples& surface, const DescriptorOptions& options)
      : surface_(surface),
        radius_(static_cast<float>(options.radius_m)),
        scale_(static_cast<float>(std::sqrt(3.0 * options.surface_weight))),
        hellinger_(options.hellinger),
        index_(flann::Matrix<float>(const_cast<float*>(surface.points[0].data()), surface.size(), 3),
               flann::KDTreeSingleIndexParams(12)) {
    index_.buildIndex();
  }

  // Fills values[0, 48) for the source at `source`; zeros when fewer than 5 samples lie within the radius.
  void Describe(const Eigen::Vector3f& source, std::vector<std::vector<size_t>>& found,
                std::vector<std::vector<float>>& squared, float* values) const {
    constexpr int kValues = 3 * kDescriptorBins;
    std::fill(values, values + kValues, 0.0F);
    Eigen::Vector3f query = source;
    index_.radiusSearch(flann::Matrix<float>(query.data(), 1, 3), found, squared, radius_ * radius_, Unsorted());
    const std::vector<size_t>& members = found[0];
    if (members.size() < 5) return;
    Eigen::Vector3f x, y, z;
    if (!ReferenceFrame(source, members, squared[0], &x, &y, &z)) return;
    constexpr float kTwoPi = 6.28318531F;
    for (size_t k = 0; k < members.size(); ++k) {
      const Eigen::Vector3f offset = surface_.points[members[k]] - source;
      const int shell = std::min(static_cast<int>(squared[0][k] / (radius_ * radius_) * kShells), kShells - 1);
      // Shared linearly between the two nearest sectors (centres at k + 1/2 of kSectors around the circle).
      const float azimuth = std::atan2(offset.dot(y), offset.dot(x)) + kTwoPi / 2.0F;  // [0, 2 pi]
      const float centred = azimuth / kTwoPi * static_cast<float>(kSectors) - 0.5F;
      const int low = static_cast<int>(std::floor(centred));
      const float high_share = centred - static_cast<float>(low);
      const int sectors[2] = {(low + kSectors) % kSectors, (low + 1) % kSectors};
      const float sector_share[2] = {1.0F - high_share, high_share};
      // The cosine of the sample's normal with z, shared between its two nearest bins.
      const float cosine = std::clamp(surface_.normals[members[k]].dot(z), -1.0F, 1.0F);
      const float position =
          std::clamp((cosine + 1.0F) * 0.5F * static_cast<float>(kBins) - 0.5F, 0.0F, static_cast<float>(kBins - 1));
      const int lower = std::min(static_cast<int>(position), kBins - 2);
      const float upper = position - static_cast<float>(lower);
      for (int t = 0; t < 2; ++t) {
        float* histogram = values + (shell * kSectors + sectors[t]) * kBins;
        histogram[lower] += sector_share[t] * (1.0F - upper);
        histogram[lower + 1] += sector_share[t] * upper;
      }
    }
    const float sum = std::accumulate(values, values + kValues, 0.0F);
    if (sum <= 0.0F) return;
    for (int k = 0; k < kValues; ++k) {
      values[k] = hellinger_ ? scale_ * std::sqrt(values[k] / sum) : scale_ * values[k] / sum;
    }
  }

 private:
  // The source's local reference frame: eigenvectors of the covariance of the members' offsets, weighted by
  // radius - distance. z (least variance) turned to the side most normals face, x (most variance) towards most
  // of the offsets, y = z x x. Rigid: it moves with the surface. False when degenerate.
  bool ReferenceFrame(const Eigen::Vector3f& source, const std::vector<size_t>& members,
                      const std::vector<float>& squared, Eigen::Vector3f* x, Eigen::Vector3f* y,
                      Eigen::Vector3f* z) const {
    Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();
    Eigen::Vector3f normal_sum = Eigen::Vector3f::Zero();
    float total = 0.0F;
    for (size_t k = 0; k < members.size(); ++k) {
      const Eigen::Vector3f offset = surface_.points[members[k]] - source;
      const float weight = radius_ - std::sqrt(squared[k]);
      covariance += weight * offset * offset.transpose();
      total += weight;
      normal_sum += surface_.normals[members[k]];
    }
    if (!(total > 0.0F)) return false;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver(covariance / total);
    *z = solver.eigenvectors().col(0);
    *x = solver.eigenvectors().col(2);
    if (z->dot(normal_sum) < 0.0F) *z = -*z;
    int ahead = 0;
    for (const size_t m : members) ahead += (surface_.points[m] - source).dot(*x) >= 0.0F ? 1 : 0;
    if (2 * ahead < static_cast<int>(members.size())) *x = -*x;
    *y = z->cross(*x);
    return true;
  }

  const SurfaceSamples& surface_;
  const float radius_, scale_;
  const bool hellinger_;
  flann::KDTreeSingleIndex<flann::L2_Simple<float>> index_;
};

}  // namespace

DescriptorOptions DescriptorOptions::SourceShells() {
  DescriptorOptions options;
  options.pairs = DescriptorPairs::kSource;
  options.shells = 4;
  options.radius_m = 0.045;
  return options;
}

DescriptorOptions DescriptorOptions::SurfaceShells() {
  DescriptorOptions options = SourceShells();
  options.shape = DescriptorShape::kSurface;
  return options;
}

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
  if (shape != DescriptorShape::kPrimitives && shape != DescriptorShape::kSurface) {
    ThrowInputError("descriptor options", "shape", "0 (the primitives' orientations) or 1 (the surface context)",
                    std::to_string(static_cast<int>(shape)));
  }
  if (!(surface_weight > 0.0) || !std::isfinite(surface_weight)) {
    ThrowInputError("descriptor options", "surface_weight", "a weight > 0", std::to_string(surface_weight));
  }
  if (!(closeness_weight >= 0.0 && closeness_weight <= 1.0)) {
    ThrowInputError("descriptor options", "closeness_weight", "a weight in [0, 1]", std::to_string(closeness_weight));
  }
}

SurfaceSamples DescriptorSurface(const RgbdFrame& frame, const DescriptorOptions& options, const cv::Mat& mask) {
  if (options.shape != DescriptorShape::kSurface) return {};
  return SampleSurface(frame, mask);
}

Descriptors ComputeDescriptors(const std::vector<Primitive>& input, const DescriptorOptions& options, int threads,
                               int source_step, const SurfaceSamples* surface) {
  options.Check();
  const bool surface_shape = options.shape == DescriptorShape::kSurface;
  if (surface_shape && surface == nullptr) {
    ThrowInputError("descriptor computation", "surface",
                    "the views' surface samples (the descriptor's shape is the surface context)");
  }
  if (surface != nullptr && surface->normals.size() != surface->points.size()) {
    ThrowInputError("descriptor computation", "surface.normals", "one normal per point",
                    std::to_string(surface->normals.size()) + " for " + std::to_string(surface->points.size()));
  }
  CheckThreadCount("descriptor computation", threads);
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

  const AppearanceValues appearance = ComputeAppearance(primitives, options.appearance);
  std::unique_ptr<SurfaceHistograms> surface_histograms;
  if (surface_shape && surface->size() > 0) surface_histograms = std::make_unique<SurfaceHistograms>(*surface, options);
  // Row s describes source s (primitive s * step); the rows of isolated sources are dropped at the end. Each
  // worker searches its own sources' neighbours: on a dense frame the radius searches are a large share of the work.
  cv::Mat values(static_cast<int>(sources), kDescriptorSize, CV_32F);
  std::vector<char> described(sources, 0);  // not vector<bool>: written by the workers
  std::atomic<size_t> next{0};
  auto work = [&] {
    ContextHistograms histograms(appearance, options);  // per worker: reuses its buffers
    std::vector<std::vector<size_t>> found(1);
    std::vector<std::vector<float>> found_squared(1);
    std::vector<int> neighbours;
    std::vector<float> neighbour_distances;
    for (size_t s = next++; s < sources; s = next++) {
      float* source = &positions[3 * s * step];
      index.radiusSearch(flann::Matrix<float>(source, 1, 3), found, found_squared, squared_radius, search);
      const std::vector<size_t>& near = found[0];  // by distance, the source first
      if (near.size() < 2) continue;               // isolated: no context
      const size_t cap = options.max_neighbours > 0 ? static_cast<size_t>(options.max_neighbours) : near.size();
      neighbours.clear();
      neighbour_distances.clear();
      for (size_t j = 0; j < std::min(cap, near.size()); ++j) {
        // All, or evenly spread over the distance ranks, so that the context still spans the whole radius.
        const size_t k = near.size() <= cap ? j : j * (near.size() - 1) / (cap - 1);
        neighbours.push_back(static_cast<int>(near[k]));
        neighbour_distances.push_back(std::sqrt(found_squared[0][k]));
      }
      float* row = values.ptr<float>(static_cast<int>(s));
      histograms.Describe(primitives, static_cast<int>(s * step), neighbours, neighbour_distances, row);
      if (surface_shape) {
        if (surface_histograms) {
          surface_histograms->Describe(primitives[s * step].position, found, found_squared, row);
        } else {
          std::fill(row, row + 3 * kDescriptorBins, 0.0F);
        }
      }
      described[s] = 1;
    }
  };
  RunOnThreads(threads, work);

  std::vector<int> rows;  // of `values`
  for (size_t s = 0; s < sources; ++s) {
    if (described[s] == 0) continue;
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
