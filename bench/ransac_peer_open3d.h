#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ransac_peer_pcl.h"
#include "registration/ransac.h"

namespace ecv::bench {

/// Settings of Open3D's registration_ransac_based_on_correspondence, run by bench/ransac_open3d.py.
struct Open3dRansacOptions {
  std::string python = "/usr/bin/python3";  ///< interpreter with Open3D (Debian 12: apt-get install python3-open3d)
  std::string script;                       ///< path of bench/ransac_open3d.py
  int runs = 100;                           ///< seeds 1..runs
  int max_iterations = 5000;
  double confidence = 1.0;                    ///< RANSACConvergenceCriteria's; 1: no early exit intended
  double max_correspondence_distance = 0.01;  ///< metres
  double similarity_threshold = 0.75;         ///< CorrespondenceCheckerBasedOnEdgeLength's
  int threads = 1;                            ///< OMP_NUM_THREADS
};

/// Writes `object_points` (a.txt), `scene_points` (b.txt) and `correspondences` (correspondences.txt, "i j")
/// into `directory` for ransac_open3d.py.
void WriteOpen3dInput(const std::vector<Eigen::Vector3f>& object_points,
                      const std::vector<Eigen::Vector3f>& scene_points,
                      const std::vector<Correspondence>& correspondences, const std::filesystem::path& directory);

/// Runs ransac_open3d.py on the input in `directory` (one process, all runs); one pose per run, or none
/// when Open3D is missing or the script failed, with the reason in `*problem`.
std::vector<PeerPose> RunOpen3dRansac(const std::filesystem::path& directory, const Open3dRansacOptions& options,
                                      std::string* problem);

}  // namespace ecv::bench
