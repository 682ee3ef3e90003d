// PCL's FPFH, SHOT, colour SHOT and spin images at given keypoints (kept in this file: PCL feature
// headers are slow to compile).

#include <cmath>

#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/features/shot_omp.h>
#include <pcl/features/spin_image.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>

#include "peer_descriptors.h"

namespace ecv::bench {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;
using Normals = pcl::PointCloud<pcl::Normal>;

Cloud::Ptr SupportCloud(const RgbdFrame& frame, const cv::Mat& mask) {
  Cloud::Ptr cloud(new Cloud);
  for (int v = 0; v < frame.depth.rows; ++v) {
    for (int u = 0; u < frame.depth.cols; ++u) {
      const float z = frame.depth.at<float>(v, u);
      if (z <= 0.0F || (!mask.empty() && mask.at<uchar>(v, u) == 0)) continue;
      const Eigen::Vector3d p = frame.camera.BackProject(Eigen::Vector2d(u, v), z);
      pcl::PointXYZRGBA point;
      point.x = static_cast<float>(p.x());
      point.y = static_cast<float>(p.y());
      point.z = static_cast<float>(p.z());
      const cv::Vec3b& c = frame.color.at<cv::Vec3b>(v, u);
      point.r = c[0];
      point.g = c[1];
      point.b = c[2];
      point.a = 255;
      cloud->push_back(point);
    }
  }
  // Voxelised at 4 mm as in PCL's recognition tutorials: full-resolution support makes FPFH quadratic.
  Cloud::Ptr voxelised(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZRGBA> grid;
  grid.setInputCloud(cloud);
  grid.setLeafSize(0.004F, 0.004F, 0.004F);
  grid.filter(*voxelised);
  return voxelised;
}

Cloud::Ptr KeypointCloud(const std::vector<Eigen::Vector3f>& keypoints) {
  Cloud::Ptr cloud(new Cloud);
  for (const Eigen::Vector3f& k : keypoints) {
    pcl::PointXYZRGBA point;
    point.getVector3fMap() = k;
    cloud->push_back(point);
  }
  return cloud;
}

// Normals of `cloud` over `radius_m` of `surface`, oriented towards the camera at the origin.
Normals::Ptr EstimateNormals(const Cloud::Ptr& cloud, const Cloud::Ptr& surface, double radius_m) {
  pcl::NormalEstimationOMP<pcl::PointXYZRGBA, pcl::Normal> estimation(2);
  estimation.setInputCloud(cloud);
  estimation.setSearchSurface(surface);
  estimation.setRadiusSearch(radius_m);
  estimation.setViewPoint(0.0F, 0.0F, 0.0F);
  Normals::Ptr normals(new Normals);
  estimation.compute(*normals);
  return normals;
}

template <typename Histogram>
void CopyRows(const pcl::PointCloud<Histogram>& histograms, int size, KeypointDescriptors* out,
              const float* (*data)(const Histogram&)) {
  out->values.create(static_cast<int>(histograms.size()), size, CV_32F);
  out->valid.assign(histograms.size(), true);
  for (size_t i = 0; i < histograms.size(); ++i) {
    const float* values = data(histograms[i]);
    float* row = out->values.ptr<float>(static_cast<int>(i));
    for (int k = 0; k < size; ++k) {
      row[k] = values[k];
      if (!std::isfinite(values[k])) out->valid[i] = false;
    }
    if (!out->valid[i]) std::fill(row, row + size, 0.0F);
  }
}

template <typename Estimation, typename Histogram>
pcl::PointCloud<Histogram> Run(Estimation& estimation, const Cloud::Ptr& keypoints, const Cloud::Ptr& surface,
                               const Normals::Ptr& normals, double radius_m) {
  estimation.setInputCloud(keypoints);
  estimation.setSearchSurface(surface);
  estimation.setInputNormals(normals);
  estimation.setRadiusSearch(radius_m);
  pcl::PointCloud<Histogram> histograms;
  estimation.compute(histograms);
  return histograms;
}

}  // namespace

const char* ToString(PclDescriptor descriptor) {
  switch (descriptor) {
    case PclDescriptor::kFpfh: return "FPFH (PCL)";
    case PclDescriptor::kShot: return "SHOT (PCL)";
    case PclDescriptor::kShotColor: return "colour SHOT (PCL)";
    case PclDescriptor::kSpinImage: return "spin image (PCL)";
  }
  return "?";
}

KeypointDescriptors ComputePclDescriptors(const RgbdFrame& frame, const cv::Mat& support_mask,
                                          const std::vector<Eigen::Vector3f>& keypoints, PclDescriptor descriptor,
                                          double radius_m) {
  KeypointDescriptors out;
  out.positions = keypoints;
  const Cloud::Ptr surface = SupportCloud(frame, support_mask);
  const Cloud::Ptr keypoint_cloud = KeypointCloud(keypoints);
  if (keypoints.empty() || surface->empty()) return out;
  const Normals::Ptr surface_normals = EstimateNormals(surface, surface, 0.01);
  switch (descriptor) {
    case PclDescriptor::kFpfh: {
      pcl::FPFHEstimationOMP<pcl::PointXYZRGBA, pcl::Normal, pcl::FPFHSignature33> estimation(2);
      const auto histograms = Run<decltype(estimation), pcl::FPFHSignature33>(estimation, keypoint_cloud, surface,
                                                                              surface_normals, radius_m);
      CopyRows<pcl::FPFHSignature33>(histograms, 33, &out,
                                     [](const pcl::FPFHSignature33& h) -> const float* { return h.histogram; });
      break;
    }
    case PclDescriptor::kShot: {
      pcl::SHOTEstimationOMP<pcl::PointXYZRGBA, pcl::Normal, pcl::SHOT352> estimation(2);
      const auto histograms =
          Run<decltype(estimation), pcl::SHOT352>(estimation, keypoint_cloud, surface, surface_normals, radius_m);
      CopyRows<pcl::SHOT352>(histograms, 352, &out, [](const pcl::SHOT352& h) -> const float* { return h.descriptor; });
      break;
    }
    case PclDescriptor::kShotColor: {
      pcl::SHOTColorEstimationOMP<pcl::PointXYZRGBA, pcl::Normal, pcl::SHOT1344> estimation(true, true, 2);
      const auto histograms =
          Run<decltype(estimation), pcl::SHOT1344>(estimation, keypoint_cloud, surface, surface_normals, radius_m);
      CopyRows<pcl::SHOT1344>(histograms, 1344, &out,
                              [](const pcl::SHOT1344& h) -> const float* { return h.descriptor; });
      break;
    }
    case PclDescriptor::kSpinImage: {
      // Spin images need the keypoints' own normals.
      const Normals::Ptr keypoint_normals = EstimateNormals(keypoint_cloud, surface, 0.01);
      pcl::SpinImageEstimation<pcl::PointXYZRGBA, pcl::Normal, pcl::Histogram<153>> estimation(
          8, 0.0, 0);  // no support angle: PCL 1.13 indexes input normals by surface indices there
      estimation.setInputCloud(keypoint_cloud);
      estimation.setInputNormals(keypoint_normals);
      estimation.setSearchSurface(surface);
      estimation.setRadiusSearch(radius_m);
      pcl::PointCloud<pcl::Histogram<153>> histograms;
      estimation.compute(histograms);
      CopyRows<pcl::Histogram<153>>(histograms, 153, &out,
                                    [](const pcl::Histogram<153>& h) -> const float* { return h.histogram; });
      break;
    }
  }
  return out;
}

}  // namespace ecv::bench
