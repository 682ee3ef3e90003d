// The generalisation set's rendered scenes (bench/scenes): resting poses of a box, and scenes from the real assets
// that are physically consistent (objects on the table, none inside another), whose ground truth projects onto its
// own pixels, that repeat from their seed, with repainted objects in colour.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/frame_io.h"
#include "scenes/rendered_scenes.h"
#include "scenes/resting_poses.h"
#include "support/test_data.h"

namespace ecv::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A closed box [0, size.x] x [0, size.y] x [0, size.z] shifted by `offset`, faces turned outwards.
TriangleMesh Box(const Eigen::Vector3f& size, const Eigen::Vector3f& offset) {
  MeshPart part;
  for (int i = 0; i < 8; ++i) {
    part.positions.push_back(offset +
                             Eigen::Vector3f((i & 1) * size.x(), (i >> 1 & 1) * size.y(), (i >> 2 & 1) * size.z()));
  }
  // Two triangles per face; each face: the 4 corners sharing one coordinate bit.
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      std::vector<int> corners;
      for (int i = 0; i < 8; ++i) {
        if ((i >> axis & 1) == side) corners.push_back(i);
      }
      for (const Eigen::Vector3i& t :
           {Eigen::Vector3i(corners[0], corners[1], corners[3]), Eigen::Vector3i(corners[0], corners[3], corners[2])}) {
        const Eigen::Vector3f& a = part.positions[t.x()];
        const Eigen::Vector3f normal = (part.positions[t.y()] - a).cross(part.positions[t.z()] - a);
        const Eigen::Vector3f outwards = a - (offset + 0.5F * size);
        part.triangles.push_back(normal.dot(outwards) > 0.0F ? t : Eigen::Vector3i(t.x(), t.z(), t.y()));
      }
    }
  }
  TriangleMesh mesh;
  mesh.name = "box";
  mesh.parts.push_back(part);
  return mesh;
}

TEST(RestingPosesTest, BoxRestsFlatOnEachOfItsSixFaces) {
  const Eigen::Vector3f size(0.1F, 0.2F, 0.3F), offset(0.02F, -0.05F, 0.01F);
  const TriangleMesh box = Box(size, offset);
  ASSERT_TRUE(box.IsClosedOutward());
  const std::vector<RestingPose> poses = RestingPoses(box);
  ASSERT_EQ(poses.size(), 6U);
  const double expected_areas[6] = {0.06, 0.06, 0.03, 0.03, 0.02, 0.02};
  std::vector<Eigen::Vector3d> downs;
  for (size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Isometry3d& table_from_object = poses[k].table_from_object;
    EXPECT_NEAR(poses[k].support_area_m2, expected_areas[k], 1e-7) << "pose " << k;
    double min_z = 1e9;
    for (const Eigen::Vector3f& p : box.parts[0].positions)
      min_z = std::min(min_z, (table_from_object * p.cast<double>()).z());
    EXPECT_NEAR(min_z, 0.0, 1e-6) << "pose " << k;
    int on_table = 0;  // the lowest face's 4 corners, nothing else
    for (const Eigen::Vector3f& p : box.parts[0].positions)
      on_table += std::abs((table_from_object * p.cast<double>()).z()) < 1e-6;
    EXPECT_EQ(on_table, 4) << "pose " << k;
    const Eigen::Vector3d centre = table_from_object * (offset + 0.5F * size).cast<double>();
    EXPECT_NEAR(centre.x(), 0.0, 1e-7) << "pose " << k;
    EXPECT_NEAR(centre.y(), 0.0, 1e-7) << "pose " << k;
    EXPECT_GT(poses[k].margin_m, 0.049) << "pose " << k;  // half the shorter side of the face it lies on
    const Eigen::Vector3d down = table_from_object.linear().transpose() * -Eigen::Vector3d::UnitZ();
    EXPECT_NEAR(down.cwiseAbs().maxCoeff(), 1.0, 1e-9) << "pose " << k << ": along a box axis";
    for (const Eigen::Vector3d& other : downs) EXPECT_LT(down.dot(other), 0.5) << "pose " << k << " repeats a face";
    downs.push_back(down);
  }
  // The footprint lying on the largest face is that face: 0.2 m x 0.3 m, counter-clockwise.
  const std::vector<cv::Point2f> footprint = Footprint(box, poses[0].table_from_object);
  ASSERT_EQ(footprint.size(), 4U);
  EXPECT_NEAR(cv::contourArea(footprint, true), 0.06, 1e-6);  // OpenCV's sign: positive for counter-clockwise (y up)
}

TEST(RestingPosesTest, OptionsRejectNonsense) {
  RestingPoseOptions options;
  options.contact_tolerance_m = -0.001;
  EXPECT_THROW(options.Check(), InputError);
  options = {};
  options.min_margin_m = std::nan("");
  EXPECT_THROW(options.Check(), InputError);
  RenderedSceneOptions scene;
  scene.min_objects = 5;
  scene.max_objects = 4;
  EXPECT_THROW(scene.Check(), InputError);
  scene = {};
  scene.ambient = 1.5;
  EXPECT_THROW(scene.Check(), InputError);
  EXPECT_NO_THROW(RenderedSceneOptions().Check());
}

// ---------------------------------------------------------------------------------------------------------------------

constexpr uint32_t kSeeds[] = {1, 2, 3};

// Assets, backdrops, a renderer and the scenes of kSeeds, made once for the tests below.
struct Shared {
  std::vector<SceneAsset> assets;
  Backdrops backdrops;
  Renderer renderer;
  std::vector<MeshId> mesh_ids;
  std::map<uint32_t, RenderedScene> scenes;

  Shared() {
    const std::string data_dir = std::filesystem::path(test::DataPath("ycbv_subset")).parent_path().string();
    assets = LoadSceneAssets(data_dir);
    backdrops = LoadBackdrops({test::DataPath("ycbv_subset/Example-Scenes/0002/000001"),
                               test::DataPath("ycbv_subset/Example-Scenes/0000/000011")});
    for (const SceneAsset& asset : assets) mesh_ids.push_back(renderer.AddMesh(asset.mesh));
    for (uint32_t seed : kSeeds) {
      const auto start = std::chrono::steady_clock::now();
      scenes[seed] = GenerateRenderedScene(renderer, assets, mesh_ids, backdrops, seed);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      std::cout << "[ timing   ] rendered scene " << seed << ": " << ms << " ms, " << scenes[seed].objects.size()
                << " objects\n";
    }
  }

  size_t AssetIndex(const std::string& name) const {
    for (size_t i = 0; i < assets.size(); ++i) {
      if (assets[i].name == name) return i;
    }
    ADD_FAILURE() << "no asset " << name;
    return 0;
  }
};

Shared& GetShared() {
  static Shared* shared = new Shared();  // lives until the end of the program, as the GL context may need
  return *shared;
}

std::vector<Eigen::Vector3d> TableVertices(const TriangleMesh& mesh, const Eigen::Isometry3d& table_from_object) {
  std::vector<Eigen::Vector3d> vertices;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3f& p : part.positions) vertices.push_back(table_from_object * p.cast<double>());
  }
  return vertices;
}

constexpr int kAround = 3600;  // horizontal directions to test for a separating plane, every 0.1 degrees
constexpr int kSphere = 100;   // pairs of opposite directions spread over the sphere, also tested

// Directions to test for a separating plane: kAround around the vertical, then kSphere opposite pairs.
std::vector<Eigen::Vector3d> SeparatingDirections() {
  std::vector<Eigen::Vector3d> directions;
  for (int k = 0; k < kAround; ++k) {
    const double angle = k * 2.0 * kPi / kAround;
    directions.emplace_back(std::cos(angle), std::sin(angle), 0.0);
  }
  for (int k = 0; k < kSphere; ++k) {  // Fibonacci sphere
    const double z = 1.0 - (2.0 * k + 1.0) / kSphere, r = std::sqrt(1.0 - z * z);
    const double phi = k * kPi * (3.0 - std::sqrt(5.0));
    directions.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    directions.emplace_back(-r * std::cos(phi), -r * std::sin(phi), -z);
  }
  return directions;
}

size_t Opposite(size_t d) {
  if (d < kAround) return (d + kAround / 2) % kAround;
  return (d - kAround) % 2 == 0 ? d + 1 : d - 1;
}

// The support function of `vertices`: per direction, their largest coordinate along it. Along horizontal directions
// only the outline seen from above (OpenCV's convex hull) can be extreme.
std::vector<double> Support(const std::vector<Eigen::Vector3d>& vertices,
                            const std::vector<Eigen::Vector3d>& directions) {
  std::vector<cv::Point2f> seen_from_above, outline;
  for (const Eigen::Vector3d& v : vertices)
    seen_from_above.emplace_back(static_cast<float>(v.x()), static_cast<float>(v.y()));
  cv::convexHull(seen_from_above, outline);
  std::vector<double> support(directions.size(), -1e9);
  for (size_t d = 0; d < directions.size(); ++d) {
    if (d < kAround) {
      for (const cv::Point2f& p : outline)
        support[d] = std::max(support[d], p.x * directions[d].x() + p.y * directions[d].y());
    } else {
      for (const Eigen::Vector3d& v : vertices) support[d] = std::max(support[d], v.dot(directions[d]));
    }
  }
  return support;
}

void CheckAssetsAreTheSixteenModelsAndEightClutterMeshes() {
  const Shared& shared = GetShared();
  ASSERT_EQ(shared.assets.size(), 24U);
  int modelled = 0, repainted = 0;
  for (const SceneAsset& asset : shared.assets) {
    modelled += asset.modelled;
    repainted += asset.repaint;
    EXPECT_FALSE(asset.resting_poses.empty()) << asset.name;
    std::cout << "[ poses    ] " << asset.name << ": " << asset.resting_poses.size() << "\n";
  }
  EXPECT_EQ(modelled, 16);
  EXPECT_EQ(repainted, 9);
  const SceneAsset& bowl = shared.assets[shared.AssetIndex("024_bowl")];
  EXPECT_TRUE(bowl.repaint && bowl.modelled);
  const SceneAsset& cracker = shared.assets[shared.AssetIndex("003_cracker_box")];
  EXPECT_FALSE(cracker.repaint);
  EXPECT_EQ(cracker.mesh.Coloring(cracker.mesh.parts[0]), MeshColoring::kTexture);
  EXPECT_FALSE(shared.assets[shared.AssetIndex("obj_000005")].modelled);
}

TEST(RenderedScenesTest, BrokenInputsAreInputErrors) {
  const test::TemporaryDirectory empty;
  EXPECT_THROW(LoadSceneAssets(empty.path().string()), InputError);
  EXPECT_THROW(LoadBackdrops({empty.File("000001")}), InputError);
  Renderer renderer;
  std::vector<SceneAsset> boxes(3);
  for (SceneAsset& asset : boxes) asset.mesh = Box({0.05F, 0.05F, 0.05F}, {0.0F, 0.0F, 0.0F});
  std::vector<MeshId> mesh_ids;
  for (const SceneAsset& asset : boxes) mesh_ids.push_back(renderer.AddMesh(asset.mesh));
  EXPECT_THROW(GenerateRenderedScene(renderer, boxes, {mesh_ids[0]}, Backdrops{{cv::Mat(64, 64, CV_8UC3)}}, 1),
               InputError);
  EXPECT_THROW(GenerateRenderedScene(renderer, boxes, mesh_ids, Backdrops(), 1), InputError);
  RenderedSceneOptions four;
  four.min_objects = 4;
  four.max_objects = 4;
  EXPECT_THROW(GenerateRenderedScene(renderer, boxes, mesh_ids, Backdrops{{cv::Mat(64, 64, CV_8UC3)}}, 1, four),
               InputError);
}

void CheckObjectsRestOnTheTableWithoutInterpenetrating() {
  Shared& shared = GetShared();
  const std::vector<Eigen::Vector3d> directions = SeparatingDirections();
  for (uint32_t seed : kSeeds) {
    const RenderedScene& scene = shared.scenes.at(seed);
    int modelled = 0;
    std::vector<std::vector<double>> support;  // per object, max of its table-frame vertices along each direction
    for (const PlacedObject& object : scene.objects) {
      modelled += object.modelled;
      const std::vector<Eigen::Vector3d> vertices =
          TableVertices(shared.assets[shared.AssetIndex(object.name)].mesh, object.table_from_object);
      double lowest = 1e9;
      for (const Eigen::Vector3d& v : vertices) lowest = std::min(lowest, v.z());
      EXPECT_NEAR(lowest, 0.0, 0.001) << "seed " << seed << ", " << object.name << " does not rest on the table";
      EXPECT_TRUE(object.camera_from_object.isApprox(scene.camera_from_table * object.table_from_object, 1e-9));
      support.push_back(Support(vertices, directions));
    }
    EXPECT_GE(modelled, 3) << "seed " << seed;
    EXPECT_LE(modelled, 8) << "seed " << seed;
    // Convex hulls apart (up to 2 mm): some direction d with max_A d.x <= min_B d.x + 2 mm = -max_B (-d).x + 2 mm.
    for (size_t a = 0; a < support.size(); ++a) {
      for (size_t b = a + 1; b < support.size(); ++b) {
        double smallest = 1e9;
        for (size_t d = 0; d < directions.size(); ++d) {
          smallest = std::min(smallest, support[a][d] + support[b][Opposite(d)]);
        }
        EXPECT_LE(smallest, 0.002) << "seed " << seed << ": " << scene.objects[a].name << " and "
                                   << scene.objects[b].name << " overlap by " << 1000 * smallest << " mm";
      }
    }
  }
}

void CheckGroundTruthPosesProjectOntoTheirOwnPixels() {
  Shared& shared = GetShared();
  for (uint32_t seed : kSeeds) {
    const RenderedScene& scene = shared.scenes.at(seed);
    const LoadedFrame& frame = scene.frame;
    EXPECT_NO_THROW(frame.rgbd.Check());
    EXPECT_EQ(frame.rgbd.name, "rendered/" + std::to_string(seed));
    EXPECT_FALSE(frame.ground_truth.empty());
    for (const GroundTruth& truth : frame.ground_truth) {
      const auto found = std::find_if(scene.objects.begin(), scene.objects.end(),
                                      [&](const PlacedObject& o) { return o.name == truth.object_name; });
      ASSERT_NE(found, scene.objects.end()) << truth.object_name;
      EXPECT_TRUE(found->modelled);
      EXPECT_GT(truth.object_id, 0) << truth.object_name;
      const int label = static_cast<int>(found - scene.objects.begin()) + 1;
      RenderOptions options;
      options.near_m = 0.05;
      const RenderResult alone = shared.renderer.Render(shared.mesh_ids[shared.AssetIndex(truth.object_name)],
                                                        frame.rgbd.camera, truth.camera_from_object, options);
      const cv::Mat own = scene.labels == label;
      const int visible = cv::countNonZero(own), unoccluded = cv::countNonZero(alone.mask);
      const int inside = cv::countNonZero(own & alone.mask);
      EXPECT_GE(inside, 0.99 * visible) << "seed " << seed << ", " << truth.object_name;
      EXPECT_GE(visible, 0.1 * unoccluded) << "seed " << seed << ", " << truth.object_name;
      EXPECT_EQ(found->visible_pixels, visible);
      EXPECT_EQ(found->unoccluded_pixels, unoccluded);
      EXPECT_NEAR(truth.visible_fraction, static_cast<double>(visible) / unoccluded, 1e-9);
      EXPECT_EQ(truth.visible_box, cv::boundingRect(own));
      EXPECT_EQ(truth.object_box, cv::boundingRect(alone.mask));
    }
    for (const PlacedObject& object : scene.objects) {  // the modelled ones left out are hidden to below 10 %
      const bool listed = std::any_of(frame.ground_truth.begin(), frame.ground_truth.end(),
                                      [&](const GroundTruth& t) { return t.object_name == object.name; });
      if (object.modelled && !listed) {
        EXPECT_LT(10 * object.visible_pixels, object.unoccluded_pixels) << object.name;
      }
      if (!object.modelled) {
        EXPECT_FALSE(listed) << object.name;
      }
    }
  }
  if (const char* path = std::getenv("ECV_RENDERED_SCENE_PNG")) {  // a picture to look at: colour with label outlines
    const RenderedScene& scene = shared.scenes.at(kSeeds[0]);
    cv::Mat picture = scene.frame.rgbd.color.clone();
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      std::vector<std::vector<cv::Point>> outlines;
      cv::findContours(scene.labels == static_cast<int>(i + 1), outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
      cv::drawContours(picture, outlines, -1,
                       scene.objects[i].modelled ? cv::Scalar(0, 255, 0) : cv::Scalar(255, 0, 255));
    }
    WriteColorImage(path, picture);
  }
}

void CheckTheSameSeedGivesTheSameScene() {
  Shared& shared = GetShared();
  const RenderedScene again =
      GenerateRenderedScene(shared.renderer, shared.assets, shared.mesh_ids, shared.backdrops, kSeeds[0]);
  const RenderedScene& first = shared.scenes.at(kSeeds[0]);
  EXPECT_EQ(cv::norm(again.frame.rgbd.color, first.frame.rgbd.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(again.frame.rgbd.depth, first.frame.rgbd.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(again.labels, first.labels, cv::NORM_INF), 0.0);
  const RenderedScene& other = shared.scenes.at(kSeeds[1]);
  EXPECT_GT(cv::norm(other.frame.rgbd.color, first.frame.rgbd.color, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(other.frame.rgbd.depth, first.frame.rgbd.depth, cv::NORM_L1), 0.0);
}

void CheckRepaintedObjectsShowTheirPaintNotGrey() {
  Shared& shared = GetShared();
  int checked = 0;
  for (uint32_t seed : kSeeds) {
    const RenderedScene& scene = shared.scenes.at(seed);
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const PlacedObject& object = scene.objects[i];
      const bool repaint = shared.assets[shared.AssetIndex(object.name)].repaint;
      EXPECT_EQ(object.paint.x() >= 0.0F, repaint) << object.name;
      if (!repaint || object.visible_pixels < 200) continue;
      // The mean colour without the light's gain, over pixels not clipped, points like the paint and is not grey.
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int v = 0; v < scene.labels.rows; ++v) {
        for (int u = 0; u < scene.labels.cols; ++u) {
          const cv::Vec3b& c = scene.frame.rgbd.color.at<cv::Vec3b>(v, u);
          if (scene.labels.at<uint16_t>(v, u) != i + 1 || std::max({c[0], c[1], c[2]}) == 255) continue;
          sum += Eigen::Vector3d(c[0], c[1], c[2]).cwiseQuotient(scene.light_gain);
        }
      }
      ASSERT_GT(sum.norm(), 0.0) << object.name;
      const double saturation = 1.0 - sum.minCoeff() / sum.maxCoeff();
      EXPECT_GT(saturation, 0.2) << "seed " << seed << ", " << object.name;
      EXPECT_GT(sum.normalized().dot(object.paint.cast<double>().normalized()), 0.99)
          << "seed " << seed << ", " << object.name;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

// The checks on the generated scenes share one process: loading the 24 meshes is most of their cost.
TEST(RenderedScenesTest, AssetsAndScenesArePhysicallyConsistent) {
  CheckAssetsAreTheSixteenModelsAndEightClutterMeshes();
  CheckObjectsRestOnTheTableWithoutInterpenetrating();
  CheckGroundTruthPosesProjectOntoTheirOwnPixels();
}

TEST(RenderedScenesTest, ScenesRepeatAndGreyMeshesArePainted) {
  CheckTheSameSeedGivesTheSameScene();
  CheckRepaintedObjectsShowTheirPaintNotGrey();
}

}  // namespace
}  // namespace ecv::bench
