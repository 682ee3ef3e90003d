#include "scenes/rendered_scenes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
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
#include "scenes/scene_lighting.h"
#include "scenes/scene_placement.h"

namespace ecv::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadiansPerDegree = kPi / 180.0;
constexpr int kMaxTextureSide = 2048;  // google16k textures (4096) are capped to this in LoadSceneAssets

// YCB-Video's cls_index by name (YcbvClassName's inverse over its 21 objects), 0 for other names.
int YcbvClassIndex(const std::string& name) {
  constexpr int kClasses = 21;
  for (int index = 1; index <= kClasses; ++index) {
    if (name == YcbvClassName(index)) return index;
  }
  return 0;
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

// Where a scene asset's mesh is read from, and how.
struct AssetSource {
  std::string name, path;
  MeshLoadOptions load;
  bool modelled, repaint;
};

// The 6 google16k meshes (moved into the YCB-Video frame), the 10 other YCB-Video models (9 to repaint) and the 8 LM-O
// meshes as clutter.
std::vector<AssetSource> AssetSources(const std::string& data_dir) {
  const std::string ycbv = data_dir + "/ycbv_subset/";
  const auto to_ycbv = ReadTransformTable(ycbv + "derived/google16k_to_ycbv.txt");
  std::vector<AssetSource> sources;
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
  return sources;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------------
// Assets and backdrops

std::vector<SceneAsset> LoadSceneAssets(const std::string& data_dir) {
  const std::vector<AssetSource> sources = AssetSources(data_dir);
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

// The scene's objects as placed (a random paint for each repainted one, in drawing order) and what to render for them.
std::vector<SceneObject> DescribeObjects(const std::vector<SceneAsset>& assets, const std::vector<MeshId>& mesh_ids,
                                         const std::vector<Placed>& placed, const View& view, std::mt19937& rng,
                                         RenderedScene* scene) {
  std::vector<SceneObject> objects;
  for (const Placed& p : placed) {
    const SceneAsset& asset = assets[p.asset];
    PlacedObject object;
    object.name = asset.name;
    object.modelled = asset.modelled;
    object.table_from_object = p.table_from_object;
    object.camera_from_object = view.camera_from_table * p.table_from_object;
    if (asset.repaint) object.paint = RandomPaint(rng);
    scene->objects.push_back(object);
    objects.push_back({mesh_ids[p.asset], object.camera_from_object});
  }
  return objects;
}

// The light's colour and strength, and its direction in the camera frame (into `scene`); returns the direction towards
// the light in the table frame.
Eigen::Vector3d DrawLight(const RenderedSceneOptions& options, const View& view, std::mt19937& rng,
                          RenderedScene* scene) {
  const double light_azimuth = Uniform(rng, 0.0, 2.0 * kPi);
  const double light_elevation = kRadiansPerDegree * Uniform(rng, 30.0, 80.0);
  const Eigen::Vector3d to_light = DirectionFromAngles(light_azimuth, light_elevation);
  for (int c = 0; c < 3; ++c) scene->light_gain[c] = Uniform(rng, options.min_gain, options.max_gain);
  scene->light_gain *= Uniform(rng, options.min_intensity, options.max_intensity);
  scene->light_direction = view.camera_from_table.linear() * to_light;
  return to_light;
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
  std::vector<SceneObject> objects = DescribeObjects(assets, mesh_ids, placed, view, rng, &scene);
  const Eigen::Vector3d to_light = DrawLight(options, view, rng, &scene);
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
