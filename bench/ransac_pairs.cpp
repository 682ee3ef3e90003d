// The two view pairs of ransac_bench (issue 6, "Benchmarks"): a rendered wide-baseline pair of a cluster of
// YCB meshes and the real YCB-Video pair moved as in the RANSAC tests. ECV primitives, descriptors and
// nearest-neighbour matching run once per pair; every RANSAC is then fed the same correspondences.

#include "ransac_pairs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "bench_util.h"
#include "core/timing.h"
#include "ecv/descriptor.h"
#include "ecv/matching.h"
#include "ecv/primitives.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "render/renderer.h"
#include "render/sensor_noise.h"
#include "render/view_sampling.h"

namespace ecv::bench {
namespace {

constexpr double kTrueMatch = 0.01;  // metres: a correspondence is true within this after alignment
constexpr double kDegree = M_PI / 180.0;

struct FrameFeatures {
  std::vector<Primitive> primitives;
  Descriptors descriptors;
};

// `primitives` moved by `moved` (camera frame to camera frame) and their context descriptors (defaults).
FrameFeatures Describe(std::vector<Primitive> primitives,
                       const Eigen::Isometry3d& moved = Eigen::Isometry3d::Identity()) {
  FrameFeatures features;
  features.primitives = std::move(primitives);
  const Eigen::Isometry3f transform = moved.cast<float>();
  for (Primitive& primitive : features.primitives) {
    primitive.position = transform * primitive.position;
    primitive.orientation = transform.linear() * primitive.orientation;
  }
  features.descriptors = ComputeDescriptors(features.primitives);
  return features;
}

// Nearest-neighbour matching A -> B (structure-specific) and the points every RANSAC is fed. Exact search:
// FLANN's randomised kd-trees (the default above 1000 descriptors) gave 5-15 % different matches from one
// process to the next, and the inputs of a benchmark should repeat.
void Correspond(const FrameFeatures& a, const FrameFeatures& b, RegistrationPair* pair) {
  MatchOptions exact;
  exact.exact_below = std::numeric_limits<int>::max();
  const DescriptorMatcher matcher(b.primitives, b.descriptors, exact);
  const std::vector<DescriptorMatch> matches = matcher.Match(a.primitives, a.descriptors);
  const Eigen::Isometry3f b_from_a = pair->b_from_a.cast<float>();
  for (const Primitive& primitive : b.primitives) pair->b_points.push_back(primitive.position);
  for (const DescriptorMatch& match : matches) {
    if (match.rank != 0) continue;
    const Eigen::Vector3f& point = a.primitives[static_cast<size_t>(match.query)].position;
    const int index = static_cast<int>(pair->a_points.size());
    pair->a_points.push_back(point);
    pair->correspondences.push_back({index, match.train});
    const float distance = (b_from_a * point - pair->b_points[static_cast<size_t>(match.train)]).norm();
    pair->true_correspondences += distance < kTrueMatch ? 1 : 0;
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& point : pair->a_points) sum += point.cast<double>();
  if (!pair->a_points.empty()) pair->centre_a = sum / static_cast<double>(pair->a_points.size());
  pair->primitives_a = static_cast<int>(a.primitives.size());
  pair->primitives_b = static_cast<int>(b.primitives.size());
}

// A flat grey square of side `size_m` in the plane z = 0, centred at the origin.
TriangleMesh TableMesh(double size_m) {
  TriangleMesh table;
  table.name = "table";
  MeshMaterial grey;
  grey.name = "grey";
  grey.diffuse_color = Eigen::Vector3f(0.55F, 0.55F, 0.55F);
  table.materials.push_back(grey);
  MeshPart part;
  const float h = static_cast<float>(size_m / 2.0);
  part.positions = {{-h, -h, 0.0F}, {h, -h, 0.0F}, {h, h, 0.0F}, {-h, h, 0.0F}};
  part.normals.assign(4, Eigen::Vector3f::UnitZ());
  part.triangles = {{0, 1, 2}, {0, 2, 3}};
  part.material = 0;
  table.parts.push_back(part);
  return table;
}

// One mesh of the cluster: which, its turn about the table normal and its row (0 back, 1 front).
struct Placement {
  const char* object;
  double yaw_deg;
  int row;
};

const Placement kCluster[] = {{"003_cracker_box", 80.0, 0},    {"004_sugar_box", 15.0, 0},
                              {"005_tomato_soup_can", 0.0, 0}, {"006_mustard_bottle", -25.0, 1},
                              {"009_gelatin_box", 10.0, 1},    {"010_potted_meat_can", -15.0, 1}};

// world_from_object for each mesh of kCluster: standing on z = 0 (the google_16k frames have z up), packed
// left to right in two rows with 1 cm gaps, the whole cluster centred on the origin.
std::vector<Eigen::Isometry3d> PlaceCluster(const std::vector<TriangleMesh>& meshes) {
  constexpr double kGap = 0.01;
  std::vector<Eigen::Isometry3d> world_from_object(meshes.size(), Eigen::Isometry3d::Identity());
  std::vector<Eigen::AlignedBox3d> footprints(meshes.size());
  double row_x[2] = {0.0, 0.0};
  for (size_t i = 0; i < meshes.size(); ++i) {
    const Eigen::AlignedBox3d box = meshes[i].BoundingBox();
    const Eigen::Matrix3d yaw = Eigen::AngleAxisd(kCluster[i].yaw_deg * kDegree, Eigen::Vector3d::UnitZ()).matrix();
    Eigen::AlignedBox3d turned;
    for (int corner = 0; corner < 8; ++corner)
      turned.extend(yaw * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
    const int row = kCluster[i].row;
    const Eigen::Vector3d shift(row_x[row] - turned.min().x(), -turned.center().y(), -turned.min().z());
    world_from_object[i].linear() = yaw;
    world_from_object[i].translation() = shift;
    footprints[i] = Eigen::AlignedBox3d(turned.min() + shift, turned.max() + shift);
    row_x[row] += turned.sizes().x() + kGap;
  }
  double back_depth = 0.0, front_depth = 0.0;  // half extents in y of the two rows
  for (size_t i = 0; i < meshes.size(); ++i) {
    double& depth = kCluster[i].row == 0 ? back_depth : front_depth;
    depth = std::max(depth, footprints[i].sizes().y() / 2.0);
  }
  for (size_t i = 0; i < meshes.size(); ++i) {
    const int row = kCluster[i].row;
    const double y = row == 0 ? back_depth + kGap / 2.0 : -(front_depth + kGap / 2.0);
    const Eigen::Vector3d offset(-(row_x[row] - kGap) / 2.0, y, 0.0);
    world_from_object[i] = Eigen::Translation3d(offset) * world_from_object[i];
  }
  return world_from_object;
}

// camera_from_world of a camera at `azimuth_deg` and `elevation_deg`, `distance_m` from `target`.
Eigen::Isometry3d CameraAt(const Eigen::Vector3d& target, double azimuth_deg, double elevation_deg, double distance_m) {
  const double azimuth = azimuth_deg * kDegree, elevation = elevation_deg * kDegree;
  const Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                  std::sin(elevation));
  return LookAt(target + distance_m * direction, target, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
}

RgbdFrame RenderView(Renderer& renderer, const std::vector<MeshId>& ids,
                     const std::vector<Eigen::Isometry3d>& world_from_object,
                     const Eigen::Isometry3d& camera_from_world, const PinholeCamera& camera, uint32_t noise_seed,
                     const std::string& name) {
  std::vector<SceneObject> objects;
  for (size_t i = 0; i < ids.size(); ++i) objects.push_back({ids[i], camera_from_world * world_from_object[i]});
  const RenderResult rendered = renderer.RenderScene(objects, camera);
  SensorNoiseOptions noise;
  noise.seed = noise_seed;
  return {rendered.color, SimulateStructuredLight(rendered.depth, camera, noise).depth, camera, name};
}

// Mean of the back-projected valid depth pixels, camera frame, metres.
Eigen::Vector3d DepthCentre(const RgbdFrame& frame) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int v = 0; v < frame.depth.rows; ++v) {
    for (int u = 0; u < frame.depth.cols; ++u) {
      const float z = frame.depth.at<float>(v, u);
      if (z <= 0.0F) continue;
      sum += frame.camera.BackProject(Eigen::Vector2d(u, v), z);
      ++count;
    }
  }
  return count > 0 ? Eigen::Vector3d(sum / count) : sum;
}

}  // namespace

RegistrationPair RenderedPair(const std::string& data_dir, double baseline_deg) {
  const PinholeCamera camera{1066.778, 1067.487, 312.9869, 241.3109, 640, 480};  // YCB-Video
  const auto to_ycbv = ReadTransformTable(data_dir + "/ycbv_subset/derived/google16k_to_ycbv.txt");
  std::vector<TriangleMesh> meshes;
  for (const Placement& placement : kCluster) {
    MeshLoadOptions options;
    options.object_from_mesh = to_ycbv.at(placement.object);
    meshes.push_back(LoadMesh(
        data_dir + "/ycbv_subset/ycb_google16k_textured/" + std::string(placement.object) + "_textured.obj", options));
  }
  std::vector<Eigen::Isometry3d> world_from_object = PlaceCluster(meshes);
  Renderer renderer;
  std::vector<MeshId> ids;
  for (const TriangleMesh& mesh : meshes) ids.push_back(renderer.AddMesh(mesh));
  ids.push_back(renderer.AddMesh(TableMesh(1.0)));
  world_from_object.push_back(Eigen::Isometry3d::Identity());

  const Eigen::Vector3d target(0.0, 0.0, 0.07);  // about half the height of the cluster
  constexpr double kElevation = 35.0, kDistance = 0.8;
  const Eigen::Isometry3d a_from_world = CameraAt(target, -90.0 - baseline_deg / 2.0, kElevation, kDistance);
  const Eigen::Isometry3d b_from_world = CameraAt(target, -90.0 + baseline_deg / 2.0, kElevation, kDistance);
  const auto start = Clock::now();
  const RgbdFrame a = RenderView(renderer, ids, world_from_object, a_from_world, camera, 1, "rendered view A");
  const RgbdFrame b = RenderView(renderer, ids, world_from_object, b_from_world, camera, 2, "rendered view B");

  RegistrationPair pair;
  pair.name = "rendered, " + Fixed(baseline_deg, 0) + " deg";
  pair.description =
      "six YCB google_16k textured meshes (003, 004, 005, 006, 009, 010) standing on a grey table, "
      "rendered (OSMesa, unlit, 640x480, YCB-Video intrinsics) from two cameras 0.8 m from the "
      "cluster at 35 deg elevation, " +
      Fixed(baseline_deg, 0) + " deg apart in azimuth (relative rotation " + Fixed(baseline_deg, 0) +
      " deg), depth through SimulateStructuredLight (seeds 1 and 2)";
  pair.b_from_a = b_from_world * a_from_world.inverse();
  Correspond(Describe(ExtractPrimitives(a).primitives), Describe(ExtractPrimitives(b).primitives), &pair);
  pair.extraction_ms = MillisecondsSince(start);
  return pair;
}

RegistrationPair RealPair(const std::string& data_dir, double rotation_deg) {
  const std::string video = data_dir + "/ycbv_subset/Example-Scenes/0001/";
  const LoadedFrame first = LoadYcbvFrame(video + "000001");
  const LoadedFrame last = LoadYcbvFrame(video + "000019");
  RegistrationPair pair;
  pair.name = "real 0001 1->19 +" + Fixed(rotation_deg, 0) + " deg";
  const GroundTruth& truth = first.ground_truth.at(0);
  const auto same = std::find_if(last.ground_truth.begin(), last.ground_truth.end(),
                                 [&](const GroundTruth& other) { return other.object_id == truth.object_id; });
  if (same == last.ground_truth.end()) throw std::runtime_error(video + "000019: no " + truth.object_name);
  pair.description =
      "YCB-Video 0001 frame 1 (A) against frame 19 (B); camera motion T19 T1^-1 from the ground "
      "truth of " +
      truth.object_name + ", then B's primitives rotated by " + Fixed(rotation_deg, 0) +
      " deg about the axis (0.3, 1, 0.2) (camera frame, normalised) through the centre of B's depth points, as in "
      "tests/registration/scene_registration_test.cpp";
  const auto start = Clock::now();
  const FrameFeatures a = Describe(ExtractPrimitives(first.rgbd).primitives);
  const Eigen::Vector3d centre_b = DepthCentre(last.rgbd);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, 1.0, 0.2).normalized();  // as tests/registration
  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();                   // x' = R (x - c) + c
  moved.linear() = Eigen::AngleAxisd(rotation_deg * kDegree, axis).toRotationMatrix();
  moved.translation() = centre_b - moved.linear() * centre_b;
  pair.b_from_a = moved * same->camera_from_object * truth.camera_from_object.inverse();
  Correspond(a, Describe(ExtractPrimitives(last.rgbd).primitives, moved), &pair);
  pair.extraction_ms = MillisecondsSince(start);
  return pair;
}

}  // namespace ecv::bench
