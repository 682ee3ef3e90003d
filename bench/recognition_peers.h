#pragma once

// Whole-frame recognition peers for recognize_bench (issue 9): PCL's FPFH + SampleConsensusPrerejective + ICP,
// OpenCV's PPF detector (ppf_match_3d) + its ICP, and Open3D's FPFH + RANSAC + ICP recipe (through Python). They
// return detections like ours, so EvaluateFrame scores them alike. PCL and OpenCV's surface_matching stay in
// recognition_peer_pcl.cpp and recognition_peer_ppf.cpp; recognition_peer_open3d.cpp runs recognition_open3d.py.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/frame.h"
#include "core/point_index.h"
#include "core/timing.h"
#include "modeldb/model_record.h"
#include "recognize/recognizer.h"

namespace ecv::bench {

/// A model as the peers see it: points with outward normals sampled on its mesh surface.
struct PeerModel {
  std::string name;
  std::vector<Eigen::Vector3f> points;   ///< object frame, metres
  std::vector<Eigen::Vector3f> normals;  ///< unit, object frame (the sampled triangle's normal)
  double diameter_m = 0.0;
};

/// Points on the surface of `record`'s mesh (its unit and object_from_mesh applied), area-weighted random
/// sampling about `spacing_m` apart on average, with the triangles' normals. Same seed, same points.
/// Throws InputError when the mesh cannot be loaded.
PeerModel SamplePeerModel(const ModelRecord& record, double spacing_m = 0.002, unsigned seed = 1);

/// Settings of both peers (metres; fractions in [0, 1]).
struct PeerOptions {
  double voxel_m = 0.005;                 ///< voxel grid of the model and scene clouds, both peers
  double normal_radius_m = 0.01;          ///< PCL normal estimation radius
  double fpfh_radius_m = 0.025;           ///< PCL FPFH radius
  int pcl_iterations = 50000;             ///< SampleConsensusPrerejective iterations per model
  int pcl_correspondence_randomness = 5;  ///< nearest FPFH neighbours a sample picks from
  double pcl_similarity = 0.9;            ///< edge-length similarity of the prerejection (1 - t_poly)
  int icp_iterations = 30;                ///< PCL ICP iterations; OpenCV ICP iterations; Open3D ICP iterations
  int open3d_iterations = 100000;         ///< Open3D feature RANSAC: iterations at most (its recipe's)
  double open3d_confidence = 0.999;       ///< Open3D feature RANSAC: early exit (its recipe's)
  /// PPF3DDetector model sampling step, relative to the model's box (the usual 0.05 trains for minutes: OpenCV's
  /// hash table walks the chain of equal keys on every insert).
  double ppf_relative_sampling = 0.08;
  double ppf_relative_distance = 0.05;      ///< PPF3DDetector pair-distance step, relative to the diameter
  double ppf_scene_sample_step = 1.0 / 40;  ///< share of the sampled scene points used as reference points
  double ppf_scene_distance = 0.015;        ///< scene sampling step, relative to the scene's box
  int ppf_normal_neighbours = 10;           ///< computeNormalsPC3d neighbours
  /// Both peers: a model is reported when, after ICP, at least this share of its (voxelised) points lies
  /// within `inlier_distance_m` of a scene point (the visible side of a model is about half of it).
  double inlier_distance_m = 0.01;
  double min_inlier_fraction = 0.25;
  unsigned seed = 1;  ///< PCL samples with std::rand(): seeded per model with this

  /// Throws InputError naming the field when a value is out of range.
  void Check() const;
};

/// Detections of one frame (at most one per model) and the wall time of the whole frame.
struct PeerResult {
  std::vector<Detection> detections;
  double time_ms = 0.0;   ///< everything for the frame: scene cloud, features, all models
  double scene_ms = 0.0;  ///< of which the scene cloud, normals and features
  int scene_points = 0;   ///< points of the (voxelised) scene cloud
};

/// A whole-frame recognizer over a fixed list of models (no masks, no ground truth).
class RecognitionPeer {
 public:
  virtual ~RecognitionPeer() = default;
  virtual PeerResult Recognize(const RgbdFrame& frame) = 0;
};

/// PCL: FPFH on model and scene, SampleConsensusPrerejective, then IterativeClosestPoint.
std::unique_ptr<RecognitionPeer> MakePclPeer(const std::vector<PeerModel>& models, const PeerOptions& options);

/// OpenCV: PPF3DDetector trained per model (when made), matched on the scene, the best pose refined by its ICP.
std::unique_ptr<RecognitionPeer> MakePpfPeer(const std::vector<PeerModel>& models, const PeerOptions& options);

/// Open3D's global registration recipe (FPFH, registration_ransac_based_on_feature_matching, point-to-plane ICP)
/// through `script` (bench/recognition_open3d.py) under `python`, one process per frame, one OpenMP thread. The
/// frame's time is the script's: the scene's cloud and features and every model's RANSAC and ICP (not the process
/// start nor the models' features). nullptr, with the reason in `*problem`, when Open3D cannot be imported.
std::unique_ptr<RecognitionPeer> MakeOpen3dPeer(const std::vector<PeerModel>& models, const PeerOptions& options,
                                                const std::string& python, const std::string& script,
                                                std::string* problem);

// Shared by both peers (recognition_peers.cpp).

/// Camera-frame points of every valid depth pixel, averaged per `voxel_m` voxel (0: no voxel grid).
std::vector<Eigen::Vector3f> SceneCloud(const RgbdFrame& frame, double voxel_m);

/// Points (and normals, renormalised) averaged per `voxel_m` voxel.
void VoxelDownsample(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& normals,
                     double voxel_m, std::vector<Eigen::Vector3f>* out_points,
                     std::vector<Eigen::Vector3f>* out_normals);

/// Adds `detection` to `result` when its score (its inlier fraction) reaches the options' minimum.
void KeepIfAccepted(Detection detection, const PeerOptions& options, PeerResult* result);

/// Sorts the result's detections best first and stamps the frame's time since `start`.
void FinishPeerResult(Clock::time_point start, PeerResult* result);

/// Share of `object_points` that lie, under `camera_from_object`, within the grid's radius of a scene point.
double InlierFraction(const std::vector<Eigen::Vector3f>& object_points, const Eigen::Isometry3d& camera_from_object,
                      const RadiusGrid& scene);

}  // namespace ecv::bench
