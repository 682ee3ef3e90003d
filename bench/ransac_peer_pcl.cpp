// PCL's SampleConsensusPrerejective fed our correspondences (kept in this file: PCL stays here).

#include "ransac_peer_pcl.h"

#include <cstdlib>
#include <stdexcept>

#include <pcl/point_types.h>
#include <pcl/registration/sample_consensus_prerejective.h>

#include "bench_util.h"
#include "core/timing.h"

namespace ecv::bench {
namespace {

using Points = pcl::PointCloud<pcl::PointXYZ>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

Points::Ptr ToCloud(const std::vector<Eigen::Vector3f>& points) {
  Points::Ptr cloud(new Points);
  cloud->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) (*cloud)[i].getVector3fMap() = points[i];
  return cloud;
}

// A feature whose first bin is `label` and the other bins zero: equal labels are at distance 0,
// different ones at least 1 apart.
pcl::FPFHSignature33 Label(int label) {
  pcl::FPFHSignature33 feature;
  std::fill(std::begin(feature.histogram), std::end(feature.histogram), 0.0F);
  feature.histogram[0] = static_cast<float>(label);
  return feature;
}

}  // namespace

PeerPose RunPclPrerejective(const std::vector<Eigen::Vector3f>& object_points,
                            const std::vector<Eigen::Vector3f>& scene_points,
                            const std::vector<Correspondence>& correspondences, const PclPrerejectiveOptions& options,
                            unsigned seed) {
  if (correspondences.size() != object_points.size()) {
    throw std::invalid_argument("PCL feed: one correspondence per object point expected");
  }
  const Points::Ptr source = ToCloud(object_points), target = ToCloud(scene_points);
  Features::Ptr source_features(new Features), target_features(new Features);
  for (size_t i = 0; i < correspondences.size(); ++i) {
    if (correspondences[i].object != static_cast<int>(i)) {
      throw std::invalid_argument("PCL feed: correspondences[i].object == i expected");
    }
    source_features->push_back(Label(correspondences[i].scene));
  }
  for (size_t j = 0; j < scene_points.size(); ++j) target_features->push_back(Label(static_cast<int>(j)));

  PeerPose pose;
  const auto start = Clock::now();
  const double cpu_start = ProcessCpuMilliseconds();
  pcl::SampleConsensusPrerejective<pcl::PointXYZ, pcl::PointXYZ, pcl::FPFHSignature33> ransac;
  ransac.setInputSource(source);
  ransac.setSourceFeatures(source_features);
  ransac.setInputTarget(target);
  ransac.setTargetFeatures(target_features);
  ransac.setMaximumIterations(options.max_iterations);
  ransac.setNumberOfSamples(3);
  ransac.setCorrespondenceRandomness(1);
  ransac.setSimilarityThreshold(options.similarity_threshold);
  ransac.setMaxCorrespondenceDistance(options.max_correspondence_distance);
  ransac.setInlierFraction(options.inlier_fraction);
  std::srand(seed);
  Points aligned;
  ransac.align(aligned);
  pose.time_ms = MillisecondsSince(start);
  pose.cpu_ms = ProcessCpuMilliseconds() - cpu_start;
  pose.returned = ransac.hasConverged();
  pose.b_from_a.matrix() = ransac.getFinalTransformation().cast<double>();
  return pose;
}

}  // namespace ecv::bench
