// The OpenCV recognition peer: ppf_match_3d's PPF3DDetector (Drost et al., point pair features) per model on the
// whole scene, its best pose refined with ppf_match_3d's ICP (OpenCV's surface_matching stays in this file).

#include <algorithm>

#include <Eigen/SVD>

#include <opencv2/surface_matching.hpp>
#include <opencv2/surface_matching/ppf_helpers.hpp>

#include "bench_util.h"
#include "core/timing.h"
#include "recognition_peers.h"

namespace ecv::bench {
namespace {

// N x 6 CV_32F rows x y z nx ny nz (metres), as ppf_match_3d wants them.
cv::Mat PointNormalMat(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& normals) {
  cv::Mat mat(static_cast<int>(points.size()), normals.empty() ? 3 : 6, CV_32F);
  for (size_t i = 0; i < points.size(); ++i) {
    float* row = mat.ptr<float>(static_cast<int>(i));
    for (int k = 0; k < 3; ++k) row[k] = points[i][k];
    if (!normals.empty()) {
      for (int k = 0; k < 3; ++k) row[3 + k] = normals[i][k];
    }
  }
  return mat;
}

// The rigid transform nearest `pose`: OpenCV 4.6's PPF3DDetector averages the quaternions of a pose cluster
// without normalising them, so its poses come scaled (determinants of 0.03 to 0.4 seen); the rotation is
// replaced by the nearest one (SVD).
Eigen::Isometry3d ToIsometry(const cv::Matx44d& pose) {
  Eigen::Matrix3d linear;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) linear(r, c) = pose(r, c);
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(linear, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d flip = Eigen::Matrix3d::Identity();
  flip(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = svd.matrixU() * flip * svd.matrixV().transpose();
  isometry.translation() = Eigen::Vector3d(pose(0, 3), pose(1, 3), pose(2, 3));
  return isometry;
}

cv::Matx44d ToMatx(const Eigen::Isometry3d& isometry) {
  cv::Matx44d pose = cv::Matx44d::eye();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) pose(r, c) = isometry.matrix()(r, c);
  }
  return pose;
}

// Rows of the N x 6 `scene` within `radius_m` of `centre`.
cv::Mat Nearby(const cv::Mat& scene, const Eigen::Vector3d& centre, double radius_m) {
  cv::Mat nearby;
  for (int i = 0; i < scene.rows; ++i) {
    const float* row = scene.ptr<float>(i);
    if ((Eigen::Vector3d(row[0], row[1], row[2]) - centre).norm() < radius_m) nearby.push_back(scene.row(i));
  }
  return nearby;
}

class PpfPeer : public RecognitionPeer {
 public:
  PpfPeer(const std::vector<PeerModel>& models, const PeerOptions& options) : options_(options) {
    options_.Check();
    for (const PeerModel& model : models) {
      auto entry = std::make_unique<Model>();
      entry->name = model.name;
      entry->diameter_m = model.diameter_m;
      std::vector<Eigen::Vector3f> normals;
      VoxelDownsample(model.points, model.normals, options_.voxel_m, &entry->points, &normals);
      entry->cloud = PointNormalMat(entry->points, normals);
      entry->detector = std::make_unique<cv::ppf_match_3d::PPF3DDetector>(options_.ppf_relative_sampling,
                                                                          options_.ppf_relative_distance);
      entry->detector->trainModel(entry->cloud);
      models_.push_back(std::move(entry));
    }
  }

  PeerResult Recognize(const RgbdFrame& frame) override {
    PeerResult result;
    const auto start = Clock::now();
    const std::vector<Eigen::Vector3f> scene_points = SceneCloud(frame, options_.voxel_m);
    cv::Mat scene;
    cv::ppf_match_3d::computeNormalsPC3d(PointNormalMat(scene_points, {}), scene, options_.ppf_normal_neighbours, true,
                                         cv::Vec3f(0.0F, 0.0F, 0.0F));
    const RadiusGrid scene_grid(scene_points, static_cast<float>(options_.inlier_distance_m));
    result.scene_ms = MillisecondsSince(start);
    result.scene_points = static_cast<int>(scene_points.size());
    cv::ppf_match_3d::ICP icp(options_.icp_iterations, 0.005F, 2.5F, 8);
    for (const auto& model : models_) {
      std::vector<cv::ppf_match_3d::Pose3DPtr> poses;
      model->detector->match(scene, poses, options_.ppf_scene_sample_step, options_.ppf_scene_distance);
      if (poses.empty()) continue;
      poses.resize(1);  // the most voted pose cluster
      Detection detection;
      detection.model = model->name;
      detection.camera_from_object = ToIsometry(poses[0]->pose);
      cv::Matx44d rigid = ToMatx(detection.camera_from_object);
      poses[0]->updatePose(rigid);
      detection.inlier_fraction = InlierFraction(model->points, detection.camera_from_object, scene_grid);
      // ICP against the scene within one diameter of the pose (on the whole scene it drifts); its pose is kept
      // unless it lowers the inlier share.
      const cv::Mat nearby = Nearby(scene, detection.camera_from_object.translation(), model->diameter_m);
      if (nearby.rows >= 3) {
        icp.registerModelToScene(model->cloud, nearby, poses);
        const Eigen::Isometry3d refined = ToIsometry(poses[0]->pose);
        const double share = InlierFraction(model->points, refined, scene_grid);
        if (share >= detection.inlier_fraction) {
          detection.camera_from_object = refined;
          detection.inlier_fraction = share;
          detection.fit_error_m = poses[0]->residual;
        }
      }
      KeepIfAccepted(detection, options_, &result);
    }
    FinishPeerResult(start, &result);
    return result;
  }

 private:
  struct Model {
    std::string name;
    double diameter_m = 0.0;
    std::vector<Eigen::Vector3f> points;  // voxelised, object frame
    cv::Mat cloud;                        // the same with normals, N x 6
    std::unique_ptr<cv::ppf_match_3d::PPF3DDetector> detector;
  };

  PeerOptions options_;
  std::vector<std::unique_ptr<Model>> models_;
};

}  // namespace

std::unique_ptr<RecognitionPeer> MakePpfPeer(const std::vector<PeerModel>& models, const PeerOptions& options) {
  return std::make_unique<PpfPeer>(models, options);
}

}  // namespace ecv::bench
