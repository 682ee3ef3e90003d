// Point pair features: poses of a synthetic box in clutter, and of real YCB-Video objects in their frames, among the
// best pose clusters.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/pose.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "registration/ppf.h"
#include "support/test_data.h"

namespace ecv {
namespace {

constexpr double kDegree = M_PI / 180.0;

// A box of 12 x 8 x 5 cm, outward faces.
TriangleMesh Box() {
  const Eigen::Vector3f half(0.06F, 0.04F, 0.025F);
  MeshPart part;
  for (int corner = 0; corner < 8; ++corner) {
    part.positions.emplace_back((corner & 1 ? 1 : -1) * half.x(), (corner & 2 ? 1 : -1) * half.y(),
                                (corner & 4 ? 1 : -1) * half.z());
  }
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    part.triangles.emplace_back(f[0], f[1], f[2]);
    part.triangles.emplace_back(f[0], f[2], f[3]);
  }
  TriangleMesh mesh;
  mesh.parts.push_back(part);
  return mesh;
}

// The box's camera-facing surface at `camera_from_object`, with 2 mm of noise, and a table of 60 x 60 cm.
struct BoxOnTable {
  std::vector<OrientedPoint> box, table;
};

BoxOnTable MakeBoxOnTable(const TriangleMesh& box, const Eigen::Isometry3d& camera_from_object) {
  BoxOnTable scene;
  std::mt19937 random(7);
  std::normal_distribution<float> noise(0.0F, 0.002F);
  for (OrientedPoint point : SampleMeshSurface(box, 20000, 2)) {
    point.position = (camera_from_object * point.position.cast<double>()).cast<float>();
    point.normal = (camera_from_object.linear() * point.normal.cast<double>()).cast<float>();
    if (point.normal.dot(point.position) >= 0.0F) continue;  // facing away from the camera
    point.position += Eigen::Vector3f(noise(random), noise(random), noise(random));
    scene.box.push_back(point);
  }
  const Eigen::Vector3f up = -Eigen::Vector3f(0.0F, 0.5F, -1.0F).normalized();  // a table tilted towards the camera
  const Eigen::Vector3f across = up.unitOrthogonal(), along = up.cross(across);
  for (float a = -0.3F; a <= 0.3F; a += 0.004F) {
    for (float b = -0.3F; b <= 0.3F; b += 0.004F) {
      scene.table.push_back({Eigen::Vector3f(0.0F, 0.15F, 0.9F) + a * across + b * along, up});
    }
  }
  return scene;
}

// The rotation from `pose` to the nearest of the box's four rotations at `camera_from_object` (a box is symmetric).
double BoxAngle(const Eigen::Isometry3d& pose, const Eigen::Isometry3d& camera_from_object) {
  double best = RotationAngle(pose, camera_from_object);
  for (const Eigen::Vector3d axis : {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()}) {
    best = std::min(best, RotationAngle(pose, camera_from_object * Eigen::AngleAxisd(M_PI, axis)));
  }
  return best;
}

const Eigen::Isometry3d kBoxPose =
    Eigen::Translation3d(0.03, -0.02, 0.8) * Eigen::AngleAxisd(2.2, Eigen::Vector3d(0.3, -1.0, 0.4).normalized());

// The box on the table: the best cluster is the pose, within 1 cm and 10 degrees.
TEST(Ppf, FindsABoxOnATable) {
  const TriangleMesh box = Box();
  const PpfModel model(SampleMeshSurface(box, 20000), box.Diameter());
  BoxOnTable scene = MakeBoxOnTable(box, kBoxPose);
  std::vector<OrientedPoint> points = scene.box;
  points.insert(points.end(), scene.table.begin(), scene.table.end());
  const std::vector<PpfPose> poses = FindPpfPoses(model, points);
  ASSERT_FALSE(poses.empty());
  EXPECT_LT(TranslationDistance(poses[0].camera_from_object, kBoxPose), 0.01);
  EXPECT_LT(BoxAngle(poses[0].camera_from_object, kBoxPose), 10.0 * kDegree);
}

// Explained points pair but lead no vote: with the box's points explained (a detection's surface), no cluster lies
// at the box's pose; with the table's explained instead, the box is still the best cluster.
TEST(Ppf, ExplainedPointsLeadNoVote) {
  const TriangleMesh box = Box();
  const PpfModel model(SampleMeshSurface(box, 20000), box.Diameter());
  const BoxOnTable scene = MakeBoxOnTable(box, kBoxPose);
  PpfSearchStats stats;
  const std::vector<PpfPose> box_explained = FindPpfPoses(model, scene.table, scene.box, &stats);
  // Only the table's sub-sampled points lead, thinned to the reference spacing; the box's are paired with.
  const PpfOptions& options = model.options();
  const std::vector<OrientedPoint> table =
      SubsampleByNormals(scene.table, options.sampling * box.Diameter(), options.scene_keep_normal_deg);
  const size_t box_points =
      SubsampleByNormals(scene.box, options.sampling * box.Diameter(), options.scene_keep_normal_deg).size();
  EXPECT_EQ(stats.scene_points, table.size() + box_points);
  EXPECT_EQ(
      stats.references,
      SubsampleByNormals(table, options.reference_spacing * box.Diameter(), options.scene_keep_normal_deg).size());
  EXPECT_LT(stats.references * 20, table.size());  // a flat table: about one in (0.4 / 0.05)^2
  EXPECT_GT(stats.pairs, stats.references);
  EXPECT_GT(stats.entries, 0U);
  for (const PpfPose& pose : box_explained) {
    EXPECT_FALSE(TranslationDistance(pose.camera_from_object, kBoxPose) < 0.01 &&
                 BoxAngle(pose.camera_from_object, kBoxPose) < 10.0 * kDegree);
  }
  const std::vector<PpfPose> table_explained = FindPpfPoses(model, scene.box, scene.table);
  ASSERT_FALSE(table_explained.empty());
  EXPECT_LT(TranslationDistance(table_explained[0].camera_from_object, kBoxPose), 0.01);
  EXPECT_LT(BoxAngle(table_explained[0].camera_from_object, kBoxPose), 10.0 * kDegree);
}

// A quick vote: at most max_references reference points, and the box still the best cluster.
TEST(Ppf, AFewReferencesStillFindTheBox) {
  const TriangleMesh box = Box();
  PpfOptions quick;
  quick.max_references = 20;
  const PpfModel model(SampleMeshSurface(box, 20000), box.Diameter(), quick);
  const BoxOnTable scene = MakeBoxOnTable(box, kBoxPose);
  PpfSearchStats all_stats, quick_stats;
  FindPpfPoses(PpfModel(SampleMeshSurface(box, 20000), box.Diameter()), scene.box, {}, &all_stats);
  const std::vector<PpfPose> poses = FindPpfPoses(model, scene.box, {}, &quick_stats);
  ASSERT_GT(all_stats.references, 20U);
  EXPECT_EQ(quick_stats.references, 20U);
  ASSERT_FALSE(poses.empty());
  EXPECT_LT(TranslationDistance(poses[0].camera_from_object, kBoxPose), 0.01);
  EXPECT_LT(BoxAngle(poses[0].camera_from_object, kBoxPose), 10.0 * kDegree);
  quick.max_references = -1;
  EXPECT_THROW(quick.Check(), InputError);
}

// The banana of video 0002, plain yellow and curved, is the best cluster of the whole real frame, within 1 cm and
// 10 degrees (it is what the context descriptors miss).
TEST(Ppf, FindsTheBananaOfARealFrame) {
  const LoadedFrame loaded = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0002/000001"));
  MeshLoadOptions load;
  load.allow_missing_textures = true;
  const TriangleMesh mesh = LoadMesh(test::DataPath("ycbv_subset/models/011_banana/textured_simple.obj"), load);
  PpfOptions options;
  options.spread_margin = 0.5;  // every vote spread: the banana's right pose leads by itself (0.15 puts it second)
  const PpfModel model(SampleMeshSurface(mesh, 20000), mesh.Diameter(), options);
  const std::vector<PpfPose> poses = FindPpfPoses(model, OrientedScenePoints(loaded.rgbd, 2));
  ASSERT_FALSE(poses.empty());
  const GroundTruth* truth = nullptr;
  for (const GroundTruth& object : loaded.ground_truth) {
    if (object.object_name == "011_banana") truth = &object;
  }
  ASSERT_NE(truth, nullptr);
  EXPECT_LT(TranslationDistance(poses[0].camera_from_object, truth->camera_from_object), 0.01);
  EXPECT_LT(RotationAngle(poses[0].camera_from_object, truth->camera_from_object), 10.0 * kDegree);
}

// A table top of 60 x 60 cm (tilted, 2 mm noise) with the box held 2 cm above it: the table's points are left out and
// every one of the box's kept; without a dominant plane (a ball), every point is kept.
TEST(Ppf, LeavesOutTheDominantPlaneAndKeepsWhatStandsOnIt) {
  std::mt19937 random(3);
  std::normal_distribution<float> noise(0.0F, 0.002F);
  std::uniform_real_distribution<float> across(-0.3F, 0.3F);
  const Eigen::Matrix3f tilt = Eigen::AngleAxisf(0.4F, Eigen::Vector3f(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::Vector3f centre(0.0F, 0.0F, 0.8F);
  std::vector<OrientedPoint> points;
  for (int i = 0; i < 4000; ++i) {
    points.push_back({tilt * Eigen::Vector3f(across(random), across(random), noise(random)) + centre,
                      tilt * Eigen::Vector3f::UnitZ()});
  }
  // The box, 2 cm above the table and farther, so that none of its faces lies in the table's plane.
  std::vector<OrientedPoint> box;
  for (OrientedPoint point : SampleMeshSurface(Box(), 800)) {
    point.position = tilt * (point.position + Eigen::Vector3f(0.0F, 0.0F, 0.045F)) + centre;
    point.normal = tilt * point.normal;
    box.push_back(point);
  }
  points.insert(points.end(), box.begin(), box.end());
  const std::vector<OrientedPoint> kept = WithoutDominantPlane(points);
  EXPECT_EQ(kept.size(), box.size());
  std::vector<OrientedPoint> ball;
  std::normal_distribution<float> direction(0.0F, 1.0F);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3f normal =
        Eigen::Vector3f(direction(random), direction(random), direction(random)).normalized();
    ball.push_back({centre + 0.05F * normal, normal});
  }
  EXPECT_EQ(WithoutDominantPlane(ball).size(), ball.size());
  ScenePlaneOptions bad;
  bad.min_share = 0.0;
  EXPECT_THROW(WithoutDominantPlane(points, bad), InputError);
}

TEST(Ppf, RefusesAFlatModelAndBadOptions) {
  MeshPart part;
  part.positions = {{0, 0, 0}, {0.01F, 0, 0}, {0, 0.01F, 0}};
  part.triangles = {{0, 1, 2}};
  TriangleMesh triangle;
  triangle.parts.push_back(part);
  PpfOptions flat;
  flat.coplanar_deg = 12.0;  // a flat triangle: every pair lies in its plane
  EXPECT_THROW(PpfModel(SampleMeshSurface(triangle, 1000), triangle.Diameter(), flat), InputError);
  PpfOptions options;
  options.angle_bins = 2;
  EXPECT_THROW(options.Check(), InputError);
  options = PpfOptions();
  options.reference_spacing = 0.0;
  EXPECT_THROW(options.Check(), InputError);
  // A table entry holds its model point in 16 bits: more than 65536 points (a sampling far too fine) are refused.
  std::vector<OrientedPoint> many(65537);
  for (size_t i = 0; i < many.size(); ++i) many[i].position = Eigen::Vector3f(0.001F * static_cast<float>(i), 0, 0);
  try {
    PpfModel::FromSampledPoints(many, 0.1);
    ADD_FAILURE() << "65537 points were taken";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("65537"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace ecv
