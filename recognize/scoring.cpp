#include "recognize/scoring.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "ecv/surface.h"

namespace ecv {
namespace {

// Whether two correspondences can both be true (ConsistencyOptions).
bool Consistent(const Primitive& object_a, const Primitive& scene_a, const Primitive& object_b,
                const Primitive& scene_b, const ConsistencyOptions& options) {
  const auto tolerance_m = static_cast<float>(options.tolerance_m);
  const auto angle_tolerance = static_cast<float>(options.angle_tolerance);
  Eigen::Vector3f object_line = object_b.position - object_a.position;
  Eigen::Vector3f scene_line = scene_b.position - scene_a.position;
  const float object_distance = object_line.norm(), scene_distance = scene_line.norm();
  if (object_distance < static_cast<float>(options.min_distance_m) ||
      object_distance > static_cast<float>(options.max_distance_m) ||
      std::abs(object_distance - scene_distance) > tolerance_m) {
    return false;
  }
  object_line /= object_distance;
  scene_line /= scene_distance;
  auto agree = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                   const Eigen::Vector3f& d) {
    return std::abs(std::abs(a.dot(b)) - std::abs(c.dot(d))) <= angle_tolerance;
  };
  return agree(object_a.orientation, object_b.orientation, scene_a.orientation, scene_b.orientation) &&
         agree(object_a.orientation, object_line, scene_a.orientation, scene_line) &&
         agree(object_b.orientation, object_line, scene_b.orientation, scene_line);
}

}  // namespace

void ConsistencyOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("consistency options", field, expected);
  };
  require(tolerance_m > 0.0, "tolerance_m", "> 0 m");
  require(angle_tolerance > 0.0, "angle_tolerance", "> 0");
  require(min_distance_m >= 0.0 && max_distance_m > min_distance_m, "max_distance_m", "> min_distance_m >= 0 m");
}

int ConsistentSetSize(const std::vector<Primitive>& object, const std::vector<Primitive>& scene,
                      const std::vector<Correspondence>& correspondences, const ConsistencyOptions& options) {
  options.Check();
  const size_t n = correspondences.size();
  std::vector<std::vector<int>> partners(n);
  std::vector<char> agree(n * n, 0);
  for (size_t a = 0; a < n; ++a) {
    const Primitive& object_a = object[static_cast<size_t>(correspondences[a].object)];
    const Primitive& scene_a = scene[static_cast<size_t>(correspondences[a].scene)];
    for (size_t b = a + 1; b < n; ++b) {
      if (!Consistent(object_a, scene_a, object[static_cast<size_t>(correspondences[b].object)],
                      scene[static_cast<size_t>(correspondences[b].scene)], options)) {
        continue;
      }
      agree[a * n + b] = agree[b * n + a] = 1;
      partners[a].push_back(static_cast<int>(b));
      partners[b].push_back(static_cast<int>(a));
    }
  }
  int best = n > 0 ? 1 : 0;
  for (size_t a = 0; a < n; ++a) {
    if (static_cast<int>(partners[a].size()) < best) continue;  // cannot grow a larger set
    std::vector<int>& candidates = partners[a];
    std::vector<int> degree(candidates.size(), 0);
    for (size_t x = 0; x < candidates.size(); ++x) {
      for (const int y : candidates)
        degree[x] += agree[static_cast<size_t>(candidates[x]) * n + static_cast<size_t>(y)];
    }
    std::vector<size_t> order(candidates.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return degree[x] > degree[y]; });
    std::vector<int> set;
    for (const size_t x : order) {
      const int candidate = candidates[x];
      if (std::all_of(set.begin(), set.end(), [&](int member) {
            return agree[static_cast<size_t>(member) * n + static_cast<size_t>(candidate)] != 0;
          })) {
        set.push_back(candidate);
      }
    }
    best = std::max(best, static_cast<int>(set.size()) + 1);
  }
  return best;
}

void PlanePatchOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("plane patch options", field, expected);
  };
  require(distance_m > 0.0, "distance_m", "> 0 m");
  require(min_share > 0.0 && min_share <= 1.0, "min_share", "in (0, 1]");
  require(min_points >= 3, "min_points", "at least 3");
}

bool PatchOfLargerPlane(const std::vector<Eigen::Vector3f>& surface, const std::vector<Eigen::Vector3f>& ring,
                        const PlanePatchOptions& options) {
  options.Check();
  const auto min_points = static_cast<size_t>(options.min_points);
  if (surface.size() < min_points || ring.size() < min_points) return false;
  const Plane plane = FitPlane(surface);
  auto mostly_on_plane = [&](const std::vector<Eigen::Vector3f>& points) {
    const auto on_plane = std::count_if(points.begin(), points.end(), [&](const Eigen::Vector3f& point) {
      return std::abs((point - plane.centroid).dot(plane.normal)) <= options.distance_m;
    });
    return static_cast<double>(on_plane) >= options.min_share * static_cast<double>(points.size());
  };
  return mostly_on_plane(surface) && mostly_on_plane(ring);
}

cv::Mat DepthSteps(const cv::Mat& depth, double step_m, int grow_px) {
  if (depth.type() != CV_32FC1) ThrowInputError("depth steps", "depth", "a CV_32FC1 image in metres");
  if (!(step_m > 0.0)) ThrowInputError("depth steps", "step_m", "> 0 m");
  if (grow_px < 0) ThrowInputError("depth steps", "grow_px", ">= 0 pixels");
  cv::Mat steps = cv::Mat::zeros(depth.size(), CV_8UC1);
  const auto step = static_cast<float>(step_m);
  auto apart = [&](float a, float b) { return (a > 0.0F) != (b > 0.0F) || std::abs(a - b) > step; };
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      if (u + 1 < depth.cols && apart(z, depth.at<float>(v, u + 1)))
        steps.at<uchar>(v, u) = steps.at<uchar>(v, u + 1) = 255;
      if (v + 1 < depth.rows && apart(z, depth.at<float>(v + 1, u)))
        steps.at<uchar>(v, u) = steps.at<uchar>(v + 1, u) = 255;
    }
  }
  if (grow_px > 0) {
    cv::dilate(steps, steps, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * grow_px + 1, 2 * grow_px + 1)));
  }
  return steps;
}

OutlineOnSteps OutlineOnDepthSteps(const cv::Mat& rendered_depth, int stride, const cv::Mat& scene_depth,
                                   const cv::Mat& scene_steps, double hidden_margin_m) {
  if (rendered_depth.type() != CV_32FC1 || scene_depth.type() != CV_32FC1) {
    ThrowInputError("outline on depth steps", "rendered_depth/scene_depth", "CV_32FC1 images in metres");
  }
  if (scene_steps.size() != scene_depth.size() || scene_steps.type() != CV_8UC1) {
    ThrowInputError("outline on depth steps", "scene_steps", "a CV_8UC1 image of the scene depth's size");
  }
  if (stride < 1) ThrowInputError("outline on depth steps", "stride", "at least 1");
  const auto margin = static_cast<float>(hidden_margin_m);
  // Beyond the image counts as on the object: where the image cuts an object off, that is not its outline.
  auto on_object = [&](int u, int v) {
    return u < 0 || v < 0 || u >= rendered_depth.cols || v >= rendered_depth.rows ||
           rendered_depth.at<float>(v, u) > 0.0F;
  };
  OutlineOnSteps outline;
  for (int v = 0; v < rendered_depth.rows; ++v) {
    for (int u = 0; u < rendered_depth.cols; ++u) {
      if (rendered_depth.at<float>(v, u) <= 0.0F) continue;
      if (on_object(u - 1, v) && on_object(u + 1, v) && on_object(u, v - 1) && on_object(u, v + 1)) continue;
      const int scene_u = u * stride, scene_v = v * stride;
      if (scene_u >= scene_depth.cols || scene_v >= scene_depth.rows) continue;
      const float scene_z = scene_depth.at<float>(scene_v, scene_u);
      if (scene_z > 0.0F && scene_z < rendered_depth.at<float>(v, u) - margin) continue;  // hidden
      ++outline.seen;
      if (scene_steps.at<uchar>(scene_v, scene_u) != 0) ++outline.on_step;
    }
  }
  return outline;
}

cv::Mat DepthNormals(const cv::Mat& depth, const PinholeCamera& camera, int reach, double max_step_m) {
  if (depth.type() != CV_32FC1) ThrowInputError("depth normals", "depth", "a CV_32FC1 image in metres");
  if (reach < 1) ThrowInputError("depth normals", "reach", "at least 1 pixel", std::to_string(reach));
  if (camera.width != depth.cols || camera.height != depth.rows) {
    ThrowInputError("depth normals", "camera", "the depth image's size");
  }
  const auto max_step = static_cast<float>(max_step_m);
  cv::Mat normals(depth.size(), CV_32FC3, cv::Scalar::all(0.0));
  auto point = [&](int u, int v, float z) -> Eigen::Vector3f {
    return camera.BackProject(Eigen::Vector2d(u, v), z).cast<float>();
  };
  for (int v = reach; v + reach < depth.rows; ++v) {
    for (int u = reach; u + reach < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      if (z <= 0.0F) continue;
      const float left = depth.at<float>(v, u - reach), right = depth.at<float>(v, u + reach);
      const float up = depth.at<float>(v - reach, u), down = depth.at<float>(v + reach, u);
      bool surface = true;
      for (const float neighbour : {left, right, up, down}) {
        surface = surface && neighbour > 0.0F && std::abs(neighbour - z) <= max_step;
      }
      if (!surface) continue;
      Eigen::Vector3f normal = (point(u + reach, v, right) - point(u - reach, v, left))
                                   .cross(point(u, v + reach, down) - point(u, v - reach, up));
      if (normal.norm() <= 0.0F) continue;
      normal.normalize();
      if (normal.dot(point(u, v, z)) > 0.0F) normal = -normal;  // facing the camera
      normals.at<cv::Vec3f>(v, u) = cv::Vec3f(normal.x(), normal.y(), normal.z());
    }
  }
  return normals;
}

void OccludingContourOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("occluding contour options", field, expected);
  };
  require(step_m > 0.0, "step_m", "> 0 m");
  require(gap >= 1 && gap <= 20, "gap", "in [1, 20] samples");
  require(crease_angle_deg > 0.0 && crease_angle_deg < 180.0, "crease_angle_deg", "in (0, 180) degrees");
}

OccludingContour OccludingContourSteps(const cv::Mat& rendered_depth, int stride, const cv::Mat& scene_depth,
                                       const cv::Mat& scene_normals, double surface_tolerance_m,
                                       const OccludingContourOptions& options) {
  if (rendered_depth.type() != CV_32FC1 || scene_depth.type() != CV_32FC1) {
    ThrowInputError("occluding contour", "rendered_depth/scene_depth", "CV_32FC1 images in metres");
  }
  if (!scene_normals.empty() && (scene_normals.type() != CV_32FC3 || scene_normals.size() != rendered_depth.size())) {
    ThrowInputError("occluding contour", "scene_normals", "a CV_32FC3 image of the rendered depth's size");
  }
  if (stride < 1) ThrowInputError("occluding contour", "stride", "at least 1");
  options.Check();
  const auto tolerance = static_cast<float>(surface_tolerance_m);
  const auto step = static_cast<float>(options.step_m);
  const auto crease_cos = static_cast<float>(std::cos(options.crease_angle_deg * 3.14159265358979323846 / 180.0));
  auto inside_image = [&](int u, int v) {
    return u >= 0 && v >= 0 && u < rendered_depth.cols && v < rendered_depth.rows;
  };
  // Beyond the image counts as on the object: where the image cuts an object off, that is not its outline.
  auto on_object = [&](int u, int v) { return !inside_image(u, v) || rendered_depth.at<float>(v, u) > 0.0F; };
  // The scene's depth at sample (u, v) of the render; -1 outside the frame.
  auto scene_at = [&](int u, int v) {
    const int scene_u = u * stride, scene_v = v * stride;
    if (scene_u < 0 || scene_v < 0 || scene_u >= scene_depth.cols || scene_v >= scene_depth.rows) return -1.0F;
    return scene_depth.at<float>(scene_v, scene_u);
  };
  // The scene's normal at sample (u, v) of the render; zero outside or where the depth does not tell.
  auto normal_at = [&](int u, int v) { return inside_image(u, v) ? scene_normals.at<cv::Vec3f>(v, u) : cv::Vec3f(); };
  OccludingContour contour;
  for (int v = 0; v < rendered_depth.rows; ++v) {
    for (int u = 0; u < rendered_depth.cols; ++u) {
      const float model_z = rendered_depth.at<float>(v, u);
      if (model_z <= 0.0F) continue;
      Eigen::Vector2f outward = Eigen::Vector2f::Zero();  // towards the neighbours off the object
      for (const auto& [du, dv] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
        if (!on_object(u + du, v + dv)) outward += Eigen::Vector2f(static_cast<float>(du), static_cast<float>(dv));
      }
      const float scene_z = scene_at(u, v);
      if (outward.isZero() || scene_z < 0.0F) continue;               // inside, or an outline beyond the frame
      if (scene_z > 0.0F && scene_z < model_z - tolerance) continue;  // hidden
      ++contour.seen;
      if (scene_z <= 0.0F || std::abs(scene_z - model_z) > tolerance) continue;  // the scene is not the model here
      outward.normalize();
      auto along = [&](int k) {  // the sample k steps outwards (k < 0: inwards)
        return cv::Point(u + static_cast<int>(std::lround(k * outward.x())),
                         v + static_cast<int>(std::lround(k * outward.y())));
      };
      bool stepping_back = false;
      for (int k = 1; k <= options.gap && !stepping_back; ++k) {
        const float beyond = scene_at(along(k).x, along(k).y);
        stepping_back = beyond == 0.0F || beyond > scene_z + step;
      }
      if (stepping_back) {
        ++contour.stepping_back;
        continue;
      }
      if (scene_normals.empty()) continue;
      const cv::Point in = along(-options.gap), out = along(options.gap);
      const cv::Vec3f inner = normal_at(in.x, in.y), outer = normal_at(out.x, out.y);
      if (inner != cv::Vec3f() && outer != cv::Vec3f() && inner.dot(outer) < crease_cos) ++contour.creased;
    }
  }
  return contour;
}

double ContourFactor(const OutlineOnSteps& outline, double free, double falloff, int min_seen) {
  if (falloff <= 0.0 || outline.seen < min_seen) return 1.0;
  return std::clamp(1.0 - (free - outline.Share()) / falloff, 0.0, 1.0);
}

void ContinuationOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("continuation options", field, expected);
  };
  require(window_px >= 2 && window_px <= 200, "window_px", "in [2, 200] pixels");
  require(min_gap_px >= 0 && min_gap_px <= max_gap_px, "min_gap_px", ">= 0 and at most max_gap_px");
  require(max_gap_px <= window_px, "max_gap_px", "at most window_px");
  require(tolerance_m > 0.0, "tolerance_m", "> 0 m");
  require(max_fit_rms_m > 0.0, "max_fit_rms_m", "> 0 m");
  require(min_samples >= 3, "min_samples", "at least 3");
}

OutlineContinuation SurfaceContinuation(const cv::Mat& rendered_depth, int stride, const cv::Mat& scene_depth,
                                        double surface_tolerance_m, const ContinuationOptions& options) {
  options.Check();
  if (rendered_depth.type() != CV_32FC1 || scene_depth.type() != CV_32FC1) {
    ThrowInputError("surface continuation", "rendered_depth/scene_depth", "CV_32FC1 images in metres");
  }
  if (stride < 1 || rendered_depth.rows != (scene_depth.rows + stride - 1) / stride ||
      rendered_depth.cols != (scene_depth.cols + stride - 1) / stride) {
    ThrowInputError("surface continuation", "rendered_depth", "the scene depth's size / stride");
  }
  const int rows = rendered_depth.rows, cols = rendered_depth.cols;
  // The scene at the render's samples, and where it shows the model's surface.
  cv::Mat scene(rows, cols, CV_32FC1), surface = cv::Mat::zeros(rows, cols, CV_8UC1);
  const auto on_surface_m = static_cast<float>(surface_tolerance_m);
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      const float z = scene_depth.at<float>(v * stride, u * stride);
      const float model_z = rendered_depth.at<float>(v, u);
      scene.at<float>(v, u) = z;
      if (model_z > 0.0F && z > 0.0F && std::abs(z - model_z) <= on_surface_m) surface.at<uchar>(v, u) = 1;
    }
  }
  // Distance of every sample off the model to the model's nearest one, in samples.
  cv::Mat off_model = rendered_depth <= 0.0F, distance;
  cv::distanceTransform(off_model, distance, cv::DIST_L2, 3);
  const int window = std::max(1, options.window_px / stride);
  const auto min_gap = static_cast<float>(options.min_gap_px) / static_cast<float>(stride);
  const auto max_gap = static_cast<float>(options.max_gap_px) / static_cast<float>(stride);
  const auto min_samples = static_cast<size_t>(options.min_samples);
  auto on_model = [&](int u, int v) {
    return u < 0 || v < 0 || u >= cols || v >= rows || rendered_depth.at<float>(v, u) > 0.0F;
  };
  OutlineContinuation continuation;
  std::vector<cv::Point> outside;
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      if (surface.at<uchar>(v, u) == 0) continue;
      if (on_model(u - 1, v) && on_model(u + 1, v) && on_model(u, v - 1) && on_model(u, v + 1)) continue;
      // The surface inside as a plane: inverse depth is affine in the pixel coordinates for a plane.
      const cv::Rect box =
          cv::Rect(u - window, v - window, 2 * window + 1, 2 * window + 1) & cv::Rect(0, 0, cols, rows);
      Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
      Eigen::Vector3d right = Eigen::Vector3d::Zero();
      size_t inside = 0;
      outside.clear();
      for (int y = box.y; y < box.y + box.height; ++y) {
        for (int x = box.x; x < box.x + box.width; ++x) {
          if (surface.at<uchar>(y, x) != 0) {
            const Eigen::Vector3d row(x - u, y - v, 1.0);
            normal += row * row.transpose();
            right += row / scene.at<float>(y, x);
            ++inside;
          } else if (rendered_depth.at<float>(y, x) <= 0.0F && distance.at<float>(y, x) >= min_gap &&
                     distance.at<float>(y, x) <= max_gap && scene.at<float>(y, x) > 0.0F) {
            outside.emplace_back(x, y);
          }
        }
      }
      if (inside < min_samples || outside.size() < min_samples) continue;
      const Eigen::Vector3d plane = normal.ldlt().solve(right);
      auto plane_depth = [&](int x, int y) { return 1.0 / plane.dot(Eigen::Vector3d(x - u, y - v, 1.0)); };
      double squares = 0.0;
      for (int y = box.y; y < box.y + box.height; ++y) {
        for (int x = box.x; x < box.x + box.width; ++x) {
          if (surface.at<uchar>(y, x) == 0) continue;
          const double residual = scene.at<float>(y, x) - plane_depth(x, y);
          squares += residual * residual;
        }
      }
      if (!(std::sqrt(squares / static_cast<double>(inside)) <= options.max_fit_rms_m)) continue;
      const auto on_plane = std::count_if(outside.begin(), outside.end(), [&](const cv::Point& p) {
        const double z = plane_depth(p.x, p.y);
        return z > 0.0 && std::abs(scene.at<float>(p) - z) <= options.tolerance_m;
      });
      ++continuation.tested;
      if (2 * static_cast<size_t>(on_plane) > outside.size()) ++continuation.continued;
    }
  }
  return continuation;
}

double ContinuationFactor(const OutlineContinuation& continuation, double free, double falloff, int min_tested) {
  if (falloff <= 0.0 || continuation.tested < min_tested) return 1.0;
  return std::clamp(1.0 - (continuation.Share() - free) / falloff, 0.0, 1.0);
}

cv::Mat GreyGradient(const cv::Mat& grey) {
  if (grey.type() != CV_8UC1) ThrowInputError("grey gradient", "grey", "a CV_8UC1 image");
  cv::Mat du, dv, gradient;
  cv::Sobel(grey, du, CV_32F, 1, 0, 3);
  cv::Sobel(grey, dv, CV_32F, 0, 1, 3);
  cv::merge(std::vector<cv::Mat>{du, dv}, gradient);
  return gradient;
}

void EdgeOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("edge options", field, expected);
  };
  require(strong > 0.0, "strong", "> 0");
  require(weak >= 0.0, "weak", ">= 0");
  require(min_cos >= 0.0 && min_cos <= 1.0, "min_cos", "in [0, 1]");
}

EdgeAgreement CompareEdges(const cv::Mat& model_gradient, const cv::Mat& scene_gradient,
                           const std::vector<cv::Point>& pixels, const EdgeOptions& options) {
  options.Check();
  if (model_gradient.type() != CV_32FC2 || scene_gradient.type() != CV_32FC2 ||
      model_gradient.size() != scene_gradient.size()) {
    ThrowInputError("compare edges", "model_gradient/scene_gradient", "CV_32FC2 images of one size");
  }
  const cv::Rect image(cv::Point(0, 0), model_gradient.size());
  const auto strong = static_cast<float>(options.strong), weak = static_cast<float>(options.weak);
  const auto min_cos = static_cast<float>(options.min_cos);
  EdgeAgreement agreement;
  for (const cv::Point& p : pixels) {
    if (!image.contains(p)) ThrowInputError("compare edges", "pixels", "pixels inside the gradient images");
    const cv::Vec2f& m = model_gradient.at<cv::Vec2f>(p);
    const float model_norm = std::hypot(m[0], m[1]);
    if (model_norm < strong) continue;
    ++agreement.predicted;
    const cv::Vec2f& s = scene_gradient.at<cv::Vec2f>(p);
    const float scene_norm = std::hypot(s[0], s[1]);
    if (scene_norm >= weak && std::abs(m[0] * s[0] + m[1] * s[1]) >= min_cos * model_norm * scene_norm) {
      ++agreement.shown;
    }
  }
  return agreement;
}

double Appearance(double color, const EdgeAgreement& edges, double weight, int min_edges) {
  if (weight <= 0.0 || edges.predicted < std::max(1, min_edges)) return color;
  return std::pow(std::max(0.0, color), 1.0 - weight) * std::pow(edges.Share(), weight);
}

// Normalised cross-correlation of (model, scene) colour pairs: the smaller of two. Per channel (averaged), it
// ignores each channel's gain and offset: a white balance, a colour cast. Over all channels at once (one gain and
// one offset), it keeps the hue: per channel alone, a red label and a blue one with the same light-dark pattern
// correlate perfectly (on YCB-Video the absent tomato soup can was reported on the blue master chef can).
double ColorCorrelation(const std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>>& colors) {
  constexpr double kPlainSpread = 0.02;  // standard deviation of a plain channel's colours, 0..1 (5 of 255)
  constexpr size_t kMinPixels = 10;
  if (colors.size() < kMinPixels) return 0.0;
  Eigen::Vector3f model_mean = Eigen::Vector3f::Zero(), scene_mean = Eigen::Vector3f::Zero();
  for (const auto& [model, scene] : colors) {
    model_mean += model;
    scene_mean += scene;
  }
  model_mean /= static_cast<float>(colors.size());
  scene_mean /= static_cast<float>(colors.size());
  const float model_grey = model_mean.mean(), scene_grey = scene_mean.mean();
  Eigen::Vector3f cross = Eigen::Vector3f::Zero(), model_variance = cross, scene_variance = cross;
  double joint_cross = 0.0, joint_model = 0.0, joint_scene = 0.0;
  for (const auto& [model, scene] : colors) {
    const Eigen::Vector3f a = model - model_mean, b = scene - scene_mean;
    cross += a.cwiseProduct(b);
    model_variance += a.cwiseProduct(a);
    scene_variance += b.cwiseProduct(b);
    const Eigen::Array3f joint_a = model.array() - model_grey, joint_b = scene.array() - scene_grey;
    joint_cross += (joint_a * joint_b).sum();
    joint_model += joint_a.square().sum();
    joint_scene += joint_b.square().sum();
  }
  // A channel in which the model is plain (its spread within the noise of a render) says nothing per channel: its
  // correlation is weighed down, and where the model is plain in all three only the joint term (the hue) is left.
  const double noise = kPlainSpread * kPlainSpread * static_cast<double>(colors.size());
  double per_channel = 0.0, weights = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double weight = model_variance[k] / (model_variance[k] + noise);
    per_channel += weight * cross[k] / std::sqrt(std::max(1e-9F, model_variance[k] * scene_variance[k]));
    weights += weight;
  }
  const double joint = joint_cross / std::sqrt(std::max(1e-12, joint_model * joint_scene));
  if (weights < 1e-9) return std::max(0.0, joint);
  const double textured = weights / 3.0;
  return std::max(0.0, textured * std::min(per_channel / weights, joint) + (1.0 - textured) * joint);
}

}  // namespace ecv
