// The PCL recognition peer: FPFH on model and whole scene, SampleConsensusPrerejective (the paper's algorithm as
// PCL ships it), IterativeClosestPoint (PCL stays in this file).

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/sample_consensus_prerejective.h>

#include "bench_util.h"
#include "core/timing.h"
#include "recognition_peers.h"

namespace ecv::bench {
namespace {

using Cloud = pcl::PointCloud<pcl::PointNormal>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

struct Described {
  Cloud::Ptr cloud{new Cloud};
  Features::Ptr features{new Features};
};

// PCL normals (radius `normal_radius_m`; flipped towards the camera at the origin, or to agree with
// `orientation` when given) and FPFH; points whose normal or feature is not finite are dropped. One thread.
Described Describe(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& orientation,
                   const PeerOptions& options) {
  Cloud::Ptr cloud(new Cloud);
  cloud->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) (*cloud)[i].getVector3fMap() = points[i];
  pcl::NormalEstimationOMP<pcl::PointNormal, pcl::PointNormal> normals;
  normals.setNumberOfThreads(1);
  normals.setRadiusSearch(options.normal_radius_m);
  normals.setInputCloud(cloud);
  normals.compute(*cloud);
  Cloud::Ptr valid(new Cloud);
  for (size_t i = 0; i < cloud->size(); ++i) {
    pcl::PointNormal point = (*cloud)[i];
    if (!std::isfinite(point.normal_x) || !std::isfinite(point.normal_y) || !std::isfinite(point.normal_z)) continue;
    if (!orientation.empty() && point.getNormalVector3fMap().dot(orientation[i]) < 0.0F) {
      point.getNormalVector3fMap() *= -1.0F;
    }
    valid->push_back(point);
  }
  Features::Ptr features(new Features);
  pcl::FPFHEstimationOMP<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> fpfh;
  fpfh.setNumberOfThreads(1);
  fpfh.setRadiusSearch(options.fpfh_radius_m);
  fpfh.setInputCloud(valid);
  fpfh.setInputNormals(valid);
  fpfh.compute(*features);
  Described described;
  for (size_t i = 0; i < valid->size(); ++i) {
    if (!std::isfinite((*features)[i].histogram[0])) continue;
    described.cloud->push_back((*valid)[i]);
    described.features->push_back((*features)[i]);
  }
  return described;
}

class PclPeer : public RecognitionPeer {
 public:
  PclPeer(const std::vector<PeerModel>& models, const PeerOptions& options) : options_(options) {
    options_.Check();
    for (const PeerModel& model : models) {
      Model entry;
      entry.name = model.name;
      std::vector<Eigen::Vector3f> normals;
      VoxelDownsample(model.points, model.normals, options_.voxel_m, &entry.points, &normals);
      entry.described = Describe(entry.points, normals, options_);
      models_.push_back(std::move(entry));
    }
  }

  PeerResult Recognize(const RgbdFrame& frame) override {
    PeerResult result;
    const auto start = Clock::now();
    const std::vector<Eigen::Vector3f> scene_points = SceneCloud(frame, options_.voxel_m);
    const Described scene = Describe(scene_points, {}, options_);
    const RadiusGrid scene_grid(scene_points, static_cast<float>(options_.inlier_distance_m));
    result.scene_ms = MillisecondsSince(start);
    result.scene_points = static_cast<int>(scene_points.size());
    for (const Model& model : models_) {
      Detection detection;
      if (Align(model, scene, &detection)) {
        detection.inlier_fraction = InlierFraction(model.points, detection.camera_from_object, scene_grid);
        KeepIfAccepted(detection, options_, &result);
      }
    }
    FinishPeerResult(start, &result);
    return result;
  }

 private:
  struct Model {
    std::string name;
    std::vector<Eigen::Vector3f> points;  // voxelised, object frame
    Described described;
  };

  // Prerejective RANSAC on FPFH matches, then ICP; false when PCL reports no alignment.
  bool Align(const Model& model, const Described& scene, Detection* detection) const {
    if (model.described.cloud->size() < 3 || scene.cloud->size() < 3) return false;
    pcl::SampleConsensusPrerejective<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> ransac;
    ransac.setInputSource(model.described.cloud);
    ransac.setSourceFeatures(model.described.features);
    ransac.setInputTarget(scene.cloud);
    ransac.setTargetFeatures(scene.features);
    ransac.setMaximumIterations(options_.pcl_iterations);
    ransac.setNumberOfSamples(3);
    ransac.setCorrespondenceRandomness(options_.pcl_correspondence_randomness);
    ransac.setSimilarityThreshold(static_cast<float>(options_.pcl_similarity));
    ransac.setMaxCorrespondenceDistance(options_.inlier_distance_m);
    ransac.setInlierFraction(static_cast<float>(options_.min_inlier_fraction));
    std::srand(options_.seed);
    Cloud aligned;
    ransac.align(aligned);
    if (!ransac.hasConverged()) return false;
    pcl::IterativeClosestPoint<pcl::PointNormal, pcl::PointNormal> icp;
    icp.setInputSource(model.described.cloud);
    icp.setInputTarget(scene.cloud);
    icp.setMaxCorrespondenceDistance(options_.inlier_distance_m);
    icp.setMaximumIterations(options_.icp_iterations);
    icp.align(aligned, ransac.getFinalTransformation());
    const Eigen::Matrix4f camera_from_object =
        icp.hasConverged() ? icp.getFinalTransformation() : ransac.getFinalTransformation();
    detection->model = model.name;
    detection->camera_from_object.matrix() = camera_from_object.cast<double>();
    detection->fit_error_m = std::sqrt(icp.getFitnessScore(options_.inlier_distance_m * options_.inlier_distance_m));
    return true;
  }

  PeerOptions options_;
  std::vector<Model> models_;
};

}  // namespace

std::unique_ptr<RecognitionPeer> MakePclPeer(const std::vector<PeerModel>& models, const PeerOptions& options) {
  return std::make_unique<PclPeer>(models, options);
}

}  // namespace ecv::bench
