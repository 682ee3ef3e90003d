// Composites of real frames: an object cut from one YCB-Video frame by its label mask, moved rigidly from its table
// onto another frame's table, its pixels reprojected through their depth and pasted under a z-test.

#include "scenes/composites.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include <Eigen/Eigenvalues>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/points_io.h"
#include "scenes/composite_warp.h"

namespace ecv::bench {
namespace {

constexpr int kPlaneStride = 4;            // pixel grid of the plane fit
constexpr int kPlaneIterations = 300;      // RANSAC iterations of the plane fit
constexpr double kPlaneInlierM = 0.01;     // a depth sample within this of the plane is on it
constexpr int kLabelMarginPx = 7;          // objects' label masks are widened by this before the plane fit
constexpr double kSupportM = 0.02;         // a footprint pixel is table when within this of the plane
constexpr int kMinSupportPixels = 20;      // footprint pixels that must show the table
constexpr double kCollisionSlackM = 0.01;  // objects may come this much closer than the sum of their radii

double Radians(double degrees) {
  return degrees * M_PI / 180.0;
}

// An object's place relative to a table: centroid of its model points, its foot on the plane, its horizontal
// radius about the centroid and the height of its lowest point.
struct Footing {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d foot = Eigen::Vector3d::Zero();
  double radius = 0.0;
  double lowest = 0.0;
};

Footing FootingOf(const std::vector<Eigen::Vector3d>& points, const Eigen::Isometry3d& camera_from_object,
                  const TablePlane& table) {
  Footing footing;
  for (const Eigen::Vector3d& point : points) footing.centre += camera_from_object * point;
  footing.centre /= static_cast<double>(std::max<size_t>(points.size(), 1));
  footing.lowest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& point : points) {
    const Eigen::Vector3d offset = camera_from_object * point - footing.centre;
    footing.radius = std::max(footing.radius, (offset - table.normal * table.normal.dot(offset)).norm());
    footing.lowest = std::min(footing.lowest, table.Height(camera_from_object * point));
  }
  footing.foot = footing.centre - table.normal * table.Height(footing.centre);
  return footing;
}

const GroundTruth& TruthOf(const SourceFrame& frame, const std::string& object_name, const std::string& field) {
  for (const GroundTruth& truth : frame.frame.ground_truth) {
    if (truth.object_name == object_name) return truth;
  }
  ThrowInputError(frame.prefix + "-meta.mat", field, "an object " + object_name + " in cls_indexes", "none");
}

const std::vector<Eigen::Vector3d>& PointsOf(const SourceFrame& frame, const std::string& object_name) {
  const auto found = frame.model_points.find(object_name);
  if (found == frame.model_points.end() || found->second.empty()) {
    ThrowInputError(frame.prefix, "model_points", "the points.xyz of " + object_name, "none");
  }
  return found->second;
}

// "0002-000001" of ".../0002/000001".
std::string FrameTag(const std::string& prefix) {
  const std::filesystem::path path(prefix);
  return path.parent_path().filename().string() + "-" + path.filename().string();
}

enum class Rejection { kNone, kViewChanged, kLeftImage, kUnsupported, kCollided, kHidTarget };

// What stays fixed over the attempts of one composite.
struct Setting {
  const SourceFrame& source;
  const SourceFrame& target;
  const GroundTruth& truth;                    // the pasted object's, in the source
  const std::vector<Eigen::Vector3d>& points;  // its model points
  const CompositeOptions& options;
  Footing pasted;                   // on the source table
  std::vector<Footing> neighbours;  // the target's objects on its table, in the order of its ground truth
  Cut cut;
};

// The part of a composite that stays fixed over its placements.
Setting Prepare(const SourceFrame& source, const GroundTruth& truth, const std::vector<Eigen::Vector3d>& points,
                const SourceFrame& target, const CompositeOptions& options) {
  Setting setting{source, target, truth, points, options, {}, {}, CutObject(source, truth, points, options)};
  setting.pasted = FootingOf(points, truth.camera_from_object, source.table);
  for (const GroundTruth& other : target.frame.ground_truth) {
    setting.neighbours.push_back(
        FootingOf(PointsOf(target, other.object_name), other.camera_from_object, target.table));
  }
  return setting;
}

// The move that turns the object by `turn_rad` about the target table's normal after the least rotation taking the
// source table's normal to it, with its lowest point on the target table and its centre above `place`.
Eigen::Isometry3d MoveOnto(const Setting& setting, const Eigen::Vector3d& place, double turn_rad) {
  const TablePlane &from = setting.source.table, &to = setting.target.table;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(turn_rad, to.normal).toRotationMatrix() *
                                   Eigen::Quaterniond::FromTwoVectors(from.normal, to.normal).toRotationMatrix();
  Eigen::Isometry3d move = Eigen::Isometry3d::Identity();
  move.linear() = rotation;
  const double centre_height = from.Height(setting.pasted.centre) - setting.pasted.lowest;
  move.translation() = place + to.normal * centre_height - rotation * setting.pasted.centre;
  return move;
}

// Angle between the directions from the camera to the object's centre, in the object's frame, before and after
// `move`, degrees.
double ViewChangeDeg(const Setting& setting, const Eigen::Isometry3d& move) {
  const Eigen::Isometry3d& before = setting.truth.camera_from_object;
  const Eigen::Vector3d seen = before.linear().transpose() * setting.pasted.centre.normalized();
  const Eigen::Vector3d seen_after = (move * before).linear().transpose() * (move * setting.pasted.centre).normalized();
  return std::acos(std::clamp(seen.dot(seen_after), -1.0, 1.0)) * 180.0 / M_PI;
}

// Whether the object's footprint (its model points dropped onto the target table) shows the table where the target
// shows no object: min_support_share of those pixels within kSupportM of the plane.
bool Supported(const Setting& setting, const Eigen::Isometry3d& move) {
  const TablePlane& table = setting.target.table;
  const RgbdFrame& rgbd = setting.target.frame.rgbd;
  int seen = 0, on_table = 0;
  for (size_t i = 0; i < setting.points.size(); i += 4) {
    const Eigen::Vector3d point = move * (setting.truth.camera_from_object * setting.points[i]);
    const Eigen::Vector3d foot = point - table.normal * table.Height(point);
    if (foot.z() <= 0.0) continue;
    const Eigen::Vector2d pixel = rgbd.camera.Project(foot);
    if (!rgbd.camera.Contains(pixel)) continue;
    const int u = static_cast<int>(std::lround(pixel.x())), v = static_cast<int>(std::lround(pixel.y()));
    const float z = rgbd.depth.at<float>(v, u);
    if (z <= 0.0F || setting.target.labels.at<uint8_t>(v, u) != 0) continue;
    ++seen;
    on_table += std::abs(table.Height(rgbd.camera.BackProject(pixel, z))) < kSupportM ? 1 : 0;
  }
  return seen >= kMinSupportPixels && on_table >= setting.options.min_support_share * seen;
}

bool Collides(const Setting& setting, const Eigen::Vector3d& place) {
  for (const Footing& neighbour : setting.neighbours) {
    if ((place - neighbour.foot).norm() < setting.pasted.radius + neighbour.radius - kCollisionSlackM) return true;
  }
  return false;
}

// The largest share of a target object's labelled pixels that `shown` covers.
double HiddenShare(const SourceFrame& target, const cv::Mat& shown) {
  double largest = 0.0;
  for (const GroundTruth& truth : target.frame.ground_truth) {
    const cv::Mat object = target.labels == truth.object_id;
    const int pixels = cv::countNonZero(object);
    if (pixels == 0) continue;
    largest = std::max(largest, static_cast<double>(cv::countNonZero(object & shown)) / pixels);
  }
  return largest;
}

// Judges the placement `move` at `place`: cheap tests first, then the warp (returned in `warp` and `shown`).
Rejection Judge(const Setting& setting, const Eigen::Isometry3d& move, const Eigen::Vector3d& place, Warp* warp,
                cv::Mat* shown) {
  const CompositeOptions& options = setting.options;
  if (ViewChangeDeg(setting, move) > options.max_view_change_deg) return Rejection::kViewChanged;
  if (Collides(setting, place)) return Rejection::kCollided;
  if (!Supported(setting, move)) return Rejection::kUnsupported;
  const RgbdFrame& rgbd = setting.target.frame.rgbd;
  *warp = WarpCut(setting.cut, move, rgbd.camera, options.occlusion_tolerance_m);
  if (warp->inside < options.min_inside_share * warp->points) return Rejection::kLeftImage;
  *shown = ShownMask(*warp, rgbd.depth, setting.target.labels, options.occlusion_tolerance_m);
  if (HiddenShare(setting.target, *shown) > options.max_hidden_share) return Rejection::kHidTarget;
  return Rejection::kNone;
}

void Count(Rejection rejection, CompositeAttempts* log) {
  switch (rejection) {
    case Rejection::kViewChanged: ++log->view_changed; break;
    case Rejection::kLeftImage: ++log->left_image; break;
    case Rejection::kUnsupported: ++log->unsupported; break;
    case Rejection::kCollided: ++log->collided; break;
    case Rejection::kHidTarget: ++log->hid_target; break;
    case Rejection::kNone: break;
  }
}

// The composite of an accepted placement: the target's images, labels and ground truth with the object pasted.
Composite Assemble(const Setting& setting, const Eigen::Isometry3d& move, const Warp& warp, const cv::Mat& shown) {
  const SourceFrame &source = setting.source, &target = setting.target;
  Composite composite;
  composite.frame = target.frame;
  composite.frame.rgbd.color = target.frame.rgbd.color.clone();
  composite.frame.rgbd.depth = target.frame.rgbd.depth.clone();
  composite.labels = target.labels.clone();
  warp.color.copyTo(composite.frame.rgbd.color, shown);
  cv::Mat measured_float;
  warp.measured.convertTo(measured_float, CV_32F);
  const cv::Mat depth = warp.depth.mul(measured_float);  // holes of the source stay holes
  depth.copyTo(composite.frame.rgbd.depth, shown);
  composite.labels.setTo(setting.truth.object_id, shown);
  GroundTruth pasted = setting.truth;
  pasted.camera_from_object = move * setting.truth.camera_from_object;
  composite.pasted_pixels = cv::countNonZero(shown);
  const int warped_pixels = cv::countNonZero(warp.depth > 0.0F);
  pasted.visible_fraction = warped_pixels > 0 ? static_cast<double>(composite.pasted_pixels) / warped_pixels : 0.0;
  pasted.object_box = cv::boundingRect(warp.depth > 0.0F);
  pasted.visible_box = cv::boundingRect(shown);
  composite.frame.ground_truth.push_back(pasted);
  composite.frame.rgbd.name =
      "composite/" + FrameTag(source.prefix) + "-" + setting.truth.object_name + "-into-" + FrameTag(target.prefix);
  composite.frame.scene_id = composite.frame.image_id = -1;  // a new image
  composite.source_prefix = source.prefix;
  composite.target_prefix = target.prefix;
  composite.object_name = setting.truth.object_name;
  composite.target_from_source = move;
  composite.view_change_deg = ViewChangeDeg(setting, move);
  return composite;
}

// Why the object cannot be pasted into the target at all; "" when it can.
std::string Refusal(const SourceFrame& source, const GroundTruth& truth, const SourceFrame& target,
                    const CompositeOptions& options) {
  for (const GroundTruth& other : target.frame.ground_truth) {
    if (other.object_name == truth.object_name) return "the target holds " + truth.object_name + " already";
  }
  if (source.table.inliers == 0) return "no table plane in " + source.prefix;
  if (target.table.inliers == 0) return "no table plane in " + target.prefix;
  const double whole =
      WholeShare(PointsOf(source, truth.object_name), truth.camera_from_object, source, truth.object_id);
  if (whole < options.min_source_whole) {
    return truth.object_name + " is not whole in " + source.prefix + ": " + std::to_string(whole) +
           " of its model points on its label";
  }
  return "";
}

// A random place on the target table for the object's centre: beside the target's object `next_to` (an index into
// its ground truth, -1 for none) at a random gap in a random direction, or else under a random pixel. False when
// that pixel's ray misses the table.
bool SamplePlace(const Setting& setting, int next_to, std::mt19937* rng, Eigen::Vector3d* place) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const CompositeOptions& options = setting.options;
  const double angle = 2.0 * M_PI * unit(*rng);
  const double gap = options.min_gap_m + (options.max_gap_m - options.min_gap_m) * unit(*rng);
  const PinholeCamera& camera = setting.target.frame.rgbd.camera;
  const Eigen::Vector2d pixel(unit(*rng) * camera.width - 0.5, unit(*rng) * camera.height - 0.5);
  const TablePlane& table = setting.target.table;
  if (next_to >= 0) {
    const Footing& neighbour = setting.neighbours[static_cast<size_t>(next_to)];
    const Eigen::Vector3d across = table.normal.unitOrthogonal(), along = table.normal.cross(across);
    const double reach = neighbour.radius + setting.pasted.radius + gap;
    *place = neighbour.foot + reach * (std::cos(angle) * across + std::sin(angle) * along);
    return true;
  }
  const Eigen::Vector3d ray = camera.BackProject(pixel, 1.0);
  const double along_ray = -table.offset / table.normal.dot(ray);  // the plane's point on the ray
  if (!std::isfinite(along_ray) || along_ray <= 0.0) return false;
  *place = ray * along_ray;
  return true;
}

// The least-squares plane of the points within kPlaneInlierM of `plane` (the normal is their direction of least
// spread), its normal towards the camera; inliers 0 when fewer than 3 points are near `plane`, 1 otherwise.
TablePlane RefinedPlane(const std::vector<Eigen::Vector3d>& points, const TablePlane& plane) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  int count = 0;
  for (const Eigen::Vector3d& point : points) {
    if (std::abs(plane.Height(point)) >= kPlaneInlierM) continue;
    mean += point;
    scatter += point * point.transpose();
    ++count;
  }
  TablePlane refined;
  if (count < 3) return refined;
  mean /= count;
  scatter = scatter / count - mean * mean.transpose();
  refined.normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0).normalized();
  refined.offset = -refined.normal.dot(mean);
  if (refined.offset < 0.0) {  // the camera (the origin) lies on the side the normal points to
    refined.normal = -refined.normal;
    refined.offset = -refined.offset;
  }
  refined.inliers = 1;
  return refined;
}

}  // namespace

TablePlane FitTablePlane(const RgbdFrame& frame, const cv::Mat& labels, uint32_t seed) {
  cv::Mat objects = cv::Mat::zeros(frame.depth.size(), CV_8U);
  if (!labels.empty()) {
    const cv::Size margin(2 * kLabelMarginPx + 1, 2 * kLabelMarginPx + 1);
    cv::dilate(labels > 0, objects, cv::getStructuringElement(cv::MORPH_RECT, margin));
  }
  std::vector<Eigen::Vector3d> points;
  for (int v = 0; v < frame.depth.rows; v += kPlaneStride) {
    for (int u = 0; u < frame.depth.cols; u += kPlaneStride) {
      const float z = frame.depth.at<float>(v, u);
      if (z > 0.0F && objects.at<uint8_t>(v, u) == 0) points.push_back(frame.camera.BackProject({u, v}, z));
    }
  }
  TablePlane best;
  if (points.size() < 3) return best;
  auto count_inliers = [&](const TablePlane& plane) {
    return static_cast<int>(std::count_if(points.begin(), points.end(), [&](const Eigen::Vector3d& point) {
      return std::abs(plane.Height(point)) < kPlaneInlierM;
    }));
  };
  std::mt19937 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, points.size() - 1);
  for (int iteration = 0; iteration < kPlaneIterations; ++iteration) {
    const Eigen::Vector3d a = points[pick(rng)], b = points[pick(rng)], c = points[pick(rng)];
    TablePlane plane;
    plane.normal = (b - a).cross(c - a);
    if (plane.normal.norm() < 1e-9) continue;
    plane.normal.normalize();
    plane.offset = -plane.normal.dot(a);
    plane.inliers = count_inliers(plane);
    if (plane.inliers > best.inliers) best = plane;
  }
  TablePlane refined = RefinedPlane(points, best);
  refined.inliers = refined.inliers > 0 ? count_inliers(refined) : 0;
  return refined;
}

SourceFrame LoadSourceFrame(const std::string& prefix, const std::string& models_dir) {
  SourceFrame source;
  source.prefix = prefix;
  source.frame = LoadYcbvFrame(prefix);
  const std::string label_path = prefix + "-label.png";
  source.labels = cv::imread(label_path, cv::IMREAD_UNCHANGED);
  if (source.labels.empty() || source.labels.type() != CV_8UC1 ||
      source.labels.size() != source.frame.rgbd.depth.size()) {
    ThrowInputError(label_path, "label", "an 8-bit one-channel PNG of the frame's size");
  }
  const std::filesystem::path models =
      models_dir.empty() ? std::filesystem::path(prefix).parent_path().parent_path().parent_path() / "models"
                         : std::filesystem::path(models_dir);
  for (const GroundTruth& truth : source.frame.ground_truth) {
    if (source.model_points.count(truth.object_name) != 0) continue;
    source.model_points[truth.object_name] = ReadXyzFile((models / truth.object_name / "points.xyz").string());
  }
  source.table = FitTablePlane(source.frame.rgbd, source.labels, 0);
  return source;
}

void CompositeOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected, double got) {
    if (!ok) ThrowInputError("composite options", field, expected, std::to_string(got));
  };
  auto share = [&](double value, const char* field) {
    require(value >= 0.0 && value <= 1.0, field, "in [0, 1]", value);
  };
  require(max_view_change_deg > 0.0 && max_view_change_deg <= 180.0, "max_view_change_deg", "in (0, 180] degrees",
          max_view_change_deg);
  share(max_hidden_share, "max_hidden_share");
  require(min_gap_m >= 0.0 && min_gap_m <= 1.0, "min_gap_m", "in [0, 1] m", min_gap_m);
  require(max_gap_m >= min_gap_m && max_gap_m <= 1.0, "max_gap_m", "in [min_gap_m, 1] m", max_gap_m);
  require(attempts >= 1, "attempts", "at least 1", attempts);
  require(max_turn_deg >= 0.0 && max_turn_deg <= 180.0, "max_turn_deg", "in [0, 180] degrees", max_turn_deg);
  share(min_source_whole, "min_source_whole");
  require(max_label_depth_m > 0.0, "max_label_depth_m", "> 0 m", max_label_depth_m);
  require(max_surface_distance_m > 0.0, "max_surface_distance_m", "> 0 m", max_surface_distance_m);
  share(min_inside_share, "min_inside_share");
  share(min_support_share, "min_support_share");
  require(occlusion_tolerance_m >= 0.0 && occlusion_tolerance_m <= 0.1, "occlusion_tolerance_m", "in [0, 0.1] m",
          occlusion_tolerance_m);
}

bool MakeComposite(const SourceFrame& source, const std::string& object_name, const SourceFrame& target,
                   const std::string& beside, uint32_t seed, const CompositeOptions& options, Composite* out,
                   CompositeAttempts* attempts) {
  options.Check();
  if (out == nullptr) ThrowInputError("MakeComposite", "out", "a composite to fill", "null");
  CompositeAttempts unused;
  CompositeAttempts& log = attempts != nullptr ? *attempts : unused;
  log = CompositeAttempts();
  const GroundTruth& truth = TruthOf(source, object_name, "object_name");
  const std::vector<Eigen::Vector3d>& points = PointsOf(source, object_name);
  const int next_to =
      beside.empty() ? -1 : static_cast<int>(&TruthOf(target, beside, "beside") - target.frame.ground_truth.data());
  if (cv::countNonZero(source.labels == truth.object_id) == 0) {
    ThrowInputError(source.prefix + "-label.png", "label", "pixels of class " + std::to_string(truth.object_id));
  }
  log.refused = Refusal(source, truth, target, options);
  if (!log.refused.empty()) return false;
  const Setting setting = Prepare(source, truth, points, target, options);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Warp warp;
  cv::Mat shown;
  for (int attempt = 0; attempt < options.attempts; ++attempt) {
    ++log.tried;
    const double turn_rad = Radians(options.max_turn_deg) * (2.0 * unit(rng) - 1.0);
    Eigen::Vector3d place;
    const Rejection rejection = SamplePlace(setting, next_to, &rng, &place)
                                    ? Judge(setting, MoveOnto(setting, place, turn_rad), place, &warp, &shown)
                                    : Rejection::kLeftImage;
    Count(rejection, &log);
    if (rejection != Rejection::kNone) continue;
    *out = Assemble(setting, MoveOnto(setting, place, turn_rad), warp, shown);
    out->beside = beside;
    out->attempts = log;
    return true;
  }
  return false;
}

}  // namespace ecv::bench
