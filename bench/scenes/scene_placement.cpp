#include "scenes/scene_placement.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace ecv::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadiansPerDegree = kPi / 180.0;
constexpr double kOverlapMm2 = 0.1;     // footprints overlapping by less count as touching, square millimetres
constexpr int kPlacementAttempts = 40;  // random places tried per object

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

}  // namespace

double Uniform(std::mt19937& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
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

namespace {

// ---------------------------------------------------------------------------------------------------------------------
// Placement on the table: footprints in millimetres (float precision of cv::intersectConvexConvex).

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

}  // namespace

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

}  // namespace ecv::bench
