#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "core/mesh.h"

namespace ecv {
namespace {

// A unit cube's 8 corners and 12 triangles.
TriangleMesh Cube(double side) {
  TriangleMesh mesh;
  MeshPart part;
  for (int i = 0; i < 8; ++i) {
    part.positions.emplace_back(static_cast<float>(side * (i & 1)), static_cast<float>(side * ((i >> 1) & 1)),
                                static_cast<float>(side * ((i >> 2) & 1)));
  }
  part.triangles = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}, {0, 4, 5}, {0, 5, 1},
                    {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
  mesh.parts.push_back(part);
  return mesh;
}

TEST(TriangleMesh, CountsBoxAndDiameterOfACube) {
  const TriangleMesh cube = Cube(0.1);
  EXPECT_EQ(cube.NumVertices(), 8U);
  EXPECT_EQ(cube.NumTriangles(), 12U);
  EXPECT_LT((cube.BoundingBox().sizes() - Eigen::Vector3d::Constant(0.1)).norm(), 1e-7);
  EXPECT_NEAR(cube.Diameter(), 0.1 * std::sqrt(3.0), 1e-7);
}

// A box of 0.2 x 0.1 x 0.04 m, turned and moved: its principal axes are its edges, least spread first, and its
// principal box is the box itself.
TEST(TriangleMesh, PrincipalAxesBoxOfATurnedBoxIsTheBox) {
  TriangleMesh box = Cube(1.0);
  Eigen::Isometry3d placed = Eigen::Isometry3d::Identity();
  placed.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() *
                    Eigen::Vector3d(0.2, 0.1, 0.04).asDiagonal();
  placed.translation() = Eigen::Vector3d(0.3, -0.1, 0.5);
  for (Eigen::Vector3f& p : box.parts[0].positions) p = (placed * p.cast<double>()).cast<float>();

  const PrincipalBox principal = box.PrincipalAxesBox();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_NEAR((principal.centre - placed * Eigen::Vector3d(0.5, 0.5, 0.5)).norm(), 0.0, 1e-6);
  EXPECT_NEAR(std::abs(principal.axes.col(0).dot(turn.col(2))), 1.0, 1e-6);  // 4 cm: least spread
  EXPECT_NEAR(std::abs(principal.axes.col(1).dot(turn.col(1))), 1.0, 1e-6);
  EXPECT_NEAR(std::abs(principal.axes.col(2).dot(turn.col(0))), 1.0, 1e-6);  // 20 cm: most spread
  EXPECT_NEAR((principal.half_sizes - Eigen::Vector3d(0.02, 0.05, 0.1)).norm(), 0.0, 1e-6);
  EXPECT_EQ(TriangleMesh().PrincipalAxesBox().half_sizes, Eigen::Vector3d::Zero());
}

TEST(TriangleMesh, ClosedOutwardNeedsEveryEdgeRunBothWaysAndFacesTurnedOut) {
  TriangleMesh inward = Cube(0.1);  // Cube's triangles run clockwise seen from outside
  EXPECT_FALSE(inward.IsClosedOutward()) << "closed, but turned inwards";
  TriangleMesh outward = inward;
  for (Eigen::Vector3i& triangle : outward.parts[0].triangles) std::swap(triangle.y(), triangle.z());
  EXPECT_TRUE(outward.IsClosedOutward());

  // A texture seam: the +x face in a part of its own with copies of its corners stays closed.
  TriangleMesh seamed = outward;
  MeshPart face;
  for (int corner : {1, 3, 5, 7}) face.positions.push_back(outward.parts[0].positions[static_cast<size_t>(corner)]);
  std::vector<Eigen::Vector3i>& triangles = seamed.parts[0].triangles;
  // Odd corners have x = 1.
  const auto on_face = [](const Eigen::Vector3i& t) { return t.x() % 2 == 1 && t.y() % 2 == 1 && t.z() % 2 == 1; };
  for (const Eigen::Vector3i& t : triangles) {
    if (on_face(t)) face.triangles.emplace_back(t.x() / 2, t.y() / 2, t.z() / 2);  // 1, 3, 5, 7 -> 0, 1, 2, 3
  }
  triangles.erase(std::remove_if(triangles.begin(), triangles.end(), on_face), triangles.end());
  ASSERT_EQ(face.triangles.size(), 2U);
  seamed.parts.push_back(face);
  EXPECT_TRUE(seamed.IsClosedOutward());
  seamed.parts[0].triangles.emplace_back(0, 0, 1);  // covers nothing
  EXPECT_TRUE(seamed.IsClosedOutward());

  TriangleMesh open = outward;
  open.parts[0].triangles.pop_back();
  EXPECT_FALSE(open.IsClosedOutward()) << "a missing triangle leaves a hole";
  TriangleMesh mixed = outward;
  std::swap(mixed.parts[0].triangles[0].y(), mixed.parts[0].triangles[0].z());
  EXPECT_FALSE(mixed.IsClosedOutward()) << "one triangle turned over";
  EXPECT_FALSE(TriangleMesh().IsClosedOutward());
}

TEST(TriangleMesh, DiameterEqualsBruteForceOnRandomPoints) {
  std::mt19937 random(7);
  std::normal_distribution<float> normal(0.0F, 1.0F);
  TriangleMesh mesh;
  mesh.parts.emplace_back();
  for (int i = 0; i < 2000; ++i)
    mesh.parts[0].positions.emplace_back(normal(random), 0.3F * normal(random), normal(random));
  double brute = 0.0;
  const auto& p = mesh.parts[0].positions;
  for (size_t i = 0; i < p.size(); ++i) {
    for (size_t j = i + 1; j < p.size(); ++j)
      brute = std::max(brute, (p[i].cast<double>() - p[j].cast<double>()).norm());
  }
  EXPECT_NEAR(mesh.Diameter(), brute, 1e-9);
}

TEST(TriangleMesh, ScaleThenTransformMovesPositionsAndNormals) {
  TriangleMesh cube = Cube(100.0);  // millimetres
  cube.parts[0].normals.assign(8, Eigen::Vector3f::UnitZ());
  cube.Scale(0.001);
  Eigen::Isometry3d object_from_mesh = Eigen::Isometry3d::Identity();
  object_from_mesh.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  object_from_mesh.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  cube.Transform(object_from_mesh);
  // Corner (0.1, 0.1, 0.1) -> rotated about x by 90 degrees -> (0.1, -0.1, 0.1) + (0, 0, 0.5).
  EXPECT_LT((cube.parts[0].positions[7] - Eigen::Vector3f(0.1F, -0.1F, 0.6F)).norm(), 1e-6F);
  EXPECT_LT((cube.parts[0].normals[0] - Eigen::Vector3f(0.0F, -1.0F, 0.0F)).norm(), 1e-6F);
  EXPECT_NEAR(cube.Diameter(), 0.1 * std::sqrt(3.0), 1e-6);
}

TEST(TriangleMesh, ColoringPrefersTextureThenVertexColours) {
  TriangleMesh mesh = Cube(1.0);
  EXPECT_EQ(mesh.Coloring(mesh.parts[0]), MeshColoring::kMaterialColor);
  mesh.parts[0].colors.assign(8, Eigen::Vector3f(1, 0, 0));
  EXPECT_EQ(mesh.Coloring(mesh.parts[0]), MeshColoring::kVertexColor);
  mesh.materials.push_back({"m", {1, 1, 1}, cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)), "t.png"});
  mesh.parts[0].material = 0;
  EXPECT_EQ(mesh.Coloring(mesh.parts[0]), MeshColoring::kVertexColor);  // no texcoords yet
  mesh.parts[0].texcoords.assign(8, Eigen::Vector2f(0.5F, 0.5F));
  EXPECT_EQ(mesh.Coloring(mesh.parts[0]), MeshColoring::kTexture);
}

}  // namespace
}  // namespace ecv
