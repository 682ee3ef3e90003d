#include "colorcal/color_pairs.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

#include "core/error.h"

namespace ecv {
namespace {

std::string SizeText(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

void RequireImage(const cv::Mat& image, int type, const cv::Size& size, const char* field, const char* expected) {
  if (image.type() != type)
    ThrowInputError("colour pairs from pose", field, expected, "type " + std::to_string(image.type()));
  if (image.size() != size) {
    ThrowInputError("colour pairs from pose", field,
                    "the size of the rendered image, " + std::to_string(size.width) + "x" + std::to_string(size.height),
                    SizeText(image));
  }
}

// Mean colour (in [0, 1]) and largest channel value over the window around (u, v); false if it leaves the mask.
bool WindowColor(const cv::Mat& rgb, const cv::Mat& mask, int u, int v, int radius, Eigen::Vector3d* mean,
                 double* largest) {
  if (u < radius || v < radius || u + radius >= rgb.cols || v + radius >= rgb.rows) return false;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int high = 0;
  for (int y = v - radius; y <= v + radius; ++y) {
    for (int x = u - radius; x <= u + radius; ++x) {
      if (mask.at<uint8_t>(y, x) == 0) return false;
      const cv::Vec3b& pixel = rgb.at<cv::Vec3b>(y, x);
      sum += Eigen::Vector3d(pixel[0], pixel[1], pixel[2]);
      high = std::max({high, int{pixel[0]}, int{pixel[1]}, int{pixel[2]}});
    }
  }
  const int side = 2 * radius + 1;
  *mean = sum / (255.0 * side * side);
  *largest = high / 255.0;
  return true;
}

}  // namespace

void PosePairOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("pose pair options", field, expected);
  };
  require(max_pairs >= 0, "max_pairs", ">= 0 (0: every usable pixel)");
  require(window_radius_px >= 0, "window_radius_px", ">= 0 pixels");
  require(min_value >= 0.0 && min_value <= 1.0, "min_value", "in [0, 1]");
  require(max_value > min_value && max_value <= 1.0, "max_value", "in (min_value, 1]");
}

PosePairs ColorPairsFromPose(const cv::Mat& model_rgb, const cv::Mat& scene_rgb, const cv::Mat& mask,
                             const PosePairOptions& options) {
  options.Check();
  RequireImage(model_rgb, CV_8UC3, model_rgb.size(), "model image", "an 8-bit RGB image (CV_8UC3)");
  RequireImage(scene_rgb, CV_8UC3, model_rgb.size(), "scene image", "an 8-bit RGB image (CV_8UC3)");
  RequireImage(mask, CV_8UC1, model_rgb.size(), "mask", "an 8-bit mask (CV_8UC1)");
  PosePairs result;
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (mask.at<uint8_t>(v, u) == 0) continue;
      ++result.mask_pixels;
      ColorPair pair;
      double model_high = 0.0, scene_high = 0.0;
      if (!WindowColor(model_rgb, mask, u, v, options.window_radius_px, &pair.model, &model_high) ||
          !WindowColor(scene_rgb, mask, u, v, options.window_radius_px, &pair.scene, &scene_high)) {
        ++result.window_outside;
      } else if (std::max(model_high, scene_high) > options.max_value) {
        ++result.saturated;
      } else if (pair.model.maxCoeff() < options.min_value || pair.scene.maxCoeff() < options.min_value) {
        ++result.dark;
      } else {
        result.pairs.push_back(pair);
        result.pixels.emplace_back(u, v);
      }
    }
  }
  const size_t keep = static_cast<size_t>(options.max_pairs);
  if (keep == 0 || result.pairs.size() <= keep) return result;
  // Partial Fisher-Yates with the seeded generator: the first `keep` entries become a uniform random subset.
  std::mt19937_64 random(options.seed);
  for (size_t i = 0; i < keep; ++i) {
    const size_t j = std::uniform_int_distribution<size_t>(i, result.pairs.size() - 1)(random);
    std::swap(result.pairs[i], result.pairs[j]);
    std::swap(result.pixels[i], result.pixels[j]);
  }
  result.pairs.resize(keep);
  result.pixels.resize(keep);
  return result;
}

cv::Mat DepthAgreementMask(const cv::Mat& model_depth, const cv::Mat& scene_depth, double max_difference_m) {
  RequireImage(model_depth, CV_32FC1, model_depth.size(), "model depth", "a float depth image (CV_32FC1, metres)");
  RequireImage(scene_depth, CV_32FC1, model_depth.size(), "scene depth", "a float depth image (CV_32FC1, metres)");
  if (!(max_difference_m > 0.0)) {
    ThrowInputError("depth agreement", "max_difference_m", "> 0 metres", std::to_string(max_difference_m));
  }
  cv::Mat mask(model_depth.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      const float model = model_depth.at<float>(v, u), scene = scene_depth.at<float>(v, u);
      if (model > 0.0F && scene > 0.0F && std::abs(model - scene) <= max_difference_m) mask.at<uint8_t>(v, u) = 255;
    }
  }
  return mask;
}

}  // namespace ecv
