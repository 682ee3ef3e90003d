#include "scenes/rendered_scenes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include "core/error.h"
#include "core/parallel.h"
#include "io/mesh_io.h"
#include "render/sensor_noise.h"

namespace ecv::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadiansPerDegree = kPi / 180.0;
constexpr int kMaxTextureSide = 2048;    // google16k textures (4096) are capped to this in LoadSceneAssets
constexpr double kOverlapMm2 = 0.1;      // footprints overlapping by less count as touching, square millimetres
constexpr int kPlacementAttempts = 40;   // random places tried per object
constexpr double kShadowBiasM = 0.005;   // a point is in shadow when the light sees this much nearer, metres
constexpr double kLightDistanceM = 3.0;  // of the shadow map's camera from the scene centre, metres
constexpr int kShadowMapSide = 640;      // pixels a side, about 1 mm each over the objects

// YCB-Video's cls_index by name (its dataset's 21 objects), 0 for other names.
int YcbvClassIndex(const std::string& name) {
  // clang-format off
  static const std::array<const char*, 21> kNames = {
      "002_master_chef_can", "003_cracker_box", "004_sugar_box", "005_tomato_soup_can", "006_mustard_bottle",
      "007_tuna_fish_can", "008_pudding_box", "009_gelatin_box", "010_potted_meat_can", "011_banana",
      "019_pitcher_base", "021_bleach_cleanser", "024_bowl", "025_mug", "035_power_drill", "036_wood_block",
      "037_scissors", "040_large_marker", "051_large_clamp", "052_extra_large_clamp", "061_foam_brick"};
  // clang-format on
  for (size_t i = 0; i < kNames.size(); ++i) {
    if (name == kNames[i]) return static_cast<int>(i) + 1;
  }
  return 0;
}

// YCB-Video's camera (SOURCE.md of ycbv_subset).
PinholeCamera YcbvCamera() {
  PinholeCamera camera;
  camera.fx = 1066.778;
  camera.fy = 1067.487;
  camera.cx = 312.9869;
  camera.cy = 241.3109;
  camera.width = 640;
  camera.height = 480;
  return camera;
}

double Uniform(std::mt19937& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

// A saturated, bright colour: HSV with s, v in [0.3, 1], as RGB in [0, 1].
Eigen::Vector3f RandomPaint(std::mt19937& rng) {
  const double hue = Uniform(rng, 0.0, 6.0), s = Uniform(rng, 0.3, 1.0), v = Uniform(rng, 0.3, 1.0);
  const double c = v * s, x = c * (1.0 - std::abs(std::fmod(hue, 2.0) - 1.0)), m = v - c;
  static const std::array<std::array<int, 3>, 6> kOrder = {
      {{0, 1, 2}, {1, 0, 2}, {2, 0, 1}, {2, 1, 0}, {1, 2, 0}, {0, 2, 1}}};
  const std::array<double, 3> parts = {c, x, 0.0};  // (c, x, 0) permuted by sextant
  const std::array<int, 3>& order = kOrder[static_cast<size_t>(std::min(5.0, std::floor(hue)))];
  return Eigen::Vector3d(parts[order[0]] + m, parts[order[1]] + m, parts[order[2]] + m).cast<float>();
}

// The camera at `eye` looking at `target` (table frame) with its x axis parallel to the table (no roll).
Eigen::Isometry3d CameraLookingAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d forward = (target - eye).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Isometry3d table_from_camera = Eigen::Isometry3d::Identity();
  table_from_camera.linear() << right, forward.cross(right), forward;
  table_from_camera.translation() = eye;
  return table_from_camera.inverse();
}

Eigen::Vector3d DirectionFromAngles(double azimuth, double elevation) {
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation)};
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------------
// Assets and backdrops

std::vector<SceneAsset> LoadSceneAssets(const std::string& data_dir) {
  struct Source {
    std::string name, path;
    MeshLoadOptions load;
    bool modelled, repaint;
  };
  const std::string ycbv = data_dir + "/ycbv_subset/";
  const auto to_ycbv = ReadTransformTable(ycbv + "derived/google16k_to_ycbv.txt");
  std::vector<Source> sources;
  for (const char* name : {"003_cracker_box", "004_sugar_box", "005_tomato_soup_can", "006_mustard_bottle",
                           "009_gelatin_box", "010_potted_meat_can"}) {
    const auto transform = to_ycbv.find(name);
    if (transform == to_ycbv.end()) {
      ThrowInputError(ycbv + "derived/google16k_to_ycbv.txt", name, "a row for this object");
    }
    MeshLoadOptions load;
    load.object_from_mesh = transform->second;
    sources.push_back({name, ycbv + "ycb_google16k_textured/" + name + "_textured.obj", load, true, false});
  }
  for (const char* name : {"011_banana", "002_master_chef_can", "007_tuna_fish_can", "008_pudding_box", "024_bowl",
                           "025_mug", "035_power_drill", "036_wood_block", "040_large_marker", "061_foam_brick"}) {
    MeshLoadOptions load;
    load.allow_missing_textures = true;
    const bool repaint = std::string(name) != "011_banana";
    sources.push_back({name, ycbv + "models/" + name + "/textured_simple.obj", load, true, repaint});
  }
  for (const char* id : {"01", "05", "06", "08", "09", "10", "11", "12"}) {
    MeshLoadOptions load;
    load.metres_per_unit = 0.001;
    const std::string name = std::string("obj_0000") + id;
    sources.push_back({name, data_dir + "/lmo_subset/data/bop/lmo/models/" + name + ".ply", load, false, false});
  }
  std::vector<SceneAsset> assets(sources.size());
  ParallelFor(sources.size(), 2, [&](size_t i) {
    SceneAsset& asset = assets[i];
    asset.name = sources[i].name;
    asset.mesh = LoadMesh(sources[i].path, sources[i].load);
    asset.mesh.name = asset.name;
    for (MeshMaterial& material : asset.mesh.materials)
      material.texture = CapTextureSize(material.texture, kMaxTextureSide);
    asset.modelled = sources[i].modelled;
    asset.repaint = sources[i].repaint;
    asset.resting_poses = RestingPoses(asset.mesh);
  });
  return assets;
}

Backdrops LoadBackdrops(const std::vector<std::string>& frame_prefixes) {
  Backdrops backdrops;
  for (const std::string& prefix : frame_prefixes) {
    const cv::Mat color = ReadColorImage(prefix + "-color.png");
    const std::string label_path = prefix + "-label.png";
    const cv::Mat labels = cv::imread(label_path, cv::IMREAD_UNCHANGED);
    if (labels.empty() || labels.channels() != 1 || labels.size() != color.size()) {
      ThrowInputError(label_path, "image", "a one-channel label PNG of the colour image's size");
    }
    cv::Mat mask = labels > 0;
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
    cv::Mat filled;
    cv::inpaint(color, mask, filled, 5.0, cv::INPAINT_TELEA);
    backdrops.images.push_back(filled);
  }
  return backdrops;
}

namespace {

// ---------------------------------------------------------------------------------------------------------------------
// Placement on the table: footprints in millimetres (float precision of cv::intersectConvexConvex).

using Polygon = std::vector<cv::Point2f>;  // table frame x, y, millimetres, counter-clockwise

// The camera's view of the table: where it looks and its horizontal axes (table frame, unit).
struct View {
  PinholeCamera camera;
  Eigen::Isometry3d camera_from_table;
  Eigen::Vector3d look_at, right, forward;
};

struct Placed {
  size_t asset = 0;
  Eigen::Isometry3d table_from_object;
  Polygon footprint;
};

// `footprint` (metres, yaw 0) turned by `yaw` about the origin and moved to `centre_mm`.
Polygon Moved(const std::vector<cv::Point2f>& footprint, double yaw, const Eigen::Vector2d& centre_mm) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Polygon moved;
  moved.reserve(footprint.size());
  for (const cv::Point2f& p : footprint) {
    moved.emplace_back(static_cast<float>(1000.0 * (c * p.x - s * p.y) + centre_mm.x()),
                       static_cast<float>(1000.0 * (s * p.x + c * p.y) + centre_mm.y()));
  }
  return moved;
}

cv::Rect2f Bounds(const Polygon& polygon) {
  cv::Point2f low = polygon.front(), high = polygon.front();
  for (const cv::Point2f& p : polygon) {
    low = cv::Point2f(std::min(low.x, p.x), std::min(low.y, p.y));
    high = cv::Point2f(std::max(high.x, p.x), std::max(high.y, p.y));
  }
  return {low, high};
}

bool Overlaps(const Polygon& a, const Polygon& b) {
  if ((Bounds(a) & Bounds(b)).area() <= 0.0F) return false;
  Polygon intersection;
  return cv::intersectConvexConvex(a, b, intersection, true) > kOverlapMm2;
}

bool OverlapsAny(const Polygon& polygon, const std::vector<Placed>& placed) {
  return std::any_of(placed.begin(), placed.end(), [&](const Placed& p) { return Overlaps(polygon, p.footprint); });
}

double SegmentDistance(const cv::Point2f& p, const cv::Point2f& a, const cv::Point2f& b) {
  const cv::Point2d ab = b - a, ap = p - a;
  const double t = std::clamp(ab.dot(ap) / std::max(ab.dot(ab), 1e-12), 0.0, 1.0);
  return cv::norm(ap - t * ab);
}

// Distance between two polygons that do not overlap, millimetres.
double Gap(const Polygon& a, const Polygon& b) {
  double gap = 1e30;
  for (int pass = 0; pass < 2; ++pass) {
    const Polygon& points = pass == 0 ? a : b;
    const Polygon& edges = pass == 0 ? b : a;
    for (const cv::Point2f& p : points) {
      for (size_t i = 0; i < edges.size(); ++i) {
        gap = std::min(gap, SegmentDistance(p, edges[i], edges[(i + 1) % edges.size()]));
      }
    }
  }
  return gap;
}

Eigen::Vector2d Centroid(const Polygon& polygon) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const cv::Point2f& p : polygon) sum += Eigen::Vector2d(p.x, p.y);
  return sum / static_cast<double>(polygon.size());
}

// Moves an object (its footprint `base` at `yaw`, centred at `*centre_mm`) in small steps straight towards the nearest
// placed footprint until it is at most `target_gap_mm` from it or another one blocks the way. Returns its footprint.
Polygon PushTowardsNeighbour(const std::vector<cv::Point2f>& base, double yaw, const std::vector<Placed>& placed,
                             double target_gap_mm, Eigen::Vector2d* centre_mm) {
  Polygon polygon = Moved(base, yaw, *centre_mm);
  size_t nearest = 0;
  double gap = 1e30;
  for (size_t k = 0; k < placed.size(); ++k) {
    const double g = Gap(polygon, placed[k].footprint);
    if (g < gap) gap = g, nearest = k;
  }
  const Eigen::Vector2d direction = (Centroid(placed[nearest].footprint) - *centre_mm).normalized();
  double step = 5.0;
  for (int i = 0; i < 1000; ++i) {
    const double move = std::min(step, gap - target_gap_mm);
    if (move < 0.25) break;
    const Eigen::Vector2d moved_centre = *centre_mm + move * direction;
    Polygon moved = Moved(base, yaw, moved_centre);
    if (OverlapsAny(moved, placed)) {
      step = move / 2.0;
      continue;
    }
    *centre_mm = moved_centre;
    polygon = std::move(moved);
    gap = Gap(polygon, placed[nearest].footprint);
  }
  return polygon;
}

// True when the centre of the object's box, placed by `table_from_object`, is seen well inside the image.
bool InView(const View& view, const TriangleMesh& mesh, const Eigen::Isometry3d& table_from_object) {
  const Eigen::Vector3d centre = view.camera_from_table * table_from_object * mesh.BoundingBox().center();
  if (centre.z() <= 0.1) return false;
  const Eigen::Vector2d pixel = view.camera.Project(centre);
  const double margin = 40.0;
  return pixel.x() >= margin && pixel.y() >= margin && pixel.x() <= view.camera.width - 1 - margin &&
         pixel.y() <= view.camera.height - 1 - margin;
}

// The pose of an object resting in `resting`, turned by `yaw` about the vertical and moved to `centre_mm`.
Eigen::Isometry3d TableFromObject(const Eigen::Vector2d& centre_mm, double yaw, const RestingPose& resting) {
  Eigen::Isometry3d table_from_rested = Eigen::Isometry3d::Identity();
  table_from_rested.translation() << centre_mm / 1000.0, 0.0;
  table_from_rested.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return table_from_rested * resting.table_from_object;
}

// One object in one of its resting poses (by support area) at a random yaw and place in view, not overlapping the
// `placed` ones and pushed to within `max_gap_m` of one of them; none when no place is found.
std::optional<Placed> PlaceObject(const SceneAsset& asset, size_t index, const std::vector<RestingPose>& poses,
                                  const View& view, const std::vector<Placed>& placed, double max_gap_m,
                                  std::mt19937& rng) {
  std::vector<double> areas;
  for (const RestingPose& pose : poses) areas.push_back(std::max(pose.support_area_m2, 1e-9));
  const RestingPose& resting = poses[std::discrete_distribution<size_t>(areas.begin(), areas.end())(rng)];
  const std::vector<cv::Point2f> base = Footprint(asset.mesh, resting.table_from_object);
  for (int attempt = 0; attempt < kPlacementAttempts; ++attempt) {
    const double yaw = Uniform(rng, 0.0, 2.0 * kPi);
    const double across = Uniform(rng, -0.2, 0.2);  // draws in sequence: the order of operands is unspecified
    const double along = Uniform(rng, -0.15, 0.15);
    const Eigen::Vector3d place = view.look_at + across * view.right + along * view.forward;
    const double target_gap_mm = 1000.0 * Uniform(rng, 0.0, max_gap_m);
    Eigen::Vector2d centre_mm = 1000.0 * place.head<2>();
    Polygon footprint = Moved(base, yaw, centre_mm);
    if (OverlapsAny(footprint, placed) || !InView(view, asset.mesh, TableFromObject(centre_mm, yaw, resting))) continue;
    if (!placed.empty()) {
      footprint = PushTowardsNeighbour(base, yaw, placed, target_gap_mm, &centre_mm);
      const bool near = std::any_of(placed.begin(), placed.end(), [&](const Placed& p) {
        return Gap(footprint, p.footprint) <= 1000.0 * max_gap_m + 0.5;
      });
      if (!near) continue;
    }
    Placed object{index, TableFromObject(centre_mm, yaw, resting), std::move(footprint)};
    if (InView(view, asset.mesh, object.table_from_object)) return object;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------------------------------
// Table and wall

// A random cut of a backdrop (scale, place, flip), tiled 2 x 2 with mirrored copies so that it repeats without seams.
cv::Mat BackdropTexture(const Backdrops& backdrops, std::mt19937& rng) {
  const cv::Mat& image = backdrops.images[std::uniform_int_distribution<size_t>(0, backdrops.images.size() - 1)(rng)];
  const double scale = Uniform(rng, 0.4, 1.0);
  const int width = std::max(8, static_cast<int>(scale * image.cols));
  const int height = std::max(8, static_cast<int>(scale * image.rows));
  const int x = std::uniform_int_distribution<int>(0, image.cols - width)(rng);
  const int y = std::uniform_int_distribution<int>(0, image.rows - height)(rng);
  const int flip = std::uniform_int_distribution<int>(-1, 2)(rng);  // OpenCV's flip codes -1, 0, 1; 2: none
  cv::Mat tile;
  cv::resize(image(cv::Rect(x, y, width, height)), tile, cv::Size(512, 384), 0.0, 0.0, cv::INTER_AREA);
  if (flip < 2) cv::flip(tile, tile, flip);
  cv::Mat mirrored_x, mirrored_y, mirrored_xy, top, bottom, texture;
  cv::flip(tile, mirrored_x, 1);
  cv::flip(tile, mirrored_y, 0);
  cv::flip(tile, mirrored_xy, -1);
  cv::hconcat(tile, mirrored_x, top);
  cv::hconcat(mirrored_y, mirrored_xy, bottom);
  cv::vconcat(top, bottom, texture);
  return texture;
}

// A quad (corners in order around it, table frame) showing `texture` at the texture coordinates of its corners.
TriangleMesh TexturedQuad(const std::string& name, const std::array<Eigen::Vector3d, 4>& corners,
                          const std::array<Eigen::Vector2d, 4>& texcoords, cv::Mat texture) {
  TriangleMesh mesh;
  mesh.name = name;
  MeshMaterial material;
  material.name = name;
  material.texture = std::move(texture);
  mesh.materials.push_back(std::move(material));
  MeshPart part;
  for (size_t i = 0; i < 4; ++i) {
    part.positions.push_back(corners[i].cast<float>());
    part.texcoords.push_back(texcoords[i].cast<float>());
  }
  part.triangles = {{0, 1, 2}, {0, 2, 3}};
  part.material = 0;
  mesh.parts.push_back(std::move(part));
  return mesh;
}

// The table top (z = 0) up to a wall across the view behind the objects, each with a backdrop cut as texture.
std::array<TriangleMesh, 2> TableAndWall(const View& view, const Backdrops& backdrops, std::mt19937& rng) {
  const double wall_distance = Uniform(rng, 0.6, 1.0);
  const double tile = Uniform(rng, 0.3, 0.8);
  const double offset_u = Uniform(rng, 0.0, 1.0);
  const double offset_v = Uniform(rng, 0.0, 1.0);
  const Eigen::Vector2d offset(offset_u, offset_v);
  const auto table_point = [&](double a, double b) {
    return Eigen::Vector3d(view.look_at + a * view.right + b * view.forward);
  };
  const auto table_uv = [&](double a, double b) {
    return Eigen::Vector2d(offset + Eigen::Vector2d(a, b * 4.0 / 3.0) / (2.0 * tile));
  };
  TriangleMesh table = TexturedQuad(
      "table",
      {table_point(-2.5, -2.5), table_point(2.5, -2.5), table_point(2.5, wall_distance),
       table_point(-2.5, wall_distance)},
      {table_uv(-2.5, -2.5), table_uv(2.5, -2.5), table_uv(2.5, wall_distance), table_uv(-2.5, wall_distance)},
      BackdropTexture(backdrops, rng));
  const double wall_tile = Uniform(rng, 0.5, 1.2);
  const auto wall_point = [&](double a, double z) {
    return Eigen::Vector3d(table_point(a, wall_distance) + z * Eigen::Vector3d::UnitZ());
  };
  const auto wall_uv = [&](double a, double z) {
    return Eigen::Vector2d(Eigen::Vector2d(a, z * 4.0 / 3.0) / (2.0 * wall_tile));
  };
  TriangleMesh wall = TexturedQuad(
      "wall", {wall_point(-4.0, 0.0), wall_point(4.0, 0.0), wall_point(4.0, 3.0), wall_point(-4.0, 3.0)},
      {wall_uv(-4.0, 0.0), wall_uv(4.0, 0.0), wall_uv(4.0, 3.0), wall_uv(-4.0, 3.0)}, BackdropTexture(backdrops, rng));
  return {std::move(table), std::move(wall)};
}

// Meshes uploaded for one scene, removed when it is done.
class SceneMeshes {
 public:
  explicit SceneMeshes(Renderer& renderer) : renderer_(renderer) {}
  ~SceneMeshes() {
    try {
      for (MeshId id : ids_) renderer_.RemoveMesh(id);
    } catch (const RenderError&) {  // a context that cannot be made current any more frees its meshes anyway
    }
  }
  SceneMeshes(const SceneMeshes&) = delete;
  SceneMeshes& operator=(const SceneMeshes&) = delete;
  MeshId Add(const TriangleMesh& mesh) { return ids_.emplace_back(renderer_.AddMesh(mesh)); }

 private:
  Renderer& renderer_;
  std::vector<MeshId> ids_;
};

// ---------------------------------------------------------------------------------------------------------------------
// Light

// Camera-frame points of the pixels of `depth` (CV_32FC3; z = 0 where there is no surface).
cv::Mat BackProject(const cv::Mat& depth, const PinholeCamera& camera) {
  cv::Mat points(depth.size(), CV_32FC3, cv::Scalar::all(0));
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      if (z <= 0.0F) continue;
      points.at<cv::Vec3f>(v, u) = cv::Vec3f(static_cast<float>((u - camera.cx) / camera.fx * z),
                                             static_cast<float>((v - camera.cy) / camera.fy * z), z);
    }
  }
  return points;
}

// Unit normal at pixel (u, v) from its neighbours, on each axis the one nearer in depth (so not across an edge),
// turned towards the camera.
Eigen::Vector3f NormalAt(const cv::Mat& points, int u, int v) {
  const auto at = [&](int x, int y) {
    const cv::Vec3f& p = points.at<cv::Vec3f>(std::clamp(y, 0, points.rows - 1), std::clamp(x, 0, points.cols - 1));
    return Eigen::Vector3f(p[0], p[1], p[2]);
  };
  const Eigen::Vector3f centre = at(u, v);
  const auto difference = [&](const Eigen::Vector3f& before, const Eigen::Vector3f& after) -> Eigen::Vector3f {
    const bool use_after = after.z() > 0.0F &&
                           (before.z() <= 0.0F || std::abs(after.z() - centre.z()) < std::abs(centre.z() - before.z()));
    if (use_after) return after - centre;
    return before.z() > 0.0F ? Eigen::Vector3f(centre - before) : Eigen::Vector3f::Zero();
  };
  Eigen::Vector3f normal = difference(at(u - 1, v), at(u + 1, v)).cross(difference(at(u, v - 1), at(u, v + 1)));
  if (normal.norm() <= 0.0F) return -centre.normalized();
  normal.normalize();
  return normal.dot(centre) > 0.0F ? Eigen::Vector3f(-normal) : normal;
}

// The objects that cast shadows, in the table frame, and a sphere that holds them.
struct Casters {
  std::vector<SceneObject> objects;  // camera_from_object holds table_from_object
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

Casters CastersOf(const std::vector<SceneAsset>& assets, const std::vector<MeshId>& mesh_ids,
                  const std::vector<Placed>& placed) {
  Casters casters;
  for (const Placed& p : placed) {
    casters.objects.push_back({mesh_ids[p.asset], p.table_from_object});
    casters.centre.head<2>() += p.table_from_object.translation().head<2>() / static_cast<double>(placed.size());
  }
  for (const Placed& p : placed) {
    const Eigen::AlignedBox3d box = assets[p.asset].mesh.BoundingBox();
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d corner = p.table_from_object * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k));
      casters.radius = std::max(casters.radius, (corner - casters.centre).norm());
    }
  }
  return casters;
}

// Per pixel of `points` (camera frame), the share (0-255) of the light hidden by an object: a shadow map rendered from
// a pinhole camera far along the light's direction (`to_light`, table frame) with a view just holding the casters,
// compared at the 3 x 3 map pixels around the point's projection (percentage-closer filtering, soft edges).
cv::Mat Shadows(Renderer& renderer, const Casters& casters, const View& view, const cv::Mat& points,
                const Eigen::Vector3d& to_light) {
  const double range = std::clamp(casters.radius, 0.05, 0.5 * kLightDistanceM);
  PinholeCamera light_camera;
  light_camera.width = light_camera.height = kShadowMapSide;
  light_camera.fx = light_camera.fy = 0.5 * kShadowMapSide * (kLightDistanceM - range) / range;
  light_camera.cx = light_camera.cy = 0.5 * (kShadowMapSide - 1);
  const Eigen::Isometry3d light_from_table =
      CameraLookingAt(casters.centre + kLightDistanceM * to_light, casters.centre);
  std::vector<SceneObject> objects = casters.objects;
  for (SceneObject& object : objects) object.camera_from_object = light_from_table * object.camera_from_object;
  RenderOptions options;
  options.near_m = 0.1 * kLightDistanceM;
  options.far_m = 2.0 * kLightDistanceM;
  const cv::Mat light_depth = renderer.RenderScene(objects, light_camera, options).depth;
  const Eigen::Isometry3d light_from_camera = light_from_table * view.camera_from_table.inverse();
  cv::Mat shadow(points.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < points.rows; ++v) {
    for (int u = 0; u < points.cols; ++u) {
      const cv::Vec3f& p = points.at<cv::Vec3f>(v, u);
      if (p[2] <= 0.0F) continue;
      const Eigen::Vector3d q = light_from_camera * Eigen::Vector3d(p[0], p[1], p[2]);
      const Eigen::Vector2d pixel = light_camera.Project(q);
      const int x = static_cast<int>(std::lround(pixel.x())), y = static_cast<int>(std::lround(pixel.y()));
      if (x < 1 || y < 1 || x >= kShadowMapSide - 1 || y >= kShadowMapSide - 1) continue;
      int hidden = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const float occluder = light_depth.at<float>(y + dy, x + dx);
          hidden += occluder > 0.0F && q.z() - occluder > kShadowBiasM ? 1 : 0;
        }
      }
      shadow.at<uint8_t>(v, u) = static_cast<uint8_t>(hidden * 255 / 9);
    }
  }
  return shadow;
}

// Lambertian shading of `albedo` (CV_8UC3): albedo x gain x (ambient + (1 - ambient) max(0, n.l) lit), lit = 1 - the
// share of `shadow` (CV_8UC1, 0-255; empty: no shadows).
cv::Mat Shade(const cv::Mat& albedo, const cv::Mat& points, const cv::Mat& shadow,
              const Eigen::Vector3d& to_light_camera, const Eigen::Vector3d& gain, double ambient) {
  const Eigen::Vector3f light = to_light_camera.cast<float>();
  const Eigen::Vector3f gain_f = gain.cast<float>();
  const float ambient_f = static_cast<float>(ambient);
  cv::Mat shaded(albedo.size(), CV_8UC3, cv::Scalar::all(0));
  for (int v = 0; v < albedo.rows; ++v) {
    for (int u = 0; u < albedo.cols; ++u) {
      if (points.at<cv::Vec3f>(v, u)[2] <= 0.0F) continue;
      const float lit = shadow.empty() ? 1.0F : 1.0F - shadow.at<uint8_t>(v, u) / 255.0F;
      const float direct = lit > 0.0F ? lit * std::max(0.0F, NormalAt(points, u, v).dot(light)) : 0.0F;
      const float brightness = ambient_f + (1.0F - ambient_f) * direct;
      const cv::Vec3b& a = albedo.at<cv::Vec3b>(v, u);
      cv::Vec3b& out = shaded.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) out[c] = cv::saturate_cast<uint8_t>(a[c] * gain_f[c] * brightness);
    }
  }
  return shaded;
}

// ---------------------------------------------------------------------------------------------------------------------
// Ground truth

struct Coverage {
  int pixels = 0;  // the object alone covers in the image
  cv::Rect box;    // of those pixels
};

// The object rendered alone, only over the image box its bounding box projects to.
Coverage RenderAlone(Renderer& renderer, MeshId mesh_id, const TriangleMesh& mesh, const PinholeCamera& camera,
                     const Eigen::Isometry3d& camera_from_object, const RenderOptions& options) {
  const Eigen::AlignedBox3d box = mesh.BoundingBox();
  cv::Rect window(0, 0, camera.width, camera.height);
  Eigen::AlignedBox2d projected;
  bool in_front = true;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner = camera_from_object * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k));
    in_front = in_front && corner.z() > options.near_m;
    if (in_front) projected.extend(camera.Project(corner));
  }
  if (in_front) {
    const cv::Point low(static_cast<int>(std::floor(projected.min().x())) - 2,
                        static_cast<int>(std::floor(projected.min().y())) - 2);
    const cv::Point high(static_cast<int>(std::ceil(projected.max().x())) + 3,
                         static_cast<int>(std::ceil(projected.max().y())) + 3);
    window &= cv::Rect(low, high);
  }
  if (window.empty()) return {};
  PinholeCamera crop = camera;
  crop.cx -= window.x;
  crop.cy -= window.y;
  crop.width = window.width;
  crop.height = window.height;
  const RenderResult alone = renderer.Render(mesh_id, crop, camera_from_object, options);
  Coverage coverage;
  coverage.pixels = cv::countNonZero(alone.mask);
  if (coverage.pixels > 0) coverage.box = cv::boundingRect(alone.mask) + window.tl();
  return coverage;
}

}  // namespace

void RenderedSceneOptions::Check() const {
  const std::string source = "rendered scene options";
  const auto range = [&](double low, double high, double domain_low, double domain_high, const char* field) {
    if (!std::isfinite(low) || !std::isfinite(high) || low < domain_low || high < low || high > domain_high) {
      ThrowInputError(
          source, field,
          "finite min <= max within [" + std::to_string(domain_low) + ", " + std::to_string(domain_high) + "]",
          std::to_string(low) + ".." + std::to_string(high));
    }
  };
  range(min_objects, max_objects, 1, 1000, "min_objects/max_objects");
  range(min_clutter, max_clutter, 0, 1000, "min_clutter/max_clutter");
  range(min_distance_m, max_distance_m, 0.1, 100.0, "min_distance_m/max_distance_m");
  range(min_elevation_deg, max_elevation_deg, 5.0, 89.0, "min_elevation_deg/max_elevation_deg");
  range(min_gain, max_gain, 0.0, 100.0, "min_gain/max_gain");
  range(min_intensity, max_intensity, 0.0, 100.0, "min_intensity/max_intensity");
  range(ambient, ambient, 0.0, 1.0, "ambient");
  range(max_gap_m, max_gap_m, 0.0, 1.0, "max_gap_m");
}

namespace {

// The camera: at a random distance, elevation and azimuth, looking at a point near the table's origin.
View DrawView(const RenderedSceneOptions& options, std::mt19937& rng) {
  View view;
  view.camera = YcbvCamera();
  const double distance = Uniform(rng, options.min_distance_m, options.max_distance_m);
  const double elevation = kRadiansPerDegree * Uniform(rng, options.min_elevation_deg, options.max_elevation_deg);
  const double azimuth = Uniform(rng, 0.0, 2.0 * kPi);
  const double look_x = Uniform(rng, -0.03, 0.03);
  const double look_y = Uniform(rng, -0.03, 0.03);
  view.look_at = Eigen::Vector3d(look_x, look_y, 0.0);
  const Eigen::Vector3d eye = view.look_at + distance * DirectionFromAngles(azimuth, elevation);
  view.camera_from_table = CameraLookingAt(eye, view.look_at);
  view.forward = -DirectionFromAngles(azimuth, 0.0);
  view.right = view.forward.cross(Eigen::Vector3d::UnitZ());
  return view;
}

// Chooses distinct modelled objects and clutter (counts from the options) and places them one after the other, in
// random order; an object that finds no place gives way to the next of its kind.
std::vector<Placed> PlaceObjects(const std::vector<SceneAsset>& assets, const View& view,
                                 const RenderedSceneOptions& options, std::mt19937& rng) {
  std::vector<size_t> candidates[2];  // [0] modelled, [1] clutter
  for (size_t i = 0; i < assets.size(); ++i) candidates[assets[i].modelled ? 0 : 1].push_back(i);
  for (std::vector<size_t>& kind : candidates) std::shuffle(kind.begin(), kind.end(), rng);
  const int modelled = std::uniform_int_distribution<int>(options.min_objects, options.max_objects)(rng);
  const int clutter = std::uniform_int_distribution<int>(options.min_clutter, options.max_clutter)(rng);
  std::vector<int> slots(static_cast<size_t>(modelled), 0);
  slots.resize(static_cast<size_t>(modelled + clutter), 1);
  std::shuffle(slots.begin(), slots.end(), rng);
  size_t next[2] = {0, 0};
  std::vector<Placed> placed;
  for (int kind : slots) {
    std::vector<size_t>& pool = candidates[kind];
    while (next[kind] < pool.size()) {
      const SceneAsset& asset = assets[pool[next[kind]]];
      const std::vector<RestingPose> computed =
          asset.resting_poses.empty() ? RestingPoses(asset.mesh) : std::vector<RestingPose>();
      const std::vector<RestingPose>& poses = asset.resting_poses.empty() ? computed : asset.resting_poses;
      std::optional<Placed> object;
      if (!poses.empty()) object = PlaceObject(asset, pool[next[kind]], poses, view, placed, options.max_gap_m, rng);
      ++next[kind];
      if (object) {
        placed.push_back(std::move(*object));
        break;
      }
    }
  }
  return placed;
}

void CheckSceneInputs(const std::vector<SceneAsset>& assets, const std::vector<MeshId>& mesh_ids,
                      const Backdrops& backdrops, const RenderedSceneOptions& options) {
  const std::string source = "rendered scene";
  if (mesh_ids.size() != assets.size()) {
    ThrowInputError(source, "mesh_ids", "one per asset (" + std::to_string(assets.size()) + ")",
                    std::to_string(mesh_ids.size()));
  }
  const auto modelled = std::count_if(assets.begin(), assets.end(), [](const SceneAsset& a) { return a.modelled; });
  if (modelled < options.min_objects) {
    ThrowInputError(source, "assets", "at least min_objects (" + std::to_string(options.min_objects) + ") modelled",
                    std::to_string(modelled));
  }
  if (backdrops.images.empty()) ThrowInputError(source, "backdrops", "at least one image");
  for (const cv::Mat& image : backdrops.images) {
    if (image.type() != CV_8UC3 || image.cols < 16 || image.rows < 16) {
      ThrowInputError(source, "backdrops", "CV_8UC3 images of at least 16 x 16 pixels");
    }
  }
}

// Paints the pixels of repainted objects (labels 1 + index) in their plain colour.
void Repaint(const std::vector<PlacedObject>& objects, const cv::Mat& labels, cv::Mat* color) {
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      const size_t label = labels.at<uint16_t>(v, u);
      if (label == 0 || label > objects.size() || objects[label - 1].paint.x() < 0.0F) continue;
      const Eigen::Vector3f& paint = objects[label - 1].paint;
      color->at<cv::Vec3b>(v, u) =
          cv::Vec3b(cv::saturate_cast<uint8_t>(255.0F * paint.x()), cv::saturate_cast<uint8_t>(255.0F * paint.y()),
                    cv::saturate_cast<uint8_t>(255.0F * paint.z()));
    }
  }
}

// Visible and unoccluded pixels of every object; the ground truth of the modelled ones seen to at least 10 %.
void FillGroundTruth(Renderer& renderer, const std::vector<SceneAsset>& assets, const std::vector<Placed>& placed,
                     const std::vector<MeshId>& mesh_ids, const RenderOptions& render_options,
                     const std::vector<int>& visible_pixels, RenderedScene* scene) {
  for (size_t i = 0; i < scene->objects.size(); ++i) {
    PlacedObject& object = scene->objects[i];
    const size_t asset = placed[i].asset;
    const Coverage alone = RenderAlone(renderer, mesh_ids[asset], assets[asset].mesh, scene->frame.rgbd.camera,
                                       object.camera_from_object, render_options);
    object.visible_pixels = visible_pixels[i];
    object.unoccluded_pixels = alone.pixels;
    if (!object.modelled || alone.pixels == 0 || 10 * object.visible_pixels < alone.pixels) continue;
    GroundTruth truth;
    truth.object_id = YcbvClassIndex(object.name);
    truth.object_name = object.name;
    truth.camera_from_object = object.camera_from_object;
    truth.visible_fraction = static_cast<double>(object.visible_pixels) / alone.pixels;
    truth.object_box = alone.box;
    truth.visible_box = cv::boundingRect(scene->labels == static_cast<int>(i + 1));
    scene->frame.ground_truth.push_back(truth);
  }
}

}  // namespace

RenderedScene GenerateRenderedScene(Renderer& renderer, const std::vector<SceneAsset>& assets,
                                    const std::vector<MeshId>& mesh_ids, const Backdrops& backdrops, uint32_t seed,
                                    const RenderedSceneOptions& options) {
  options.Check();
  CheckSceneInputs(assets, mesh_ids, backdrops, options);
  std::mt19937 rng(seed);
  const View view = DrawView(options, rng);
  const std::vector<Placed> placed = PlaceObjects(assets, view, options, rng);
  RenderedScene scene;
  scene.camera_from_table = view.camera_from_table;
  std::vector<SceneObject> objects;
  for (const Placed& p : placed) {
    const SceneAsset& asset = assets[p.asset];
    PlacedObject object;
    object.name = asset.name;
    object.modelled = asset.modelled;
    object.table_from_object = p.table_from_object;
    object.camera_from_object = view.camera_from_table * p.table_from_object;
    if (asset.repaint) object.paint = RandomPaint(rng);
    scene.objects.push_back(object);
    objects.push_back({mesh_ids[p.asset], object.camera_from_object});
  }
  const double light_azimuth = Uniform(rng, 0.0, 2.0 * kPi);
  const double light_elevation = kRadiansPerDegree * Uniform(rng, 30.0, 80.0);
  const Eigen::Vector3d to_light = DirectionFromAngles(light_azimuth, light_elevation);
  for (int c = 0; c < 3; ++c) scene.light_gain[c] = Uniform(rng, options.min_gain, options.max_gain);
  scene.light_gain *= Uniform(rng, options.min_intensity, options.max_intensity);
  scene.light_direction = view.camera_from_table.linear() * to_light;
  const std::array<TriangleMesh, 2> backdrop_meshes = TableAndWall(view, backdrops, rng);

  SceneMeshes uploaded(renderer);
  for (const TriangleMesh& mesh : backdrop_meshes) objects.push_back({uploaded.Add(mesh), view.camera_from_table});
  RenderOptions unlit;
  unlit.near_m = 0.05;
  unlit.far_m = 10.0;
  RenderResult image = renderer.RenderScene(objects, view.camera, unlit);
  Repaint(scene.objects, image.labels, &image.color);
  const cv::Mat points = BackProject(image.depth, view.camera);
  const cv::Mat shadow = options.shadows && !placed.empty()
                             ? Shadows(renderer, CastersOf(assets, mesh_ids, placed), view, points, to_light)
                             : cv::Mat();
  scene.frame.rgbd.color = Shade(image.color, points, shadow, scene.light_direction, scene.light_gain, options.ambient);
  SensorNoiseOptions noise;
  noise.seed = seed;
  scene.frame.rgbd.depth =
      options.sensor_noise ? SimulateStructuredLight(image.depth, view.camera, noise).depth : image.depth;
  scene.frame.rgbd.camera = view.camera;
  scene.frame.rgbd.name = "rendered/" + std::to_string(seed);
  scene.labels = image.labels;
  scene.labels.setTo(0, image.labels > static_cast<int>(placed.size()));
  FillGroundTruth(renderer, assets, placed, mesh_ids, unlit, image.visible_pixels, &scene);
  return scene;
}

}  // namespace ecv::bench
