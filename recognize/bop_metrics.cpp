#include "recognize/bop_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace ecv {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A 4x4 row-major matrix of 16 numbers as a rigid transformation (translation times `unit_to_m`).
Eigen::Isometry3d SymmetryFromJson(const nlohmann::json& values, double unit_to_m, const std::string& source,
                                   const std::string& field) {
  if (!values.is_array() || values.size() != 16 ||
      !std::all_of(values.begin(), values.end(), [](const nlohmann::json& v) { return v.is_number(); })) {
    ThrowInputError(source, field, "16 numbers, a 4x4 row-major transformation", values.dump());
  }
  Eigen::Matrix4d matrix;
  for (int k = 0; k < 16; ++k) matrix(k / 4, k % 4) = values[static_cast<size_t>(k)].get<double>();
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  if (!matrix.allFinite() || !(rotation * rotation.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-4)) {
    ThrowInputError(source, field, "a rotation and a translation", values.dump());
  }
  Eigen::Isometry3d symmetry = Eigen::Isometry3d::Identity();
  symmetry.linear() = rotation;
  symmetry.translation() = matrix.topRightCorner<3, 1>() * unit_to_m;
  return symmetry;
}

Eigen::Vector3d Vector3FromJson(const nlohmann::json& values, const std::string& source, const std::string& field) {
  if (!values.is_array() || values.size() != 3 ||
      !std::all_of(values.begin(), values.end(), [](const nlohmann::json& v) { return v.is_number(); })) {
    ThrowInputError(source, field, "3 numbers", values.dump());
  }
  return {values[0].get<double>(), values[1].get<double>(), values[2].get<double>()};
}

// The turns about each continuous symmetry's axis through its offset, the identity first.
std::vector<Eigen::Isometry3d> ContinuousTurns(const nlohmann::json& symmetries, double unit_to_m,
                                               const std::string& source, double max_step_rad) {
  std::vector<Eigen::Isometry3d> turns = {Eigen::Isometry3d::Identity()};
  if (!symmetries.is_array()) ThrowInputError(source, "symmetries_continuous", "an array", symmetries.dump());
  for (size_t i = 0; i < symmetries.size(); ++i) {
    const std::string field = "symmetries_continuous[" + std::to_string(i) + "]";
    const nlohmann::json& symmetry = symmetries[i];
    if (!symmetry.is_object() || !symmetry.contains("axis") || !symmetry.contains("offset")) {
      ThrowInputError(source, field, "an object with \"axis\" and \"offset\"", symmetry.dump());
    }
    const Eigen::Vector3d axis = Vector3FromJson(symmetry["axis"], source, field + ".axis");
    const Eigen::Vector3d offset = Vector3FromJson(symmetry["offset"], source, field + ".offset") * unit_to_m;
    if (!(axis.norm() > 0.0) || !axis.allFinite() || !offset.allFinite()) {
      ThrowInputError(source, field + ".axis", "a finite axis of non-zero length", symmetry.dump());
    }
    const int steps = static_cast<int>(std::ceil(kPi / max_step_rad));
    for (int k = 1; k < steps; ++k) {  // the identity is already there
      Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
      turn.linear() = Eigen::AngleAxisd(2.0 * kPi * k / steps, axis.normalized()).toRotationMatrix();
      turn.translation() = offset - turn.linear() * offset;  // about the axis through `offset`
      turns.push_back(turn);
    }
  }
  return turns;
}

// Max over points of the distance between their images under `estimate` and `truth * symmetry`, minimised over the
// symmetries; `distance` maps two camera-frame points to their distance.
template <typename Distance>
double MinMaxDistance(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& estimate,
                      const Eigen::Isometry3d& truth, const std::vector<Eigen::Isometry3d>& symmetries,
                      Distance distance) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Isometry3d& symmetry : symmetries) {
    const Eigen::Isometry3d truth_turned = truth * symmetry;
    double worst = 0.0;
    for (const Eigen::Vector3f& point : points) {
      const Eigen::Vector3d x = point.cast<double>();
      worst = std::max(worst, distance(estimate * x, truth_turned * x));
      if (worst >= best) break;  // this symmetry cannot do better
    }
    best = std::min(best, worst);
  }
  return best;
}

// Distance from the camera centre of each pixel's depth (BOP compares distances, not depths); 0 where no depth.
cv::Mat DistanceImage(const cv::Mat& depth, const PinholeCamera& camera) {
  cv::Mat distance(depth.size(), CV_32F);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      const double x = (u - camera.cx) / camera.fx, y = (v - camera.cy) / camera.fy;
      distance.at<float>(v, u) = z > 0.0F ? static_cast<float>(z * std::sqrt(x * x + y * y + 1.0)) : 0.0F;
    }
  }
  return distance;
}

// BOP 2019's visibility: where the rendering has a surface at most delta behind the test surface, or the test image
// has none.
bool Visible(float rendered, float test, double delta_m) {
  return rendered > 0.0F && (test == 0.0F || rendered - test <= delta_m);
}

void CheckDepth(const cv::Mat& depth, const PinholeCamera& camera, const std::string& which) {
  if (depth.type() != CV_32F || depth.cols != camera.width || depth.rows != camera.height) {
    ThrowInputError(
        "VSD", which,
        "a CV_32F depth image of " + std::to_string(camera.width) + "x" + std::to_string(camera.height) + " pixels");
  }
}

}  // namespace

std::vector<Eigen::Isometry3d> BopSymmetries(const nlohmann::json& model_info, double unit_to_m,
                                             const std::string& source, double max_step_rad) {
  if (!model_info.is_object()) ThrowInputError(source, "model info", "a JSON object", model_info.dump());
  if (!(max_step_rad > 0.0)) ThrowInputError(source, "symmetry step", "an angle > 0 rad");
  std::vector<Eigen::Isometry3d> discrete = {Eigen::Isometry3d::Identity()};
  if (model_info.contains("symmetries_discrete")) {
    const nlohmann::json& symmetries = model_info["symmetries_discrete"];
    if (!symmetries.is_array()) ThrowInputError(source, "symmetries_discrete", "an array", symmetries.dump());
    for (size_t i = 0; i < symmetries.size(); ++i) {
      discrete.push_back(
          SymmetryFromJson(symmetries[i], unit_to_m, source, "symmetries_discrete[" + std::to_string(i) + "]"));
    }
  }
  const std::vector<Eigen::Isometry3d> turns =
      model_info.contains("symmetries_continuous")
          ? ContinuousTurns(model_info["symmetries_continuous"], unit_to_m, source, max_step_rad)
          : std::vector<Eigen::Isometry3d>{Eigen::Isometry3d::Identity()};
  std::vector<Eigen::Isometry3d> combined;
  combined.reserve(discrete.size() * turns.size());
  for (const Eigen::Isometry3d& d : discrete) {
    for (const Eigen::Isometry3d& turn : turns) combined.push_back(turn * d);
  }
  return combined;
}

double Mssd(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& estimate,
            const Eigen::Isometry3d& truth, const std::vector<Eigen::Isometry3d>& symmetries) {
  return MinMaxDistance(points, estimate, truth, symmetries,
                        [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return (a - b).norm(); });
}

double Mspd(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& estimate,
            const Eigen::Isometry3d& truth, const std::vector<Eigen::Isometry3d>& symmetries,
            const PinholeCamera& camera) {
  const auto pixel = [&](const Eigen::Vector3d& x) {  // BOP projects without a check of z
    return Eigen::Vector2d(camera.fx * x.x() / x.z() + camera.cx, camera.fy * x.y() / x.z() + camera.cy);
  };
  return MinMaxDistance(points, estimate, truth, symmetries, [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return (pixel(a) - pixel(b)).norm();
  });
}

std::vector<double> Vsd(const cv::Mat& depth_estimate, const cv::Mat& depth_truth, const cv::Mat& depth_test,
                        const PinholeCamera& camera, double delta_m, const std::vector<double>& taus_m) {
  CheckDepth(depth_estimate, camera, "estimate's depth");
  CheckDepth(depth_truth, camera, "truth's depth");
  CheckDepth(depth_test, camera, "test image's depth");
  const cv::Mat estimate = DistanceImage(depth_estimate, camera);
  const cv::Mat truth = DistanceImage(depth_truth, camera);
  const cv::Mat test = DistanceImage(depth_test, camera);
  std::vector<float> both_differences;  // |estimate - truth| where both are visible
  long long in_union = 0, in_one_only = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const float e = estimate.at<float>(v, u), t = truth.at<float>(v, u), d = test.at<float>(v, u);
      const bool truth_visible = Visible(t, d, delta_m);
      const bool estimate_visible = Visible(e, d, delta_m) || (truth_visible && e > 0.0F);
      if (!truth_visible && !estimate_visible) continue;
      ++in_union;
      if (truth_visible && estimate_visible) {
        both_differences.push_back(std::abs(e - t));
      } else {
        ++in_one_only;
      }
    }
  }
  std::vector<double> errors;
  for (const double tau : taus_m) {
    if (in_union == 0) {
      errors.push_back(1.0);
      continue;
    }
    const auto over = std::count_if(both_differences.begin(), both_differences.end(),
                                    [tau](float difference) { return difference >= tau; });
    errors.push_back(static_cast<double>(over + in_one_only) / static_cast<double>(in_union));
  }
  return errors;
}

std::vector<double> BopFractions() {
  std::vector<double> fractions;
  for (int k = 1; k <= 10; ++k) fractions.push_back(0.05 * k);
  return fractions;
}

std::vector<double> BopMspdThresholdsPx(int width) {
  std::vector<double> thresholds;
  for (int k = 1; k <= 10; ++k) thresholds.push_back(5.0 * k * width / 640.0);
  return thresholds;
}

namespace {

// Instances of `object` matched at a threshold: `error(e)` of an estimate-instance pair, correct below `threshold`.
template <typename Error>
int Matched(const BopObjectErrors& object, double threshold, Error error) {
  std::vector<bool> taken(static_cast<size_t>(object.instances), false);
  int matched = 0;
  for (const std::vector<BopPoseErrors>& estimate : object.errors) {
    int best = -1;
    for (int i = 0; i < object.instances; ++i) {
      const double e = error(estimate[static_cast<size_t>(i)]);
      if (!taken[static_cast<size_t>(i)] && e < threshold &&
          (best < 0 || e < error(estimate[static_cast<size_t>(best)]))) {
        best = i;
      }
    }
    if (best >= 0) taken[static_cast<size_t>(best)] = true, ++matched;
  }
  return matched;
}

void CheckErrors(const BopObjectErrors& object, size_t taus) {
  for (const std::vector<BopPoseErrors>& estimate : object.errors) {
    if (estimate.size() != static_cast<size_t>(object.instances)) {
      ThrowInputError("average recall", "errors of an estimate",
                      "one per instance (" + std::to_string(object.instances) + ")", std::to_string(estimate.size()));
    }
    for (const BopPoseErrors& e : estimate) {
      if (e.vsd.size() != taus) {
        ThrowInputError("average recall", "VSD errors", "one per tau (" + std::to_string(taus) + ")",
                        std::to_string(e.vsd.size()));
      }
    }
  }
}

}  // namespace

BopRecall AverageRecall(const std::vector<BopObjectErrors>& objects, int width) {
  const std::vector<double> fractions = BopFractions();
  const std::vector<double> pixels = BopMspdThresholdsPx(width);
  BopRecall recall;
  for (const BopObjectErrors& object : objects) {
    CheckErrors(object, fractions.size());
    recall.instances += object.instances;
    for (size_t t = 0; t < fractions.size(); ++t) {
      for (const double theta : fractions) {
        recall.ar_vsd += Matched(object, theta, [t](const BopPoseErrors& e) { return e.vsd[t]; });
      }
    }
    for (const double fraction : fractions) {
      recall.ar_mssd += Matched(object, fraction * object.diameter_m, [](const BopPoseErrors& e) { return e.mssd_m; });
    }
    for (const double threshold : pixels) {
      recall.ar_mspd += Matched(object, threshold, [](const BopPoseErrors& e) { return e.mspd_px; });
    }
  }
  if (recall.instances == 0) return recall;
  const double n = recall.instances;
  const double thresholds = static_cast<double>(fractions.size());
  recall.ar_vsd /= n * thresholds * thresholds;
  recall.ar_mssd /= n * thresholds;
  recall.ar_mspd /= n * static_cast<double>(pixels.size());
  recall.ar = (recall.ar_vsd + recall.ar_mssd + recall.ar_mspd) / 3.0;
  return recall;
}

}  // namespace ecv
