#include "core/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

namespace ecv {

const char* ToString(MeshColoring coloring) {
  switch (coloring) {
    case MeshColoring::kTexture: return "texture";
    case MeshColoring::kVertexColor: return "vertex colour";
    case MeshColoring::kMaterialColor: return "material colour";
  }
  return "unknown";
}

size_t TriangleMesh::NumVertices() const {
  size_t count = 0;
  for (const MeshPart& part : parts) count += part.positions.size();
  return count;
}

size_t TriangleMesh::NumTriangles() const {
  size_t count = 0;
  for (const MeshPart& part : parts) count += part.triangles.size();
  return count;
}

MeshColoring TriangleMesh::Coloring(const MeshPart& part) const {
  const bool has_texture = part.material >= 0 && part.material < static_cast<int>(materials.size()) &&
                           !materials[static_cast<size_t>(part.material)].texture.empty();
  if (has_texture && !part.texcoords.empty()) return MeshColoring::kTexture;
  if (!part.colors.empty()) return MeshColoring::kVertexColor;
  return MeshColoring::kMaterialColor;
}

Eigen::AlignedBox3d TriangleMesh::BoundingBox() const {
  Eigen::AlignedBox3d box;
  for (const MeshPart& part : parts) {
    for (const Eigen::Vector3f& p : part.positions) box.extend(p.cast<double>());
  }
  return box;
}

PrincipalBox TriangleMesh::PrincipalAxesBox() const {
  PrincipalBox box;
  const size_t count = NumVertices();
  if (count == 0) return box;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const MeshPart& part : parts) {
    for (const Eigen::Vector3f& p : part.positions) mean += p.cast<double>();
  }
  mean /= static_cast<double>(count);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const MeshPart& part : parts) {
    for (const Eigen::Vector3f& p : part.positions) {
      const Eigen::Vector3d d = p.cast<double>() - mean;
      scatter += d * d.transpose();
    }
  }
  box.axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors();
  Eigen::AlignedBox3d along;  // the vertices in the axes' frame
  for (const MeshPart& part : parts) {
    for (const Eigen::Vector3f& p : part.positions) along.extend(box.axes.transpose() * p.cast<double>());
  }
  box.centre = box.axes * along.center();
  box.half_sizes = 0.5 * along.sizes();
  return box;
}

double TriangleMesh::Diameter() const {
  std::vector<Eigen::Vector3d> points;
  points.reserve(NumVertices());
  for (const MeshPart& part : parts) {
    for (const Eigen::Vector3f& p : part.positions) points.push_back(p.cast<double>());
  }
  if (points.size() < 2) return 0.0;

  // Exact search with pruning: |p_i - p_j| <= r_i + r_j with r the distance to the box centre, so with
  // points sorted by r (largest first) both loops stop once r_i + r_j cannot beat the best pair.
  const Eigen::Vector3d centre = BoundingBox().center();
  std::vector<double> radius(points.size());
  for (size_t i = 0; i < points.size(); ++i) radius[i] = (points[i] - centre).norm();
  std::vector<size_t> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return radius[a] > radius[b]; });

  double best_squared = 0.0;
  for (size_t a = 0; a < order.size(); ++a) {
    const size_t i = order[a];
    const double bound = radius[i] + radius[order[0]];
    if (bound * bound <= best_squared) break;
    for (size_t b = a + 1; b < order.size(); ++b) {
      const size_t j = order[b];
      const double pair_bound = radius[i] + radius[j];
      if (pair_bound * pair_bound <= best_squared) break;
      best_squared = std::max(best_squared, (points[i] - points[j]).squaredNorm());
    }
  }
  return std::sqrt(best_squared);
}

cv::Mat CapTextureSize(const cv::Mat& texture, int max_side) {
  const int longest = std::max(texture.cols, texture.rows);
  if (max_side <= 0 || longest <= max_side) return texture;
  const double scale = static_cast<double>(max_side) / longest;
  cv::Mat capped;
  cv::resize(texture, capped, cv::Size(), scale, scale, cv::INTER_AREA);
  return capped;
}

bool TriangleMesh::IsClosedOutward() const {
  // Vertices by position, numbered in sorted order: a seam's copies of a vertex become one.
  std::vector<std::pair<std::array<float, 3>, size_t>> positions;  // (position, index over all parts)
  for (const MeshPart& part : parts) {
    for (const Eigen::Vector3f& p : part.positions) positions.push_back({{p.x(), p.y(), p.z()}, positions.size()});
  }
  std::sort(positions.begin(), positions.end());
  std::vector<uint32_t> id_of(positions.size());
  uint32_t id = 0;
  for (size_t i = 0; i < positions.size(); ++i) {
    if (i > 0 && positions[i].first != positions[i - 1].first) ++id;
    id_of[positions[i].second] = id;
  }
  // Every directed edge (from, to) of every triangle, and the same edges reversed: closed when the two multisets
  // are equal (each edge run through as often in one direction as in the other).
  std::vector<uint64_t> edges, reversed;
  double volume6 = 0.0;  // 6 x the signed volume enclosed
  size_t first = 0;      // of the part's vertices in id_of
  for (const MeshPart& part : parts) {
    for (const Eigen::Vector3i& triangle : part.triangles) {
      const uint64_t corner[3] = {id_of[first + static_cast<size_t>(triangle.x())],
                                  id_of[first + static_cast<size_t>(triangle.y())],
                                  id_of[first + static_cast<size_t>(triangle.z())]};
      if (corner[0] == corner[1] || corner[1] == corner[2] || corner[0] == corner[2]) continue;  // covers nothing
      for (int k = 0; k < 3; ++k) {
        edges.push_back(corner[k] << 32 | corner[(k + 1) % 3]);
        reversed.push_back(corner[(k + 1) % 3] << 32 | corner[k]);
      }
      const Eigen::Vector3d p = part.positions[static_cast<size_t>(triangle.x())].cast<double>();
      const Eigen::Vector3d q = part.positions[static_cast<size_t>(triangle.y())].cast<double>();
      const Eigen::Vector3d r = part.positions[static_cast<size_t>(triangle.z())].cast<double>();
      volume6 += p.dot(q.cross(r));
    }
    first += part.positions.size();
  }
  if (edges.empty()) return false;
  std::sort(edges.begin(), edges.end());
  std::sort(reversed.begin(), reversed.end());
  return edges == reversed && volume6 > 0.0;
}

void TriangleMesh::Transform(const Eigen::Isometry3d& new_from_old) {
  const Eigen::Matrix3f rotation = new_from_old.linear().cast<float>();
  const Eigen::Vector3f translation = new_from_old.translation().cast<float>();
  for (MeshPart& part : parts) {
    for (Eigen::Vector3f& p : part.positions) p = rotation * p + translation;
    for (Eigen::Vector3f& n : part.normals) n = rotation * n;
  }
}

void TriangleMesh::Scale(double factor) {
  for (MeshPart& part : parts) {
    for (Eigen::Vector3f& p : part.positions) p *= static_cast<float>(factor);
  }
}

}  // namespace ecv
