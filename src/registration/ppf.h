#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "core/frame.h"
#include "core/mesh.h"
#include "registration/icp.h"

namespace ecv {

/// A surface point with its unit normal (facing out of the object, or towards the camera), metres.
struct OrientedPoint {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
};

/// Point pair features (Drost, Ulrich, Navab, Ilic, CVPR 2010) with refinements of Vidal, Lin, Llado and Marti
/// (Sensors 2018): sub-sampling that keeps points of differing normals, votes spread to the neighbouring feature
/// bins, each scene pair voting once per pose bin, and pose clustering. Steps are shares of the model's diameter.
struct PpfOptions {
  double sampling = 0.05;         ///< voxel of the model and scene sub-sampling, share of the diameter
  double distance_step = 0.05;    ///< feature distance bin, share of the diameter (Drost's tau_d)
  int angle_bins = 30;            ///< bins of each feature angle and of the rotation about the normal (12 degrees)
  double keep_normal_deg = 30.0;  ///< a voxel keeps a second point whose normal differs by more than this
  /// The same for the scene's voxels (180: one point per voxel; a depth image's normals are noisy).
  double scene_keep_normal_deg = 30.0;
  /// Reference points: the sub-sampled scene thinned again to one point per voxel of this (share of the diameter)
  /// and differing normal (scene_keep_normal_deg), an even cover of every surface.
  double reference_spacing = 0.3;
  /// At most this many of those reference points vote, evenly drawn (0: all): a quick vote, to rank models by.
  int max_references = 0;
  bool spread_votes = true;         ///< also look up the neighbouring bin of each feature value near a bin border
  double spread_margin = 0.15;      ///< ... "near": within this share of a bin from the border (0.5: always)
  int poses_per_reference = 3;      ///< the best poses of each reference point kept for clustering
  double cluster_distance = 0.1;    ///< poses closer than this (share of the diameter) ...
  double cluster_angle_deg = 30.0;  ///< ... and turned less than this join one cluster
  int max_poses = 20;               ///< clusters returned, most votes first
  /// Pairs of one plane (normals within this and both at 90 +- this degrees to the line between them) neither go
  /// into the table nor vote (0: all pairs): a table top or a box face alone gives thousands of them, all alike.
  double coplanar_deg = 12.0;

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// `points` sub-sampled on a voxel grid of `voxel_m`: per voxel the point nearest its centre, and another for each
/// normal more than `keep_normal_deg` from those kept (Vidal et al.: thin parts and edges keep both sides).
std::vector<OrientedPoint> SubsampleByNormals(const std::vector<OrientedPoint>& points, double voxel_m,
                                              double keep_normal_deg);

/// Points spread over a mesh's triangles, `count` of them in proportion to area (seeded), with the triangle's
/// normal (turned by the vertex normals' side when the mesh has them).
std::vector<OrientedPoint> SampleMeshSurface(const TriangleMesh& mesh, int count, uint64_t seed = 1);

/// A frame's depth samples every `stride` pixels with their normals (MakeOrganizedScene), turned towards the camera;
/// samples without a normal are left out.
std::vector<OrientedPoint> OrientedScenePoints(const RgbdFrame& frame, int stride);
/// The same of depth samples made already.
std::vector<OrientedPoint> OrientedScenePoints(const OrganizedScene& organized);

/// How a model's point pair points are drawn from its mesh. A library stores them with these settings; the
/// recognizer uses them when its PpfOptions sub-sample alike (PpfModelSampling::Of).
struct PpfModelSampling {
  int samples = 20000;            ///< points spread over the mesh by area (SampleMeshSurface, seed 1) ...
  double sampling = 0.05;         ///< ... then sub-sampled so (PpfOptions::sampling, share of the diameter)
  double keep_normal_deg = 30.0;  ///< PpfOptions::keep_normal_deg

  /// The settings that `options` sub-sample a model with, `samples` points spread before.
  static PpfModelSampling Of(const PpfOptions& options, int samples);
  bool operator==(const PpfModelSampling& other) const;

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// A model's point pair points (object frame, metres): its mesh sampled and sub-sampled as `sampling` says.
std::vector<OrientedPoint> SampleModelPoints(const TriangleMesh& mesh, const PpfModelSampling& sampling);

/// The largest plane of a scene (a table top, a floor), found by RANSAC on oriented points.
struct ScenePlaneOptions {
  double distance_m = 0.01;  ///< a point lies on the plane within this, metres ...
  double normal_deg = 25.0;  ///< ... with its normal within this of the plane's
  double min_share = 0.2;    ///< a plane is dominant when it holds at least this share of the points
  int iterations = 200;      ///< planes tried (seeded: the same points give the same plane)

  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// `points` without those of their dominant plane (ScenePlaneOptions), or all of them when no plane is. Pairs with a
/// table top's points describe no object on it, and they are most of a frame's points.
std::vector<OrientedPoint> WithoutDominantPlane(const std::vector<OrientedPoint>& points,
                                                const ScenePlaneOptions& options = {});

/// A model's point pair table: every ordered pair of its sub-sampled points by quantized feature.
class PpfModel {
 public:
  /// From the model's surface points (object frame) and its diameter (metres), sub-sampled as `options` say; throws
  /// InputError when fewer than 10 points remain, more than 65536 (a sampling too fine), or fewer than 100 pairs go
  /// into the table (a mesh too small, flat or coarse for point pairs).
  PpfModel(const std::vector<OrientedPoint>& surface, double diameter_m, const PpfOptions& options = {});

  /// From points sub-sampled already (SampleModelPoints, or a library's stored ones); the same refusals.
  static PpfModel FromSampledPoints(std::vector<OrientedPoint> points, double diameter_m,
                                    const PpfOptions& options = {});

  const std::vector<OrientedPoint>& points() const { return points_; }
  double diameter_m() const { return diameter_m_; }
  const PpfOptions& options() const { return options_; }
  size_t NumPairs() const { return pairs_; }

  /// The model reference point of a pair, and the angle about the reference normal that turns the pair's other
  /// point into the half-plane y >= 0, z = 0 of the reference's frame, as a turn share in 1/65536 (0: -pi): votes
  /// subtract such angles with wrap-around, in integers.
  struct Entry {
    uint16_t reference;  ///< at most 65536 points per model (PpfModel refuses more)
    uint16_t alpha;
  };
  /// The pairs with feature key `key`, as [begin, end).
  std::pair<const Entry*, const Entry*> Find(uint32_t key) const {
    if (key + 1 >= offsets_.size()) return {nullptr, nullptr};
    return {entries_.data() + offsets_[key], entries_.data() + offsets_[key + 1]};
  }
  /// Hints for a vote loop that looks keys up a few steps ahead: the key's offsets, then (once those are cached) its
  /// first entries, into the cache.
  void PrefetchOffsets(uint32_t key) const { __builtin_prefetch(offsets_.data() + key); }
  void PrefetchEntries(uint32_t key) const { __builtin_prefetch(entries_.data() + offsets_[key]); }

 private:
  PpfModel(std::vector<OrientedPoint> points, double diameter_m, const PpfOptions& options, bool sampled);

  std::vector<OrientedPoint> points_;
  double diameter_m_;
  PpfOptions options_;
  // The table: the entries of key k are entries_[offsets_[k], offsets_[k + 1]), one offset per possible key.
  std::vector<uint32_t> offsets_;
  std::vector<Entry> entries_;
  size_t pairs_ = 0;
};

/// A pose hypothesis of a model in a scene.
struct PpfPose {
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  double votes = 0.0;  ///< the cluster's votes
};

/// What one FindPpfPoses did: its work grows with references x pairs per reference x table entries per pair.
struct PpfSearchStats {
  size_t scene_points = 0;  ///< sub-sampled scene points, the explained ones included
  size_t references = 0;    ///< reference points that voted
  size_t pairs = 0;         ///< scene pairs looked up in the table
  size_t entries = 0;       ///< table entries voted for
};

/// The model's best pose clusters among `scene` points (camera frame, normals towards the camera), most votes first.
/// `explained` points (a surface a detection already accounts for) pair with the scene's but lead no vote as
/// reference points: fewer votes, and none for a pose that lies on that surface alone.
/// `stats`, when given, receives what the search did.
std::vector<PpfPose> FindPpfPoses(const PpfModel& model, const std::vector<OrientedPoint>& scene,
                                  const std::vector<OrientedPoint>& explained = {}, PpfSearchStats* stats = nullptr);

}  // namespace ecv
