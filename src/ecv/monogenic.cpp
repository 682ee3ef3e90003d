#include "ecv/monogenic.h"

#include <cmath>
#include <string>

#include <opencv2/core.hpp>

#include "core/error.h"

namespace ecv {
namespace {

// Frequency of DFT index i of n samples, cycles per pixel in [-0.5, 0.5).
double Frequency(int i, int n) {
  return (i < (n + 1) / 2 ? i : i - n) / static_cast<double>(n);
}

// Spectra (CV_32FC2) of the log-Gabor band-pass H and of H times the complex Riesz kernel (v - i u) / |w|:
// the inverse DFT of F * even_filter is the even part, of F * odd_filter is odd_x + i odd_y.
void MakeFilters(cv::Size size, const MonogenicOptions& options, cv::Mat* even_filter, cv::Mat* odd_filter) {
  even_filter->create(size, CV_32FC2);
  odd_filter->create(size, CV_32FC2);
  const double f0 = 1.0 / options.wavelength_px;
  const double log_sigma = std::log(options.sigma_on_f);
  for (int y = 0; y < size.height; ++y) {
    const double v = Frequency(y, size.height);
    auto* even_row = even_filter->ptr<cv::Vec2f>(y);
    auto* odd_row = odd_filter->ptr<cv::Vec2f>(y);
    for (int x = 0; x < size.width; ++x) {
      const double u = Frequency(x, size.width);
      const double radius = std::hypot(u, v);
      if (radius == 0.0) {
        even_row[x] = odd_row[x] = cv::Vec2f(0.0F, 0.0F);
        continue;
      }
      const double log_ratio = std::log(radius / f0);
      const double gain = std::exp(-log_ratio * log_ratio / (2.0 * log_sigma * log_sigma));
      even_row[x] = cv::Vec2f(static_cast<float>(gain), 0.0F);
      odd_row[x] = cv::Vec2f(static_cast<float>(gain * v / radius), static_cast<float>(-gain * u / radius));
    }
  }
}

// Filters are cached per padded size and options: a video stream reuses them for every frame.
struct FilterCache {
  cv::Size size;
  double wavelength_px = 0.0;
  double sigma_on_f = 0.0;
  cv::Mat even_filter, odd_filter;
};

const FilterCache& Filters(cv::Size size, const MonogenicOptions& options) {
  thread_local FilterCache cache;
  if (cache.size != size || cache.wavelength_px != options.wavelength_px || cache.sigma_on_f != options.sigma_on_f) {
    MakeFilters(size, options, &cache.even_filter, &cache.odd_filter);
    cache.size = size;
    cache.wavelength_px = options.wavelength_px;
    cache.sigma_on_f = options.sigma_on_f;
  }
  return cache;
}

}  // namespace

void MonogenicOptions::Check() const {
  if (!(wavelength_px > 2.0 && wavelength_px <= kMaxWavelengthPx)) {
    ThrowInputError(
        "monogenic options", "wavelength_px",
        "a wavelength above 2 and at most " + std::to_string(static_cast<int>(kMaxWavelengthPx)) + " pixels",
        std::to_string(wavelength_px));
  }
  if (!(sigma_on_f > 0.0 && sigma_on_f < 1.0)) {
    ThrowInputError("monogenic options", "sigma_on_f", "a bandwidth ratio in (0, 1)", std::to_string(sigma_on_f));
  }
}

MonogenicSignal ComputeMonogenic(const cv::Mat& grey, const MonogenicOptions& options) {
  options.Check();
  CV_Assert(!grey.empty() && grey.channels() == 1);
  cv::Mat image;
  grey.convertTo(image, CV_32F, grey.depth() == CV_8U ? 1.0 / 255.0 : 1.0);

  // Pad by reflection: a margin of a wavelength, then up to a size the DFT likes.
  const int margin = static_cast<int>(std::ceil(options.wavelength_px));
  const cv::Size padded(cv::getOptimalDFTSize(image.cols + 2 * margin), cv::getOptimalDFTSize(image.rows + 2 * margin));
  cv::Mat extended;
  const int left = (padded.width - image.cols) / 2, top = (padded.height - image.rows) / 2;
  cv::copyMakeBorder(image, extended, top, padded.height - image.rows - top, left, padded.width - image.cols - left,
                     cv::BORDER_REFLECT_101);

  cv::Mat spectrum;
  cv::dft(extended, spectrum, cv::DFT_COMPLEX_OUTPUT);
  const FilterCache& filters = Filters(padded, options);
  cv::Mat even_spectrum, odd_spectrum, even, odd;
  cv::mulSpectrums(spectrum, filters.even_filter, even_spectrum, 0);
  cv::mulSpectrums(spectrum, filters.odd_filter, odd_spectrum, 0);
  cv::dft(even_spectrum, even, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  cv::dft(odd_spectrum, odd, cv::DFT_INVERSE | cv::DFT_SCALE);

  // Per pixel, with OpenCV's vectorised magnitude and phase (angles to about 0.3 degrees).
  const cv::Rect inside(left, top, image.cols, image.rows);
  cv::Mat odd_parts[2];
  cv::split(odd(inside), odd_parts);
  const cv::Mat even_part = even(inside);
  MonogenicSignal signal;
  signal.odd_x = odd_parts[0].clone();
  signal.odd_y = odd_parts[1].clone();
  cv::Mat odd_norm, angle;
  cv::magnitude(signal.odd_x, signal.odd_y, odd_norm);
  cv::magnitude(even_part, odd_norm, signal.magnitude);
  cv::phase(signal.odd_x, signal.odd_y, angle);  // [0, 2 pi)
  // Fold the orientation to [0, pi); where it flips, the odd part changes sign and so does the phase.
  signal.orientation.create(image.size(), CV_32F);
  cv::Mat signed_odd(image.size(), CV_32F);
  const float pi = static_cast<float>(M_PI);
  for (int y = 0; y < image.rows; ++y) {
    const float* a = angle.ptr<float>(y);
    const float* n = odd_norm.ptr<float>(y);
    float* folded = signal.orientation.ptr<float>(y);
    float* odd_signed = signed_odd.ptr<float>(y);
    for (int x = 0; x < image.cols; ++x) {
      const bool flip = a[x] >= pi;
      folded[x] = flip ? a[x] - pi : a[x];
      odd_signed[x] = flip ? -n[x] : n[x];
    }
  }
  cv::min(signal.orientation, std::nextafter(pi, 0.0F), signal.orientation);
  cv::phase(even_part, signed_odd, signal.phase);  // [0, 2 pi) -> (-pi, pi]
  cv::Mat wrapped = signal.phase > pi;
  cv::subtract(signal.phase, 2.0F * pi, signal.phase, wrapped);
  return signal;
}

}  // namespace ecv
