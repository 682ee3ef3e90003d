#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "colorcal/color_matrix.h"

namespace ecv {

// Colour-pair CSV files. The first non-comment line is a header that tells the two forms apart:
//
//   model_image,x,y,scene_image,x,y      pixel pairs: image paths (relative to the CSV, or absolute) and integer
//                                        pixel coordinates (x = column, y = row, from 0); colour = mean over a window
//   mr,mg,mb,sr,sg,sb                    RGB triplets in [0, 1] (the project's colour convention; 0-255 values are
//                                        rejected with a hint to divide by 255)
//
// Fields are separated by commas (no quoting, so paths must not contain commas) and trimmed; blank lines and lines
// starting with '#' are skipped. Errors name the file, the line and the field.

/// How pixel pairs become colours.
struct PairCsvOptions {
  int window_radius_px = 2;  ///< pixel pairs: colour = mean over the (2r+1)^2 window, clipped to the image

  /// Throws InputError naming the field on values outside their ranges.
  void Check() const;
};

/// One hand-labelled pixel pair.
struct PixelPair {
  std::string model_image;  ///< path of a model view image, as written in the CSV
  cv::Point model_pixel;    ///< (x, y), pixels
  std::string scene_image;  ///< path of a scene image, as written in the CSV
  cv::Point scene_pixel;    ///< (x, y), pixels
  int line = 0;             ///< line of the CSV it was read from, for messages (0: not from a file)
};

/// Reads either form; pixel pairs are turned into colours by reading the images (each once). Throws InputError naming
/// the file, line and field for a malformed line, and the pixel and image size for a pixel outside its image.
std::vector<ColorPair> ReadColorPairsCsv(const std::string& path, const PairCsvOptions& options = {});

/// Reads a pixel-pair CSV without reading the images (paths as written).
std::vector<PixelPair> ReadPixelPairsCsv(const std::string& path);

/// Colours of pixel pairs whose image paths are relative to `base_dir`; `source` names the pairs in errors.
std::vector<ColorPair> ColorPairsFromPixels(const std::vector<PixelPair>& pixel_pairs, const std::string& base_dir,
                                            const PairCsvOptions& options = {},
                                            const std::string& source = "pixel pairs");

/// Writes RGB triplets (header mr,mg,mb,sr,sg,sb; values with enough digits to read back exactly).
void WriteColorPairsCsv(const std::string& path, const std::vector<ColorPair>& pairs);

/// Writes pixel pairs (header model_image,x,y,scene_image,x,y; paths as given).
void WritePixelPairsCsv(const std::string& path, const std::vector<PixelPair>& pairs);

}  // namespace ecv
