#pragma once

#include <opencv2/core.hpp>

namespace ecv {

/// Band-pass of the monogenic signal (Felsberg & Sommer 2001): a radial log-Gabor filter.
struct MonogenicOptions {
  /// The longest centre wavelength, pixels: the image is padded by a wavelength on each side (a longer one only
  /// costs memory; it finds nothing in images of real sizes).
  static constexpr double kMaxWavelengthPx = 1024.0;

  double wavelength_px = 12.0;  ///< centre wavelength of the log-Gabor band-pass, pixels (> 2, <= kMaxWavelengthPx)
  double sigma_on_f = 0.55;     ///< bandwidth: sigma / f0 of the log-Gabor, in (0, 1); 0.55 is about 2 octaves

  /// Throws InputError on values outside the ranges above.
  void Check() const;
};

/// The monogenic signal of a grey image, per pixel (all CV_32FC1, the input's size).
struct MonogenicSignal {
  cv::Mat magnitude;    ///< local amplitude sqrt(even^2 + odd_x^2 + odd_y^2), grey in [0, 1] units
  cv::Mat orientation;  ///< local orientation in [0, pi): direction of the odd (Riesz) part, normal to an edge
  cv::Mat phase;        ///< local phase in (-pi, pi], signed consistently with `orientation`
  cv::Mat odd_x;        ///< Riesz (odd) part along x
  cv::Mat odd_y;        ///< Riesz (odd) part along y
};

/// Monogenic signal of `grey` (CV_8UC1 scaled to [0, 1], or CV_32FC1) computed in the Fourier domain:
/// a log-Gabor band-pass and the Riesz transform. The image is padded by reflection to an FFT-friendly
/// size so that no wrap-around reaches the borders.
MonogenicSignal ComputeMonogenic(const cv::Mat& grey, const MonogenicOptions& options = {});

}  // namespace ecv
