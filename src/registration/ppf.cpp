// Point pair features: the model's table of quantized pair features, and voting for poses in a scene (Drost et al.
// 2010, Sect. 3; the refinements of Vidal et al. 2018, Sect. 3).

#include "registration/ppf.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <unordered_map>
#include <utility>

#include "core/error.h"
#include "registration/icp.h"

namespace ecv {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Integer voxel coordinates packed into one key (21 bits each, offset so that negative coordinates fit).
uint64_t VoxelKey(const Eigen::Vector3f& point, double voxel) {
  auto cell = [&](float v) { return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / voxel)) + (1 << 20)); };
  return (cell(point.x()) & 0x1FFFFF) << 42 | (cell(point.y()) & 0x1FFFFF) << 21 | (cell(point.z()) & 0x1FFFFF);
}

// atan2 to within 2e-6 rad (a polynomial for atan on [0, 1] and the octants' symmetries), several times faster than
// std::atan2: each scene pair takes one (its alpha), and the bins it falls in are 12 degrees wide.
float FastAtan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float big = std::max(ax, ay);
  if (big == 0.0F) return 0.0F;
  const float z = std::min(ax, ay) / big, z2 = z * z;
  float angle =
      z * (0.99997726F +
           z2 * (-0.33262347F + z2 * (0.19354346F + z2 * (-0.11643287F + z2 * (0.05265332F + z2 * -0.01172120F)))));
  if (ay > ax) angle = static_cast<float>(kPi / 2.0) - angle;
  if (x < 0.0F) angle = static_cast<float>(kPi) - angle;
  return y < 0.0F ? -angle : angle;
}

// acos to within 1e-6 rad over [-1, 1] (Abramowitz and Stegun 4.4.46, its constant term pi / 2 so that a right angle
// lands exactly on its bin border, as a mesh's box corners do), clamped: one square root and no division.
float FastAcos(float x) {
  const float a = std::min(std::abs(x), 1.0F);
  const float angle =
      std::sqrt(1.0F - a) *
      (static_cast<float>(kPi / 2.0) +
       a * (-0.2145988016F +
            a * (0.0889789874F +
                 a * (-0.0501743046F +
                      a * (0.0308918810F + a * (-0.0170881256F + a * (0.0066700901F + a * -0.0012624911F)))))));
  return x < 0.0F ? static_cast<float>(kPi) - angle : angle;
}

// `normal` scaled to unit length (pair features take unit normals), or +z when it has none.
Eigen::Vector3f UnitOr(const Eigen::Vector3f& normal) {
  const float length = normal.norm();
  return length > 0.0F ? Eigen::Vector3f(normal / length) : Eigen::Vector3f::UnitZ();
}

// The rotation that turns `normal` onto +x (Drost's T_{m->g} without its translation).
Eigen::Matrix3f ToXAxis(const Eigen::Vector3f& normal) {
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX();
  const Eigen::Vector3f axis = normal.cross(x);
  const float sine = axis.norm(), cosine = normal.dot(x);
  if (sine < 1e-6F)
    return cosine > 0.0F ? Eigen::Matrix3f::Identity()
                         : Eigen::Matrix3f(Eigen::AngleAxisf(kPi, Eigen::Vector3f::UnitZ()));
  return Eigen::AngleAxisf(std::atan2(sine, cosine), axis / sine).toRotationMatrix();
}

// The angle about x that turns `local` (a point in a reference point's frame) into the half-plane y >= 0, z = 0, in
// 1/65536 turns from -pi (PpfModel::Entry::alpha).
uint16_t AlphaOf(const Eigen::Vector3f& local) {
  const float turns = (FastAtan2(-local.z(), local.y()) + static_cast<float>(kPi)) / static_cast<float>(2.0 * kPi);
  return static_cast<uint16_t>(static_cast<uint32_t>(std::lround(turns * 65536.0F)) & 0xffffU);
}

// Quantized features of a pair: the distance and the three angles, as bin positions (fractional) and the key.
class FeatureBins {
 public:
  FeatureBins(double diameter_m, const PpfOptions& options)
      : distance_bins_(static_cast<int>(std::ceil(1.0 / options.distance_step)) + 1),
        angle_bins_(options.angle_bins),
        per_distance_(static_cast<float>(1.0 / (options.distance_step * diameter_m))),
        per_angle_(static_cast<float>(options.angle_bins / kPi)),
        coplanar_(static_cast<float>(options.coplanar_deg * kPi / 180.0)),
        margin_(static_cast<float>(options.spread_margin)) {}

  // The pair's bin positions (distance, angle(n1, d), angle(n2, d), angle(n1, n2)) of unit normals; false when beyond
  // the diameter or coplanar (PpfOptions::coplanar_deg).
  bool Positions(const OrientedPoint& a, const OrientedPoint& b, float positions[4]) const {
    const Eigen::Vector3f d = b.position - a.position;
    const float length = d.norm();
    positions[0] = length * per_distance_;
    if (!(positions[0] < static_cast<float>(distance_bins_)) || length <= 0.0F) return false;
    const Eigen::Vector3f direction = d / length;
    const float a1 = FastAcos(a.normal.dot(direction)), a2 = FastAcos(b.normal.dot(direction));
    const float a3 = FastAcos(a.normal.dot(b.normal));
    if (a3 < coplanar_ && std::abs(a1 - kHalfPi) < coplanar_ && std::abs(a2 - kHalfPi) < coplanar_) return false;
    positions[1] = a1 * per_angle_;
    positions[2] = a2 * per_angle_;
    positions[3] = a3 * per_angle_;
    return true;
  }

  // Keys run from 0 to NumKeys() - 1.
  uint32_t NumKeys() const { return static_cast<uint32_t>(distance_bins_) * angle_bins_ * angle_bins_ * angle_bins_; }

  uint32_t Key(const int bins[4]) const {
    return ((static_cast<uint32_t>(bins[0]) * angle_bins_ + bins[1]) * angle_bins_ + bins[2]) * angle_bins_ + bins[3];
  }

  // The pair's own key, and with `spread` also those with each value near a border (spread_margin) moved to the
  // neighbouring bin across it (up to 16).
  int Keys(const float positions[4], bool spread, uint32_t keys[16]) const {
    int bins[4], other[4];
    for (int k = 0; k < 4; ++k) {
      const int limit = k == 0 ? distance_bins_ : angle_bins_;
      bins[k] = std::min(static_cast<int>(positions[k]), limit - 1);
      const float remainder = positions[k] - static_cast<float>(bins[k]);
      other[k] = remainder < margin_ ? bins[k] - 1 : remainder > 1.0F - margin_ ? bins[k] + 1 : bins[k];
      if (other[k] < 0 || other[k] >= limit) other[k] = bins[k];
    }
    if (!spread) {
      keys[0] = Key(bins);
      return 1;
    }
    // Every combination of each value's own bin and, when near a border, its neighbour's: a product over the four.
    keys[0] = 0;
    int count = 1;
    for (int k = 0; k < 4; ++k) {
      const uint32_t size = k == 0 ? 1U : static_cast<uint32_t>(angle_bins_);
      const int before = count;
      for (int c = 0; c < before; ++c) {
        const uint32_t prefix = keys[c] * size;
        keys[c] = prefix + static_cast<uint32_t>(bins[k]);
        if (other[k] != bins[k]) keys[count++] = prefix + static_cast<uint32_t>(other[k]);
      }
    }
    return count;
  }

 private:
  static constexpr float kHalfPi = static_cast<float>(kPi / 2.0);
  int distance_bins_, angle_bins_;
  float per_distance_, per_angle_, coplanar_, margin_;
};

// Scene points by cells of one diameter, for the pairs of a reference point.
class CellGrid {
 public:
  CellGrid(const std::vector<OrientedPoint>& points, double cell) : cell_(cell) {
    for (size_t i = 0; i < points.size(); ++i)
      cells_[VoxelKey(points[i].position, cell)].push_back(static_cast<int>(i));
  }

  template <typename Visit>
  void ForNear(const Eigen::Vector3f& centre, Visit visit) const {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const Eigen::Vector3f moved = centre + static_cast<float>(cell_) * Eigen::Vector3f(dx, dy, dz);
          const auto found = cells_.find(VoxelKey(moved, cell_));
          if (found == cells_.end()) continue;
          for (const int i : found->second) visit(i);
        }
      }
    }
  }

 private:
  double cell_;
  std::unordered_map<uint64_t, std::vector<int>> cells_;
};

// Pose votes of one reference point, clustered with the others' afterwards.
struct Vote {
  Eigen::Isometry3d pose;
  double votes;
};

// An accumulator cell and its votes.
struct Peak {
  uint32_t votes;
  size_t cell;
};

// The `k` cells of `accumulator` with the most votes (the bits `count_mask` selects), at least 3, most first and of
// equal votes the lower cell first, in one pass. Blocks of cells none of which beats the floor are passed over on
// their maximum (a loop the compiler vectorises): most are, once the floor has risen.
void BestCells(const std::vector<uint32_t>& accumulator, uint32_t count_mask, size_t k, std::vector<Peak>* peaks) {
  constexpr size_t kBlock = 32;
  peaks->clear();
  uint32_t floor = 2;  // a cell needs more votes than this to enter
  const size_t size = accumulator.size();
  const uint32_t* cells = accumulator.data();
  for (size_t start = 0; start < size; start += kBlock) {
    const size_t end = std::min(size, start + kBlock);
    uint32_t most = 0;
    for (size_t c = start; c < end; ++c) most = std::max(most, cells[c] & count_mask);
    if (most <= floor) continue;
    for (size_t c = start; c < end; ++c) {
      const uint32_t votes = cells[c] & count_mask;
      if (votes <= floor) continue;
      auto at = std::find_if(peaks->begin(), peaks->end(), [&](const Peak& p) { return p.votes < votes; });
      peaks->insert(at, {votes, c});
      if (peaks->size() > k) peaks->pop_back();
      if (peaks->size() == k) floor = peaks->back().votes;
    }
  }
}

// Greedy clustering (Drost Sect. 3.4): poses by votes, each joining the first cluster whose leading pose is close.
std::vector<PpfPose> ClusterPoses(std::vector<Vote> votes, double diameter_m, const PpfOptions& options) {
  std::stable_sort(votes.begin(), votes.end(), [](const Vote& a, const Vote& b) { return a.votes > b.votes; });
  const double max_distance = options.cluster_distance * diameter_m;
  const double max_angle = options.cluster_angle_deg * kPi / 180.0;
  std::vector<PpfPose> clusters;
  for (const Vote& vote : votes) {
    bool joined = false;
    for (PpfPose& cluster : clusters) {
      const Eigen::Isometry3d& lead = cluster.camera_from_object;
      if ((lead.translation() - vote.pose.translation()).norm() > max_distance) continue;
      if (Eigen::AngleAxisd(lead.linear().transpose() * vote.pose.linear()).angle() > max_angle) continue;
      cluster.votes += vote.votes;
      joined = true;
      break;
    }
    if (!joined && clusters.size() < 2000) clusters.push_back({vote.pose, vote.votes});
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const PpfPose& a, const PpfPose& b) { return a.votes > b.votes; });
  if (clusters.size() > static_cast<size_t>(options.max_poses)) clusters.resize(static_cast<size_t>(options.max_poses));
  return clusters;
}

// One table look-up of a reference point's scene pair: a feature key, the pair's alpha and the pair's 1-based stamp.
struct Lookup {
  uint32_t key;
  uint16_t alpha;
  uint16_t pair;
};

// The look-ups' votes into `accumulator` (per model point and rotation bin: the last pair that voted in the high 16
// bits, the votes in the low 16, so that a pair votes once per cell); returns the table entries voted for. The table
// is far larger than the cache: each key's offsets and then its entries are fetched a few look-ups ahead.
size_t CastVotes(const PpfModel& model, const std::vector<Lookup>& lookups, int angle_bins,
                 std::vector<uint32_t>* accumulator) {
  constexpr size_t kAhead = 6;  // look-ups between fetching a key's entries and voting with them
  const size_t count = lookups.size();
  const auto bins = static_cast<uint32_t>(angle_bins);
  uint32_t* cells = accumulator->data();
  size_t entries = 0;
  for (size_t j = 0; j < count; ++j) {
    if (j + 2 * kAhead < count) model.PrefetchOffsets(lookups[j + 2 * kAhead].key);
    if (j + kAhead < count) model.PrefetchEntries(lookups[j + kAhead].key);
    const Lookup& lookup = lookups[j];
    const auto [begin, end] = model.Find(lookup.key);
    entries += static_cast<size_t>(end - begin);
    const uint32_t stamp = static_cast<uint32_t>(lookup.pair) << 16;
    for (const PpfModel::Entry* entry = begin; entry != end; ++entry) {
      // alpha_model - alpha_scene, wrapped to a turn, from -pi: the rotation about x between the two frames.
      const uint32_t turn = static_cast<uint16_t>(entry->alpha - lookup.alpha + 32768U);
      uint32_t& cell = cells[entry->reference * bins + ((turn * bins) >> 16)];
      if ((cell & 0xffff0000U) != stamp) cell = stamp | ((cell & 0xffffU) + 1U);
    }
  }
  return entries;
}

}  // namespace

void PpfOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("point pair options", field, expected);
  };
  require(sampling > 0.0 && sampling < 1.0, "sampling", "a share of the diameter in (0, 1)");
  require(distance_step > 0.0 && distance_step < 1.0, "distance_step", "a share of the diameter in (0, 1)");
  require(angle_bins >= 4 && angle_bins <= 180, "angle_bins", "4 to 180");
  require(keep_normal_deg > 0.0 && keep_normal_deg <= 180.0, "keep_normal_deg", "in (0, 180] degrees");
  require(scene_keep_normal_deg > 0.0 && scene_keep_normal_deg <= 180.0, "scene_keep_normal_deg", "in (0, 180]");
  require(reference_spacing > 0.0 && reference_spacing <= 1.0, "reference_spacing",
          "a share of the diameter in (0, 1]");
  require(max_references >= 0, "max_references", ">= 0 (0: all)");
  require(poses_per_reference >= 1, "poses_per_reference", "at least 1");
  require(cluster_distance > 0.0, "cluster_distance", "> 0");
  require(spread_margin >= 0.0 && spread_margin <= 0.5, "spread_margin", "a share of a bin in [0, 0.5]");
  require(cluster_angle_deg > 0.0, "cluster_angle_deg", "> 0 degrees");
  require(max_poses >= 1, "max_poses", "at least 1");
  require(coplanar_deg >= 0.0 && coplanar_deg < 90.0, "coplanar_deg", "in [0, 90) degrees");
}

std::vector<OrientedPoint> SubsampleByNormals(const std::vector<OrientedPoint>& points, double voxel_m,
                                              double keep_normal_deg) {
  const float min_cosine = static_cast<float>(std::cos(keep_normal_deg * kPi / 180.0));
  std::unordered_map<uint64_t, std::vector<int>> voxels;
  std::vector<uint64_t> order;  // voxels in the order first met, so that the result does not depend on hashing
  for (size_t i = 0; i < points.size(); ++i) {
    auto [entry, added] = voxels.try_emplace(VoxelKey(points[i].position, voxel_m));
    if (added) order.push_back(entry->first);
    entry->second.push_back(static_cast<int>(i));
  }
  std::vector<OrientedPoint> kept;
  for (const uint64_t key : order) {
    std::vector<int>& members = voxels[key];
    const Eigen::Vector3f centre =
        (points[static_cast<size_t>(members[0])].position / static_cast<float>(voxel_m)).array().floor().matrix() *
            static_cast<float>(voxel_m) +
        Eigen::Vector3f::Constant(static_cast<float>(voxel_m / 2.0));
    std::stable_sort(members.begin(), members.end(), [&](int a, int b) {
      return (points[static_cast<size_t>(a)].position - centre).squaredNorm() <
             (points[static_cast<size_t>(b)].position - centre).squaredNorm();
    });
    const size_t first = kept.size();
    for (const int m : members) {
      const OrientedPoint& point = points[static_cast<size_t>(m)];
      const bool similar = std::any_of(kept.begin() + static_cast<std::ptrdiff_t>(first), kept.end(),
                                       [&](const OrientedPoint& k) { return k.normal.dot(point.normal) > min_cosine; });
      if (!similar) kept.push_back(point);
    }
  }
  return kept;
}

std::vector<OrientedPoint> SampleMeshSurface(const TriangleMesh& mesh, int count, uint64_t seed) {
  struct Face {
    const MeshPart* part;
    Eigen::Vector3i triangle;
  };
  std::vector<Face> faces;
  std::vector<double> cumulative;
  double total = 0.0;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3i& t : part.triangles) {
      const Eigen::Vector3f& a = part.positions[static_cast<size_t>(t[0])];
      const double area =
          0.5 *
          (part.positions[static_cast<size_t>(t[1])] - a).cross(part.positions[static_cast<size_t>(t[2])] - a).norm();
      if (!(area > 0.0)) continue;
      total += area;
      faces.push_back({&part, t});
      cumulative.push_back(total);
    }
  }
  std::vector<OrientedPoint> samples;
  if (faces.empty() || count <= 0) return samples;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  samples.reserve(static_cast<size_t>(count));
  for (int s = 0; s < count; ++s) {
    const size_t f = static_cast<size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), uniform(random) * total) - cumulative.begin());
    const Face& face = faces[std::min(f, faces.size() - 1)];
    const MeshPart& part = *face.part;
    double u = uniform(random), v = uniform(random);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const Eigen::Vector3f a = part.positions[static_cast<size_t>(face.triangle[0])];
    const Eigen::Vector3f b = part.positions[static_cast<size_t>(face.triangle[1])];
    const Eigen::Vector3f c = part.positions[static_cast<size_t>(face.triangle[2])];
    OrientedPoint point;
    point.position = a + static_cast<float>(u) * (b - a) + static_cast<float>(v) * (c - a);
    point.normal = (b - a).cross(c - a).normalized();
    if (!part.normals.empty()) {
      const Eigen::Vector3f vertex_normal = part.normals[static_cast<size_t>(face.triangle[0])] +
                                            part.normals[static_cast<size_t>(face.triangle[1])] +
                                            part.normals[static_cast<size_t>(face.triangle[2])];
      if (vertex_normal.dot(point.normal) < 0.0F) point.normal = -point.normal;
    }
    samples.push_back(point);
  }
  return samples;
}

std::vector<OrientedPoint> OrientedScenePoints(const RgbdFrame& frame, int stride) {
  return OrientedScenePoints(MakeOrganizedScene(frame.depth, frame.camera, stride));
}

std::vector<OrientedPoint> OrientedScenePoints(const OrganizedScene& organized) {
  std::vector<OrientedPoint> points;
  for (int v = 0; v < organized.points.rows; ++v) {
    for (int u = 0; u < organized.points.cols; ++u) {
      const cv::Vec3f p = organized.points.at<cv::Vec3f>(v, u), n = organized.normals.at<cv::Vec3f>(v, u);
      if (p[2] <= 0.0F || (n[0] == 0.0F && n[1] == 0.0F && n[2] == 0.0F)) continue;
      OrientedPoint point{{p[0], p[1], p[2]}, Eigen::Vector3f(n[0], n[1], n[2]).normalized()};
      if (point.normal.dot(point.position) > 0.0F) point.normal = -point.normal;
      points.push_back(point);
    }
  }
  return points;
}

void ScenePlaneOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("scene plane options", field, expected);
  };
  require(distance_m > 0.0, "distance_m", "> 0 m");
  require(normal_deg > 0.0 && normal_deg <= 90.0, "normal_deg", "in (0, 90] degrees");
  require(min_share > 0.0 && min_share <= 1.0, "min_share", "in (0, 1]");
  require(iterations >= 1, "iterations", "at least 1");
}

std::vector<OrientedPoint> WithoutDominantPlane(const std::vector<OrientedPoint>& points,
                                                const ScenePlaneOptions& options) {
  options.Check();
  if (points.size() < 3) return points;
  const float distance = static_cast<float>(options.distance_m);
  const float min_cosine = static_cast<float>(std::cos(options.normal_deg * kPi / 180.0));
  auto on_plane = [&](const OrientedPoint& point, const Eigen::Vector3f& normal, float offset) {
    return std::abs(normal.dot(point.position) + offset) <= distance &&
           std::abs(normal.dot(point.normal)) >= min_cosine;
  };
  // Planes are scored on at most 4000 of the points, spread evenly; the best one then takes its points from all.
  const size_t step = std::max<size_t>(1, points.size() / 4000);
  std::mt19937 random(1);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  Eigen::Vector3f best_normal = Eigen::Vector3f::Zero();
  float best_offset = 0.0F;
  size_t best_count = 0;
  for (int i = 0; i < options.iterations; ++i) {
    const Eigen::Vector3f& a = points[pick(random)].position;
    const Eigen::Vector3f& b = points[pick(random)].position;
    const Eigen::Vector3f& c = points[pick(random)].position;
    const Eigen::Vector3f normal = (b - a).cross(c - a);
    if (normal.norm() < 1e-9F) continue;
    const Eigen::Vector3f unit = normal.normalized();
    const float offset = -unit.dot(a);
    size_t count = 0;
    for (size_t k = 0; k < points.size(); k += step) count += on_plane(points[k], unit, offset) ? 1 : 0;
    if (count > best_count) {
      best_count = count;
      best_normal = unit;
      best_offset = offset;
    }
  }
  const size_t sampled = (points.size() + step - 1) / step;
  if (best_count == 0 || static_cast<double>(best_count) < options.min_share * static_cast<double>(sampled)) {
    return points;
  }
  std::vector<OrientedPoint> kept;
  kept.reserve(points.size());
  for (const OrientedPoint& point : points) {
    if (!on_plane(point, best_normal, best_offset)) kept.push_back(point);
  }
  return kept;
}

PpfModelSampling PpfModelSampling::Of(const PpfOptions& options, int samples) {
  return {samples, options.sampling, options.keep_normal_deg};
}

bool PpfModelSampling::operator==(const PpfModelSampling& other) const {
  return samples == other.samples && sampling == other.sampling && keep_normal_deg == other.keep_normal_deg;
}

void PpfModelSampling::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("point pair sampling", field, expected);
  };
  require(samples >= 10 && samples <= 10000000, "samples", "10 to 10 000 000 points");
  require(sampling > 0.0 && sampling < 1.0, "sampling", "a share of the diameter in (0, 1)");
  require(keep_normal_deg > 0.0 && keep_normal_deg <= 180.0, "keep_normal_deg", "in (0, 180] degrees");
}

std::vector<OrientedPoint> SampleModelPoints(const TriangleMesh& mesh, const PpfModelSampling& sampling) {
  sampling.Check();
  return SubsampleByNormals(SampleMeshSurface(mesh, sampling.samples), sampling.sampling * mesh.Diameter(),
                            sampling.keep_normal_deg);
}

PpfModel::PpfModel(const std::vector<OrientedPoint>& surface, double diameter_m, const PpfOptions& options)
    : PpfModel(surface, diameter_m, options, false) {}

PpfModel PpfModel::FromSampledPoints(std::vector<OrientedPoint> points, double diameter_m, const PpfOptions& options) {
  return PpfModel(std::move(points), diameter_m, options, true);
}

PpfModel::PpfModel(std::vector<OrientedPoint> points, double diameter_m, const PpfOptions& options, bool sampled)
    : diameter_m_(diameter_m), options_(options) {
  options.Check();
  if (!(diameter_m > 0.0)) ThrowInputError("point pair model", "diameter_m", "> 0 m", std::to_string(diameter_m));
  points_ =
      sampled ? std::move(points) : SubsampleByNormals(points, options.sampling * diameter_m, options.keep_normal_deg);
  for (OrientedPoint& point : points_) point.normal = UnitOr(point.normal);
  if (points_.size() < 10 || points_.size() > 65536) {
    ThrowInputError("point pair model", "surface", "10 to 65536 points after sub-sampling (sampling)",
                    std::to_string(points_.size()));
  }
  const FeatureBins bins(diameter_m, options);
  std::vector<std::pair<uint32_t, Entry>> keyed;  // every pair's key and entry, then sorted into the table by key
  for (size_t r = 0; r < points_.size(); ++r) {
    const Eigen::Matrix3f to_x = ToXAxis(points_[r].normal);
    for (size_t i = 0; i < points_.size(); ++i) {
      if (i == r) continue;
      float positions[4];
      if (!bins.Positions(points_[r], points_[i], positions)) continue;
      uint32_t key[16];
      bins.Keys(positions, false, key);
      keyed.push_back(
          {key[0], {static_cast<uint16_t>(r), AlphaOf(to_x * (points_[i].position - points_[r].position))}});
    }
  }
  pairs_ = keyed.size();
  offsets_.assign(bins.NumKeys() + 1, 0);
  for (const auto& [key, entry] : keyed) ++offsets_[key + 1];
  for (size_t k = 1; k < offsets_.size(); ++k) offsets_[k] += offsets_[k - 1];
  entries_.resize(keyed.size());
  std::vector<uint32_t> next(offsets_.begin(), offsets_.end() - 1);
  for (const auto& [key, entry] : keyed) entries_[next[key]++] = entry;
  if (pairs_ < 100) {
    ThrowInputError("point pair model", "surface", "a surface with relief (at least 100 pairs not in one plane)",
                    std::to_string(pairs_) + " pairs");
  }
}

std::vector<PpfPose> FindPpfPoses(const PpfModel& model, const std::vector<OrientedPoint>& scene_points,
                                  const std::vector<OrientedPoint>& explained, PpfSearchStats* stats) {
  const PpfOptions& options = model.options();
  const double diameter = model.diameter_m();
  // Scene points sub-sampled with unit normals (pair features take unit normals).
  auto sampled = [&](const std::vector<OrientedPoint>& points) {
    std::vector<OrientedPoint> kept =
        SubsampleByNormals(points, options.sampling * diameter, options.scene_keep_normal_deg);
    for (OrientedPoint& point : kept) point.normal = UnitOr(point.normal);
    return kept;
  };
  // The open points, then the explained ones they may pair with.
  std::vector<OrientedPoint> scene = sampled(scene_points);
  // The reference points: the open ones thinned to one per coarse voxel and differing normal, so that every surface
  // leads votes however few points it has.
  std::vector<OrientedPoint> leaders =
      SubsampleByNormals(scene, options.reference_spacing * diameter, options.scene_keep_normal_deg);
  const auto max_references = static_cast<size_t>(options.max_references);
  if (max_references > 0 && leaders.size() > max_references) {
    std::vector<OrientedPoint> drawn(max_references);
    for (size_t i = 0; i < max_references; ++i) drawn[i] = leaders[i * leaders.size() / max_references];
    leaders = std::move(drawn);
  }
  if (!explained.empty()) {
    const std::vector<OrientedPoint> others = sampled(explained);
    scene.insert(scene.end(), others.begin(), others.end());
  }
  const FeatureBins bins(diameter, options);
  const CellGrid grid(scene, diameter);
  const size_t model_points = model.points().size();
  const int angle_bins = options.angle_bins;
  // Per model point and rotation bin: votes and stamp in one word (CastVotes).
  std::vector<uint32_t> accumulator(model_points * static_cast<size_t>(angle_bins));
  std::vector<Eigen::Matrix3f> model_to_x(model_points);
  for (size_t m = 0; m < model_points; ++m) model_to_x[m] = ToXAxis(model.points()[m].normal);
  std::vector<Vote> votes;
  std::vector<Peak> peaks;
  const float squared_diameter = static_cast<float>(diameter * diameter);
  constexpr uint32_t kCount = 0xffffU;
  PpfSearchStats done;
  done.scene_points = scene.size();
  done.references = leaders.size();
  std::vector<Lookup> lookups;  // the reference point's table look-ups, reused
  for (const OrientedPoint& reference : leaders) {
    const Eigen::Matrix3f to_x = ToXAxis(reference.normal);
    std::fill(accumulator.begin(), accumulator.end(), 0U);
    lookups.clear();
    uint32_t pair = 0;
    grid.ForNear(reference.position, [&](int i) {
      // A reference point has a few thousand pairs at most (its sub-sampled neighbours within one diameter); any
      // beyond the 16-bit stamps do not vote.
      if (pair == kCount) return;
      const OrientedPoint& other = scene[static_cast<size_t>(i)];
      if ((other.position - reference.position).squaredNorm() > squared_diameter) return;
      float positions[4];
      if (!bins.Positions(reference, other, positions)) return;
      uint32_t keys[16];
      const int count = bins.Keys(positions, options.spread_votes, keys);
      const uint16_t alpha_scene = AlphaOf(to_x * (other.position - reference.position));
      ++pair;
      for (int k = 0; k < count; ++k) lookups.push_back({keys[k], alpha_scene, static_cast<uint16_t>(pair)});
    });
    done.entries += CastVotes(model, lookups, angle_bins, &accumulator);
    done.pairs += pair;
    // The reference point's best cells as poses: camera_from_object = T_s^-1 R_x(alpha) T_m.
    BestCells(accumulator, kCount, static_cast<size_t>(options.poses_per_reference), &peaks);
    for (const Peak& peak : peaks) {
      const size_t m = peak.cell / static_cast<size_t>(angle_bins);
      const double alpha =
          (static_cast<double>(peak.cell % static_cast<size_t>(angle_bins)) + 0.5) * 2.0 * kPi / angle_bins - kPi;
      const Eigen::Matrix3d rotation = to_x.transpose().cast<double>() *
                                       Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                                       model_to_x[m].cast<double>();
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.linear() = rotation;
      pose.translation() = reference.position.cast<double>() - rotation * model.points()[m].position.cast<double>();
      votes.push_back({pose, static_cast<double>(peak.votes)});
    }
  }
  if (stats != nullptr) *stats = done;
  return ClusterPoses(std::move(votes), diameter, options);
}

}  // namespace ecv
