#include "colorcal/color_matrix.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "core/error.h"

namespace ecv {
namespace {

constexpr const char* kSource = "colour pairs";

std::string Text(const Eigen::Vector3d& color) {
  std::ostringstream text;
  text << "(" << color[0] << ", " << color[1] << ", " << color[2] << ")";
  return text.str();
}

std::string Text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// At least 3 pairs, all finite.
void CheckPairs(const std::vector<ColorPair>& pairs) {
  if (pairs.size() < 3) {
    ThrowInputError(kSource, "count", "at least 3 pairs (A has 9 unknowns, each pair gives 3)",
                    std::to_string(pairs.size()));
  }
  for (size_t i = 0; i < pairs.size(); ++i) {
    for (const auto& [color, which] :
         {std::pair(&pairs[i].model, " model colour"), {&pairs[i].scene, " scene colour"}}) {
      if (!color->allFinite()) {
        ThrowInputError(kSource, "pair " + std::to_string(i + 1) + which, "finite RGB values", Text(*color));
      }
    }
  }
}

// sigma_max / sigma_min of the rows of model colours picked by `use` (infinity when rank-deficient).
double ConditionNumber(const std::vector<ColorPair>& pairs, const std::vector<bool>& use) {
  Eigen::MatrixX3d model(std::count(use.begin(), use.end(), true), 3);
  Eigen::Index row = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (use[i]) model.row(row++) = pairs[i].model.transpose();
  }
  const Eigen::Vector3d sigma = Eigen::JacobiSVD<Eigen::MatrixX3d>(model).singularValues();
  if (!(sigma[2] > sigma[0] * std::numeric_limits<double>::epsilon())) return std::numeric_limits<double>::infinity();
  return sigma[0] / sigma[2];
}

void RequireConditioned(double condition_number, double limit, const std::string& which) {
  if (condition_number <= limit) return;
  ThrowInputError(kSource, "condition number of the " + which + " model colours",
                  "at most " + Text(limit) +
                      " (ColorFitOptions::max_condition_number); the model colours must span RGB, not be all grey or "
                      "all one hue",
                  Text(condition_number));
}

// Weighted linear least squares: A minimising sum_i w_i |A m_i - s_i|^2 (rows of M A^T = S).
Eigen::Matrix3d SolveWeighted(const std::vector<ColorPair>& pairs, const std::vector<double>& weights) {
  Eigen::MatrixX3d model(pairs.size(), 3), scene(pairs.size(), 3);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const double root = std::sqrt(weights[i]);
    model.row(static_cast<Eigen::Index>(i)) = root * pairs[i].model.transpose();
    scene.row(static_cast<Eigen::Index>(i)) = root * pairs[i].scene.transpose();
  }
  return model.colPivHouseholderQr().solve(scene).transpose();
}

std::vector<double> Residuals(const std::vector<ColorPair>& pairs, const Eigen::Matrix3d& A) {
  std::vector<double> residuals(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) residuals[i] = (A * pairs[i].model - pairs[i].scene).norm();
  return residuals;
}

std::vector<bool> Below(const std::vector<double>& residuals, double threshold) {
  std::vector<bool> inliers(residuals.size());
  for (size_t i = 0; i < residuals.size(); ++i) inliers[i] = residuals[i] < threshold;
  return inliers;
}

std::vector<double> ToWeights(const std::vector<bool>& inliers) {
  return {inliers.begin(), inliers.end()};
}

// The 3-pair samples of RANSAC: every triple when there are at most `max_samples`, otherwise random ones (seeded).
class TripleSampler {
 public:
  TripleSampler(size_t n, int max_samples, uint64_t seed) : n_(n), random_(seed) {
    const double all = static_cast<double>(n) * static_cast<double>(n - 1) * static_cast<double>(n - 2) / 6.0;
    exhaustive_ = all <= max_samples;
    count_ = exhaustive_ ? static_cast<int>(all) : max_samples;
  }
  int count() const { return count_; }

  std::array<size_t, 3> Next() {
    if (exhaustive_) return NextTriple();
    std::uniform_int_distribution<size_t> pick(0, n_ - 1);
    std::array<size_t, 3> sample{pick(random_), 0, 0};
    do sample[1] = pick(random_);
    while (sample[1] == sample[0]);
    do sample[2] = pick(random_);
    while (sample[2] == sample[0] || sample[2] == sample[1]);
    return sample;
  }

 private:
  std::array<size_t, 3> NextTriple() {
    const std::array<size_t, 3> current = triple_;
    if (++triple_[2] == n_) {
      if (++triple_[1] == n_ - 1) triple_[1] = ++triple_[0] + 1;
      triple_[2] = triple_[1] + 1;
    }
    return current;
  }

  size_t n_;
  std::mt19937_64 random_;
  bool exhaustive_ = false;
  int count_ = 0;
  std::array<size_t, 3> triple_{0, 1, 2};
};

// Tukey's biweight IRLS from `A`. The cut-off of each step is 4.685 robust standard deviations (1.4826 times the
// median residual), but at least `threshold`: it shrinks as the fit improves, so that a start pulled by outliers
// does not reject everything, and on real pairs (shading: heavy-tailed residuals, no clear outliers) it adapts.
Eigen::Matrix3d TukeyIrls(const std::vector<ColorPair>& pairs, Eigen::Matrix3d A, double threshold, int max_steps,
                          int* steps) {
  for (*steps = 0; *steps < max_steps;) {
    ++*steps;
    const std::vector<double> residuals = Residuals(pairs, A);
    std::vector<double> sorted = residuals;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double cutoff = std::max(threshold, 4.685 * 1.4826 * sorted[sorted.size() / 2]);
    std::vector<double> weights(pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
      const double u = residuals[i] / cutoff;
      weights[i] = u < 1.0 ? (1.0 - u * u) * (1.0 - u * u) : 0.0;
    }
    if (std::count_if(weights.begin(), weights.end(), [](double w) { return w > 0.0; }) < 3) break;
    const Eigen::Matrix3d next = SolveWeighted(pairs, weights);
    const double change = (next - A).norm();
    A = next;
    if (change < 1e-9) break;
  }
  return A;
}

// RANSAC: exact A from 3 pairs (samples whose model colours are worse conditioned than the limit are skipped),
// scored by the truncated squared residual (MSAC); least squares on the best one's inliers, then Tukey IRLS.
ColorFit FitRansac(const std::vector<ColorPair>& pairs, const ColorFitOptions& options) {
  TripleSampler sampler(pairs.size(), options.max_iterations, options.seed);
  const double cap = options.inlier_threshold * options.inlier_threshold;
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  for (int sample = 0; sample < sampler.count(); ++sample) {
    Eigen::Matrix3d model, scene;  // rows: the sample's colours
    const std::array<size_t, 3> triple = sampler.Next();
    for (int k = 0; k < 3; ++k) {
      model.row(k) = pairs[triple[k]].model.transpose();
      scene.row(k) = pairs[triple[k]].scene.transpose();
    }
    const Eigen::Vector3d sigma = Eigen::JacobiSVD<Eigen::Matrix3d>(model).singularValues();
    if (!(sigma[0] <= options.max_condition_number * sigma[2])) continue;  // degenerate sample: A is not determined
    const Eigen::Matrix3d A = model.partialPivLu().solve(scene).transpose();
    double cost = 0.0;
    for (const ColorPair& pair : pairs) cost += std::min((A * pair.model - pair.scene).squaredNorm(), cap);
    if (cost < best_cost) best_cost = cost, best = A;
  }
  if (!std::isfinite(best_cost)) {
    ThrowInputError(
        kSource, "RANSAC samples",
        "a 3-pair sample with a condition number within max_condition_number " + Text(options.max_condition_number),
        "none in " + std::to_string(sampler.count()));
  }
  const std::vector<bool> inliers = Below(Residuals(pairs, best), options.inlier_threshold);  // >= 3: the sample's
  ColorFit fit;
  fit.A = SolveWeighted(pairs, ToWeights(inliers));
  int steps = 0;
  if (options.polish) fit.A = TukeyIrls(pairs, fit.A, options.inlier_threshold, options.max_iterations, &steps);
  fit.iterations = sampler.count();
  return fit;
}

}  // namespace

const char* ToString(ColorFitMethod method) {
  switch (method) {
    case ColorFitMethod::kLeastSquares: return "least squares";
    case ColorFitMethod::kRansac: return "RANSAC + IRLS";
    case ColorFitMethod::kTukeyIrls: return "Tukey IRLS";
  }
  return "?";
}

void ColorFitOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("colour fit options", field, expected);
  };
  require(max_condition_number >= 1.0, "max_condition_number", "at least 1 (sigma_max / sigma_min)");
  require(inlier_threshold > 0.0 && std::isfinite(inlier_threshold), "inlier_threshold", "> 0 (RGB units in [0, 1])");
  require(max_iterations >= 1, "max_iterations", "at least 1");
}

ColorFit FitColorMatrix(const std::vector<ColorPair>& pairs, const ColorFitOptions& options) {
  options.Check();
  CheckPairs(pairs);
  RequireConditioned(ConditionNumber(pairs, std::vector<bool>(pairs.size(), true)), options.max_condition_number,
                     "given");
  const std::vector<double> ones(pairs.size(), 1.0);
  ColorFit fit;
  switch (options.method) {
    case ColorFitMethod::kLeastSquares: fit.A = SolveWeighted(pairs, ones); break;
    case ColorFitMethod::kRansac: fit = FitRansac(pairs, options); break;
    case ColorFitMethod::kTukeyIrls:
      fit.A = TukeyIrls(pairs, SolveWeighted(pairs, ones), options.inlier_threshold, options.max_iterations,
                        &fit.iterations);
      break;
  }
  fit.inliers = options.method == ColorFitMethod::kLeastSquares
                    ? std::vector<bool>(pairs.size(), true)
                    : Below(Residuals(pairs, fit.A), options.inlier_threshold);
  fit.num_inliers = static_cast<int>(std::count(fit.inliers.begin(), fit.inliers.end(), true));
  if (fit.num_inliers < 3) {
    ThrowInputError(kSource, std::string(ToString(options.method)) + " inliers",
                    "at least 3 pairs within inlier_threshold " + Text(options.inlier_threshold) + " of one matrix",
                    std::to_string(fit.num_inliers));
  }
  fit.condition_number = ConditionNumber(pairs, fit.inliers);
  RequireConditioned(fit.condition_number, options.max_condition_number, "inlier");
  double squared_sum = 0.0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (fit.inliers[i]) squared_sum += (fit.A * pairs[i].model - pairs[i].scene).squaredNorm();
  }
  fit.rms = std::sqrt(squared_sum / fit.num_inliers);
  return fit;
}

Eigen::Vector3d ApplyColorMatrix(const Eigen::Matrix3d& A, const Eigen::Vector3d& color) {
  return (A * color).cwiseMax(0.0).cwiseMin(1.0);
}

cv::Mat ApplyColorMatrix(const Eigen::Matrix3d& A, const cv::Mat& rgb) {
  if (rgb.type() != CV_8UC3) {
    ThrowInputError("colour matrix", "image", "an 8-bit RGB image (CV_8UC3)", "type " + std::to_string(rgb.type()));
  }
  const Eigen::Matrix3f scaled = A.cast<float>();
  cv::Mat result(rgb.size(), CV_8UC3);
  for (int v = 0; v < rgb.rows; ++v) {
    const cv::Vec3b* in = rgb.ptr<cv::Vec3b>(v);
    cv::Vec3b* out = result.ptr<cv::Vec3b>(v);
    for (int u = 0; u < rgb.cols; ++u) {
      const Eigen::Vector3f color = scaled * Eigen::Vector3f(in[u][0], in[u][1], in[u][2]);
      for (int k = 0; k < 3; ++k) out[u][k] = cv::saturate_cast<uint8_t>(color[k]);  // rounds and clamps
    }
  }
  return result;
}

void ApplyColorMatrix(const Eigen::Matrix3d& A, std::vector<Primitive>* primitives) {
  for (Primitive& primitive : *primitives) {
    primitive.color = ApplyColorMatrix(A, primitive.color.cast<double>()).cast<float>();
  }
}

double MeanColorError(const std::vector<ColorPair>& pairs, const Eigen::Matrix3d& A) {
  if (pairs.empty()) return 0.0;
  double sum = 0.0;
  for (const ColorPair& pair : pairs) sum += (ApplyColorMatrix(A, pair.model) - pair.scene).norm();
  return sum / static_cast<double>(pairs.size());
}

}  // namespace ecv
