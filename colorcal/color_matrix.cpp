#include "colorcal/color_matrix.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
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

// Weighted linear least squares: A minimising sum_i w_i |A m_i - s_i|^2 (rows of M A^T = S); for the diagonal form
// each gain on its own, a_k = sum w m_k s_k / sum w m_k^2 (0 when the channel is 0 in every weighted pair).
Eigen::Matrix3d SolveLinear(const std::vector<ColorPair>& pairs, const std::vector<double>& weights,
                            ColorMatrixForm form) {
  if (form == ColorMatrixForm::kDiagonal) {
    Eigen::Vector3d numerator = Eigen::Vector3d::Zero(), denominator = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < pairs.size(); ++i) {
      numerator += weights[i] * pairs[i].model.cwiseProduct(pairs[i].scene);
      denominator += weights[i] * pairs[i].model.cwiseProduct(pairs[i].model);
    }
    Eigen::Vector3d gains = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) gains[k] = denominator[k] > 0.0 ? numerator[k] / denominator[k] : 0.0;
    return gains.asDiagonal();
  }
  Eigen::MatrixX3d model(pairs.size(), 3), scene(pairs.size(), 3);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const double root = std::sqrt(weights[i]);
    model.row(static_cast<Eigen::Index>(i)) = root * pairs[i].model.transpose();
    scene.row(static_cast<Eigen::Index>(i)) = root * pairs[i].scene.transpose();
  }
  return model.colPivHouseholderQr().solve(scene).transpose();
}

// The diagonal form needs every channel non-zero in some model colour (else its gain is not determined).
void RequireChannels(const std::vector<ColorPair>& pairs) {
  Eigen::Vector3d energy = Eigen::Vector3d::Zero();
  for (const ColorPair& pair : pairs) energy += pair.model.cwiseProduct(pair.model);
  for (int k = 0; k < 3; ++k) {
    if (!(energy[k] > 1e-12)) {
      ThrowInputError(kSource, std::string("channel ") + "RGB"[k] + " of the model colours",
                      "non-zero in some pair (the diagonal form fits one gain per channel)", "zero in every pair");
    }
  }
}

// c_scene = A c_model + b (b = 0 unless ColorFitOptions::fit_offset).
struct ColorMap {
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
};

// SolveLinear, or with `offset` on the colours centred on their weighted means (b = mean scene - A mean model).
ColorMap SolveWeighted(const std::vector<ColorPair>& pairs, const std::vector<double>& weights, ColorMatrixForm form,
                       bool offset) {
  if (!offset) return {SolveLinear(pairs, weights, form), Eigen::Vector3d::Zero()};
  Eigen::Vector3d model_mean = Eigen::Vector3d::Zero(), scene_mean = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    model_mean += weights[i] * pairs[i].model, scene_mean += weights[i] * pairs[i].scene, total += weights[i];
  }
  model_mean /= total, scene_mean /= total;
  std::vector<ColorPair> centred = pairs;
  for (ColorPair& pair : centred) pair.model -= model_mean, pair.scene -= scene_mean;
  ColorMap map;
  map.A = SolveLinear(centred, weights, form);
  map.b = scene_mean - map.A * model_mean;
  return map;
}

std::vector<double> Residuals(const std::vector<ColorPair>& pairs, const ColorMap& map) {
  std::vector<double> residuals(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) residuals[i] = (map.A * pairs[i].model + map.b - pairs[i].scene).norm();
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
ColorMap TukeyIrls(const std::vector<ColorPair>& pairs, ColorMap map, double threshold, int max_steps,
                   ColorMatrixForm form, bool offset, int* steps) {
  for (*steps = 0; *steps < max_steps;) {
    ++*steps;
    const std::vector<double> residuals = Residuals(pairs, map);
    std::vector<double> sorted = residuals;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double cutoff = std::max(threshold, 4.685 * 1.4826 * sorted[sorted.size() / 2]);
    std::vector<double> weights(pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
      const double u = residuals[i] / cutoff;
      weights[i] = u < 1.0 ? (1.0 - u * u) * (1.0 - u * u) : 0.0;
    }
    if (std::count_if(weights.begin(), weights.end(), [](double w) { return w > 0.0; }) < 3) break;
    const ColorMap next = SolveWeighted(pairs, weights, form, offset);
    const double change = (next.A - map.A).norm() + (next.b - map.b).norm();
    map = next;
    if (change < 1e-9) break;
  }
  return map;
}

// The A of one 3-pair sample: exact for the full form (nullopt when the sample's model colours are worse conditioned
// than `max_condition_number`: A is not determined), least squares for the diagonal form (nullopt for a zero channel).
std::optional<Eigen::Matrix3d> SampleMatrix(const std::vector<ColorPair>& pairs, const std::array<size_t, 3>& triple,
                                            ColorMatrixForm form, double max_condition_number) {
  Eigen::Matrix3d model, scene;  // rows: the sample's colours
  for (int k = 0; k < 3; ++k) {
    model.row(k) = pairs[triple[k]].model.transpose();
    scene.row(k) = pairs[triple[k]].scene.transpose();
  }
  if (form == ColorMatrixForm::kDiagonal) {
    if (!((model.colwise().squaredNorm().array() > 1e-12).all())) return std::nullopt;
    const std::vector<ColorPair> sample = {pairs[triple[0]], pairs[triple[1]], pairs[triple[2]]};
    return SolveLinear(sample, {1.0, 1.0, 1.0}, form);
  }
  const Eigen::Vector3d sigma = Eigen::JacobiSVD<Eigen::Matrix3d>(model).singularValues();
  if (!(sigma[0] <= max_condition_number * sigma[2])) return std::nullopt;
  return Eigen::Matrix3d(model.partialPivLu().solve(scene).transpose());
}

// RANSAC: A from 3-pair samples (SampleMatrix), scored by the truncated squared residual (MSAC); least squares on
// the best one's inliers, then Tukey IRLS. With fit_offset the samples stay linear (they only pick the inliers); the
// refit and the polish add the offset.
ColorFit FitRansac(const std::vector<ColorPair>& pairs, const ColorFitOptions& options, ColorMatrixForm form) {
  TripleSampler sampler(pairs.size(), options.max_iterations, options.seed);
  const double cap = options.inlier_threshold * options.inlier_threshold;
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  for (int sample = 0; sample < sampler.count(); ++sample) {
    const std::optional<Eigen::Matrix3d> A = SampleMatrix(pairs, sampler.Next(), form, options.max_condition_number);
    if (!A) continue;
    double cost = 0.0;
    for (const ColorPair& pair : pairs) cost += std::min((*A * pair.model - pair.scene).squaredNorm(), cap);
    if (cost < best_cost) best_cost = cost, best = *A;
  }
  if (!std::isfinite(best_cost)) {
    ThrowInputError(
        kSource, "RANSAC samples",
        "a 3-pair sample with a condition number within max_condition_number " + Text(options.max_condition_number),
        "none in " + std::to_string(sampler.count()));
  }
  const std::vector<bool> inliers = Below(Residuals(pairs, {best, Eigen::Vector3d::Zero()}), options.inlier_threshold);
  ColorMap map = SolveWeighted(pairs, ToWeights(inliers), form, options.fit_offset);
  int steps = 0;
  if (options.polish) {
    map = TukeyIrls(pairs, map, options.inlier_threshold, options.max_iterations, form, options.fit_offset, &steps);
  }
  ColorFit fit;
  fit.A = map.A, fit.offset = map.b;
  fit.iterations = sampler.count();
  return fit;
}

// The fit of one form (kFull or kDiagonal) with the inliers, condition number and rms; throws as FitColorMatrix.
ColorFit FitForm(const std::vector<ColorPair>& pairs, const ColorFitOptions& options, ColorMatrixForm form,
                 double given_condition_number) {
  if (form == ColorMatrixForm::kFull) {
    RequireConditioned(given_condition_number, options.max_condition_number, "given");
  } else {
    RequireChannels(pairs);
  }
  const std::vector<double> ones(pairs.size(), 1.0);
  ColorFit fit;
  ColorMap map;
  switch (options.method) {
    case ColorFitMethod::kLeastSquares: map = SolveWeighted(pairs, ones, form, options.fit_offset); break;
    case ColorFitMethod::kRansac:
      fit = FitRansac(pairs, options, form);
      map = {fit.A, fit.offset};
      break;
    case ColorFitMethod::kTukeyIrls:
      map = TukeyIrls(pairs, SolveWeighted(pairs, ones, form, options.fit_offset), options.inlier_threshold,
                      options.max_iterations, form, options.fit_offset, &fit.iterations);
      break;
  }
  fit.A = map.A, fit.offset = map.b;
  fit.form = form;
  fit.inliers = options.method == ColorFitMethod::kLeastSquares
                    ? std::vector<bool>(pairs.size(), true)
                    : Below(Residuals(pairs, map), options.inlier_threshold);
  fit.num_inliers = static_cast<int>(std::count(fit.inliers.begin(), fit.inliers.end(), true));
  if (fit.num_inliers < 3) {
    ThrowInputError(kSource, std::string(ToString(options.method)) + " inliers",
                    "at least 3 pairs within inlier_threshold " + Text(options.inlier_threshold) + " of one matrix",
                    std::to_string(fit.num_inliers));
  }
  fit.condition_number = ConditionNumber(pairs, fit.inliers);
  if (form == ColorMatrixForm::kFull) RequireConditioned(fit.condition_number, options.max_condition_number, "inlier");
  return fit;
}

// keep_brightness: A scaled so that the inliers' fitted colours keep the model's total brightness.
void KeepBrightness(const std::vector<ColorPair>& pairs, ColorFit* fit) {
  double model_sum = 0.0, fitted_sum = 0.0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!fit->inliers[i]) continue;
    model_sum += pairs[i].model.sum();
    fitted_sum += (fit->A * pairs[i].model).sum();  // the offset (if any) is not part of A's gain
  }
  if (!(fitted_sum > 0.0)) return;  // a matrix that maps the colours to black: nothing to keep
  fit->brightness_scale = model_sum / fitted_sum;
  fit->A *= fit->brightness_scale;
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

const char* ToString(ColorMatrixForm form) {
  switch (form) {
    case ColorMatrixForm::kFull: return "full";
    case ColorMatrixForm::kDiagonal: return "diagonal";
    case ColorMatrixForm::kAuto: return "auto";
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
  require(diagonal_above_condition >= 1.0, "diagonal_above_condition", "at least 1 (sigma_max / sigma_min)");
}

ColorFit FitColorMatrix(const std::vector<ColorPair>& pairs, const ColorFitOptions& options) {
  options.Check();
  CheckPairs(pairs);
  const double given = ConditionNumber(pairs, std::vector<bool>(pairs.size(), true));
  ColorFit fit;
  if (options.form != ColorMatrixForm::kAuto) {
    fit = FitForm(pairs, options, options.form, given);
  } else if (given > options.diagonal_above_condition) {
    RequireConditioned(given, options.max_condition_number, "given");  // all grey, or exactly one hue: an error
    fit = FitForm(pairs, options, ColorMatrixForm::kDiagonal, given);
  } else {
    fit = FitForm(pairs, options, ColorMatrixForm::kFull, given);
    // The full fit's inliers may be of one hue although all pairs are not.
    if (fit.condition_number > options.diagonal_above_condition) {
      fit = FitForm(pairs, options, ColorMatrixForm::kDiagonal, given);
    }
  }
  if (options.keep_brightness) KeepBrightness(pairs, &fit);
  double squared_sum = 0.0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (fit.inliers[i]) squared_sum += (fit.A * pairs[i].model + fit.offset - pairs[i].scene).squaredNorm();
  }
  fit.rms = std::sqrt(squared_sum / fit.num_inliers);
  return fit;
}

Eigen::Matrix3d BrightnessPreserving(const Eigen::Matrix3d& A) {
  const double grey = A.sum();  // channel sum of A (1, 1, 1)
  return grey > 0.0 ? Eigen::Matrix3d(A * (3.0 / grey)) : A;
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
