#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "core/camera.h"

namespace ecv {

/// A simple model of a structured-light depth sensor (Kinect v1, Asus Xtion) applied to a perfect
/// depth image: axial Gaussian noise growing with distance (Nguyen, Izadi and Lovell, 3DIMPVT 2012:
/// sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 m), disparity quantisation, and missing pixels at occlusion
/// edges, on steep surfaces and at random.
struct SensorNoiseOptions {
  uint32_t seed = 1;                            ///< random seed: the same seed gives the same image
  double axial_sigma_base_m = 0.0012;           ///< sigma(z) = base + quadratic (z - offset)^2, metres
  double axial_sigma_quadratic_per_m = 0.0019;  ///< 1/metres
  double axial_sigma_offset_m = 0.4;            ///< metres
  double baseline_m = 0.075;                    ///< projector-camera baseline, metres; 0 = no quantisation
  double disparity_step_px = 0.125;             ///< disparity resolution, pixels (Kinect: 1/8)
  double max_incidence_rad = 1.31;              ///< surfaces seen more obliquely than this (75 deg) go missing
  double edge_jump_m = 0.02;                    ///< a depth step above this between neighbours is an edge, metres
  int edge_width_px = 2;                        ///< pixels within this distance of an edge may go missing
  double edge_dropout = 0.5;                    ///< probability that such an edge pixel goes missing
  double random_dropout = 0.005;                ///< probability that any other pixel goes missing

  /// Throws InputError for negative or non-finite values, probabilities outside [0, 1] or a
  /// max_incidence_rad outside (0, pi/2].
  void Check() const;
};

/// Output of SimulateStructuredLight.
struct SensorNoiseResult {
  cv::Mat depth;           ///< CV_32FC1 metres, 0 = missing
  int dropped_pixels = 0;  ///< valid input pixels made missing
};

/// Applies the model to `depth` (CV_32FC1 camera-frame z in metres, 0 = no surface) seen by `camera`.
/// Throws InputError when the image is not CV_32FC1 of the camera's size.
SensorNoiseResult SimulateStructuredLight(const cv::Mat& depth, const PinholeCamera& camera,
                                          const SensorNoiseOptions& options = {});

}  // namespace ecv
