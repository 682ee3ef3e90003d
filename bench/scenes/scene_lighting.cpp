#include "scenes/scene_lighting.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace ecv::bench {
namespace {

constexpr double kShadowBiasM = 0.005;   // a point is in shadow when the light sees this much nearer, metres
constexpr double kLightDistanceM = 3.0;  // of the shadow map's camera from the scene centre, metres
constexpr int kShadowMapSide = 640;      // pixels a side, about 1 mm each over the objects

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

}  // namespace

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

namespace {

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

// The depth of the casters seen from the light: a pinhole camera far along the light's direction (`to_light`, table
// frame) with a view just holding them.
struct ShadowMap {
  PinholeCamera camera;
  Eigen::Isometry3d light_from_table;
  cv::Mat depth;  // CV_32FC1, metres; 0 where no caster is seen
};

ShadowMap RenderShadowMap(Renderer& renderer, const Casters& casters, const Eigen::Vector3d& to_light) {
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
  return {light_camera, light_from_table, renderer.RenderScene(objects, light_camera, options).depth};
}

}  // namespace

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

// Per pixel of `points` (camera frame), the share (0-255) of the light hidden by an object: the shadow map compared at
// the 3 x 3 map pixels around the point's projection (percentage-closer filtering, soft edges).
cv::Mat Shadows(Renderer& renderer, const Casters& casters, const View& view, const cv::Mat& points,
                const Eigen::Vector3d& to_light) {
  const ShadowMap map = RenderShadowMap(renderer, casters, to_light);
  const Eigen::Isometry3d light_from_camera = map.light_from_table * view.camera_from_table.inverse();
  cv::Mat shadow(points.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < points.rows; ++v) {
    for (int u = 0; u < points.cols; ++u) {
      const cv::Vec3f& p = points.at<cv::Vec3f>(v, u);
      if (p[2] <= 0.0F) continue;
      const Eigen::Vector3d q = light_from_camera * Eigen::Vector3d(p[0], p[1], p[2]);
      const Eigen::Vector2d pixel = map.camera.Project(q);
      const int x = static_cast<int>(std::lround(pixel.x())), y = static_cast<int>(std::lround(pixel.y()));
      if (x < 1 || y < 1 || x >= kShadowMapSide - 1 || y >= kShadowMapSide - 1) continue;
      int hidden = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const float occluder = map.depth.at<float>(y + dy, x + dx);
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

}  // namespace ecv::bench
