// What both recognition peers share: model points sampled on the mesh, the scene cloud from depth, voxel grids and
// the inlier share that decides whether a model is reported.

#include "recognition_peers.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_map>

#include "core/error.h"
#include "modeldb/model_record.h"

namespace ecv::bench {
namespace {

// Voxel key of a point for a grid of `voxel_m` cells (21 bits per axis: +-10 km at 5 mm).
int64_t VoxelKey(const Eigen::Vector3f& point, double voxel_m) {
  const auto cell = [&](float value) {
    return static_cast<int64_t>(std::floor(static_cast<double>(value) / voxel_m)) + (int64_t{1} << 20);
  };
  return (cell(point.x()) << 42) | (cell(point.y()) << 21) | cell(point.z());
}

struct Triangle {
  Eigen::Vector3f a, b, c, normal;
};

// The mesh's triangles with unit normals: by winding, flipped to agree with the vertex normals where there are.
std::vector<Triangle> Triangles(const TriangleMesh& mesh) {
  std::vector<Triangle> triangles;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3i& t : part.triangles) {
      Triangle triangle{part.positions[static_cast<size_t>(t[0])], part.positions[static_cast<size_t>(t[1])],
                        part.positions[static_cast<size_t>(t[2])], Eigen::Vector3f::Zero()};
      triangle.normal = (triangle.b - triangle.a).cross(triangle.c - triangle.a);
      if (triangle.normal.norm() <= 0.0F) continue;
      triangle.normal.normalize();
      if (!part.normals.empty()) {
        const Eigen::Vector3f vertex_normals = part.normals[static_cast<size_t>(t[0])] +
                                               part.normals[static_cast<size_t>(t[1])] +
                                               part.normals[static_cast<size_t>(t[2])];
        if (vertex_normals.dot(triangle.normal) < 0.0F) triangle.normal = -triangle.normal;
      }
      triangles.push_back(triangle);
    }
  }
  return triangles;
}

}  // namespace

void PeerOptions::Check() const {
  const auto positive = [](double value, const char* field, const char* expected) {
    if (!(value > 0.0)) ThrowInputError("PeerOptions", field, expected, std::to_string(value));
  };
  positive(voxel_m, "voxel_m", "a voxel size > 0 m");
  positive(normal_radius_m, "normal_radius_m", "a radius > 0 m");
  positive(fpfh_radius_m, "fpfh_radius_m", "a radius > 0 m");
  positive(pcl_iterations, "pcl_iterations", "a number of iterations > 0");
  positive(pcl_correspondence_randomness, "pcl_correspondence_randomness", "a number of neighbours > 0");
  positive(icp_iterations, "icp_iterations", "a number of iterations > 0");
  positive(open3d_iterations, "open3d_iterations", "a number of iterations > 0");
  positive(ppf_normal_neighbours, "ppf_normal_neighbours", "a number of neighbours > 0");
  positive(inlier_distance_m, "inlier_distance_m", "a distance > 0 m");
  const auto fraction = [](double value, const char* field) {
    if (!(value > 0.0 && value <= 1.0))
      ThrowInputError("PeerOptions", field, "a value in (0, 1]", std::to_string(value));
  };
  fraction(pcl_similarity, "pcl_similarity");
  fraction(ppf_relative_sampling, "ppf_relative_sampling");
  fraction(ppf_relative_distance, "ppf_relative_distance");
  fraction(ppf_scene_sample_step, "ppf_scene_sample_step");
  fraction(ppf_scene_distance, "ppf_scene_distance");
  fraction(min_inlier_fraction, "min_inlier_fraction");
  fraction(open3d_confidence, "open3d_confidence");
}

PeerModel SamplePeerModel(const ModelRecord& record, double spacing_m, unsigned seed) {
  if (!(spacing_m > 0.0)) ThrowInputError("SamplePeerModel", "spacing_m", "a spacing > 0 m", std::to_string(spacing_m));
  const std::vector<Triangle> triangles = Triangles(ModelMesh(record, /*with_textures=*/false));
  if (triangles.empty()) ThrowInputError(record.name, "triangles", "a mesh with triangles of non-zero area");
  std::vector<double> cumulative_area;
  double area = 0.0;
  for (const Triangle& t : triangles) {
    area += 0.5 * static_cast<double>((t.b - t.a).cross(t.c - t.a).norm());
    cumulative_area.push_back(area);
  }
  const size_t count = std::max<size_t>(100, static_cast<size_t>(area / (spacing_m * spacing_m)));
  PeerModel model;
  model.name = record.name;
  model.diameter_m = record.diameter_m;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (size_t i = 0; i < count; ++i) {
    const size_t k = std::min(
        triangles.size() - 1,
        static_cast<size_t>(std::upper_bound(cumulative_area.begin(), cumulative_area.end(), uniform(random) * area) -
                            cumulative_area.begin()));
    const double r1 = std::sqrt(uniform(random)), r2 = uniform(random);  // uniform on the triangle
    const Triangle& t = triangles[k];
    model.points.push_back((static_cast<float>(1.0 - r1) * t.a + static_cast<float>(r1 * (1.0 - r2)) * t.b +
                            static_cast<float>(r1 * r2) * t.c));
    model.normals.push_back(t.normal);
  }
  return model;
}

void VoxelDownsample(const std::vector<Eigen::Vector3f>& points, const std::vector<Eigen::Vector3f>& normals,
                     double voxel_m, std::vector<Eigen::Vector3f>* out_points,
                     std::vector<Eigen::Vector3f>* out_normals) {
  std::unordered_map<int64_t, size_t> voxel_of;
  std::vector<Eigen::Vector3f> sums, normal_sums;
  std::vector<int> counts;
  for (size_t i = 0; i < points.size(); ++i) {
    const auto [found, inserted] = voxel_of.emplace(VoxelKey(points[i], voxel_m), sums.size());
    if (inserted) {
      sums.push_back(Eigen::Vector3f::Zero());
      normal_sums.push_back(Eigen::Vector3f::Zero());
      counts.push_back(0);
    }
    sums[found->second] += points[i];
    if (!normals.empty()) normal_sums[found->second] += normals[i];
    ++counts[found->second];
  }
  out_points->clear();
  if (out_normals != nullptr) out_normals->clear();
  for (size_t v = 0; v < sums.size(); ++v) {
    out_points->push_back(sums[v] / static_cast<float>(counts[v]));
    if (out_normals != nullptr && !normals.empty()) out_normals->push_back(normal_sums[v].normalized());
  }
}

std::vector<Eigen::Vector3f> SceneCloud(const RgbdFrame& frame, double voxel_m) {
  std::vector<Eigen::Vector3f> points;
  for (int v = 0; v < frame.depth.rows; ++v) {
    const float* row = frame.depth.ptr<float>(v);
    for (int u = 0; u < frame.depth.cols; ++u) {
      if (row[u] > 0.0F) points.push_back(frame.camera.BackProject(Eigen::Vector2d(u, v), row[u]).cast<float>());
    }
  }
  if (voxel_m <= 0.0) return points;
  std::vector<Eigen::Vector3f> voxelised;
  VoxelDownsample(points, {}, voxel_m, &voxelised, nullptr);
  return voxelised;
}

void KeepIfAccepted(Detection detection, const PeerOptions& options, PeerResult* result) {
  detection.score = detection.inlier_fraction;
  if (detection.inlier_fraction >= options.min_inlier_fraction) result->detections.push_back(detection);
}

void FinishPeerResult(Clock::time_point start, PeerResult* result) {
  std::sort(result->detections.begin(), result->detections.end(),
            [](const Detection& a, const Detection& b) { return a.score > b.score; });
  result->time_ms = MillisecondsSince(start);
}

double InlierFraction(const std::vector<Eigen::Vector3f>& object_points, const Eigen::Isometry3d& camera_from_object,
                      const RadiusGrid& scene) {
  if (object_points.empty()) return 0.0;
  const Eigen::Isometry3f transform = camera_from_object.cast<float>();
  size_t inliers = 0;
  for (const Eigen::Vector3f& point : object_points)
    inliers += scene.NearestWithin(transform * point).first >= 0 ? 1 : 0;
  return static_cast<double>(inliers) / static_cast<double>(object_points.size());
}

}  // namespace ecv::bench
