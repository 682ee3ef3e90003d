#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "registration/ransac.h"

namespace ecv::bench {

/// Two views of one scene with known relative pose, reduced to what every RANSAC of ransac_bench is fed:
/// the points of both frames and the nearest-neighbour correspondences A -> B, computed once.
struct RegistrationPair {
  std::string name;         ///< short, for table rows
  std::string description;  ///< how the pair was made, for the report
  /// Object side (frame A, camera frame, metres): the positions of A's primitives that got a match,
  /// so that correspondences[i].object == i (one correspondence per point, as PCL's feed needs).
  std::vector<Eigen::Vector3f> a_points;
  std::vector<Eigen::Vector3f> b_points;  ///< scene side: all of B's primitive positions, metres
  std::vector<Correspondence>
      correspondences;  ///< nearest ECV descriptor in B (exact search) of each described A primitive
  Eigen::Isometry3d b_from_a = Eigen::Isometry3d::Identity();  ///< ground truth, metres
  Eigen::Vector3d centre_a = Eigen::Vector3d::Zero();          ///< mean of a_points: translation errors are taken here
  int primitives_a = 0, primitives_b = 0;                      ///< ECV primitives extracted from each whole frame
  int true_correspondences = 0;                                ///< within 1 cm of their partner under b_from_a
  double extraction_ms = 0.0;                                  ///< primitives + descriptors of both frames + matching
};

/// Six YCB textured meshes (google_16k, in the YCB-Video frame) standing on a grey table as a cluster,
/// rendered with OSMesa from two cameras whose relative rotation is `baseline_deg` (azimuths apart about
/// the table normal, elevation 35 degrees, 0.8 m from the cluster), depth through SimulateStructuredLight.
RegistrationPair RenderedPair(const std::string& data_dir, double baseline_deg);

/// YCB-Video 0001 frame 1 (A) against frame 19 (B) with B's primitives moved by a rotation of
/// `rotation_deg` about the axis (0.3, 1, 0.2) through the centre of B's depth points (as the scene
/// registration test). Ground truth: the
/// camera motion T19 * T1^-1 of the first annotated object, composed with that rotation.
RegistrationPair RealPair(const std::string& data_dir, double rotation_deg);

}  // namespace ecv::bench
