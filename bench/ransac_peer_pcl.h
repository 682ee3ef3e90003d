#pragma once

#include <time.h>

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "registration/ransac.h"

namespace ecv::bench {

/// CPU time of the whole process (all its threads) so far, milliseconds: unlike wall time, it does not grow
/// when other programs share the cores.
inline double ProcessCpuMilliseconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

/// What one run of a peer RANSAC returned.
struct PeerPose {
  bool returned = false;  ///< the peer reports a pose (PCL: hasConverged())
  Eigen::Isometry3d b_from_a = Eigen::Isometry3d::Identity();
  double time_ms = 0.0;  ///< wall time of the peer's own work (set-up of its search trees and the RANSAC)
  double cpu_ms = 0.0;   ///< CPU time of the same
};

/// Settings of PCL's SampleConsensusPrerejective, matched to ours.
struct PclPrerejectiveOptions {
  int max_iterations = 5000;
  float similarity_threshold = 0.75F;         ///< edge-length similarity, 1 - t_poly
  float max_correspondence_distance = 0.01F;  ///< inlier distance, metres
  float inlier_fraction = 0.1F;               ///< of the source points
};

/// PCL's pcl::SampleConsensusPrerejective on exactly `correspondences` (object i -> scene j), which must
/// hold one correspondence per object point with correspondences[i].object == i. PCL matches features
/// itself, so each source point's feature is the index j of its scene partner and each target point's
/// feature its own index (FPFHSignature33, first bin): the nearest target feature of source point i is
/// then exactly j, and setCorrespondenceRandomness(1) takes it. Seeds std::rand with `seed` (PCL samples
/// with rand()).
PeerPose RunPclPrerejective(const std::vector<Eigen::Vector3f>& object_points,
                            const std::vector<Eigen::Vector3f>& scene_points,
                            const std::vector<Correspondence>& correspondences, const PclPrerejectiveOptions& options,
                            unsigned seed);

}  // namespace ecv::bench
