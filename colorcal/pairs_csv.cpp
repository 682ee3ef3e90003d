#include "colorcal/pairs_csv.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.h"
#include "io/frame_io.h"

namespace ecv {
namespace {

const std::vector<std::string> kPixelHeader = {"model_image", "x", "y", "scene_image", "x", "y"};
const std::vector<std::string> kTripletHeader = {"mr", "mg", "mb", "sr", "sg", "sb"};
const char* const kPixelFields[] = {"model_image", "model x", "model y", "scene_image", "scene x", "scene y"};

std::string Trim(const std::string& text) {
  const auto begin = std::find_if_not(text.begin(), text.end(), [](unsigned char c) { return std::isspace(c); });
  const auto end = std::find_if_not(text.rbegin(), text.rend(), [](unsigned char c) { return std::isspace(c); });
  return begin < end.base() ? std::string(begin, end.base()) : std::string();
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, ',')) fields.push_back(Trim(field));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// The lines of a CSV that carry content (not blank, not '#'), with their numbers; the first is the header.
struct CsvLines {
  std::vector<std::vector<std::string>> rows;
  std::vector<int> numbers;
  bool triplets = false;  ///< header mr,mg,mb,sr,sg,sb (else pixel pairs)
};

CsvLines ReadCsvLines(const std::string& path) {
  std::ifstream file(path);
  if (!file) ThrowInputError(path, "file", "a readable colour-pair CSV");
  CsvLines lines;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    lines.rows.push_back(SplitFields(trimmed));
    lines.numbers.push_back(number);
  }
  const std::string expected_header =
      "the header 'model_image,x,y,scene_image,x,y' (pixel pairs) or 'mr,mg,mb,sr,sg,sb' "
      "(RGB triplets in [0, 1])";
  if (lines.rows.empty()) ThrowInputError(path, "header", expected_header, "an empty file");
  std::vector<std::string> header = lines.rows.front();
  for (std::string& field : header) {
    std::transform(field.begin(), field.end(), field.begin(), [](unsigned char c) { return std::tolower(c); });
  }
  if (header != kPixelHeader && header != kTripletHeader) {
    std::string got;
    for (const std::string& field : lines.rows.front()) got += (got.empty() ? "'" : ",") + field;
    ThrowInputError(path + ":" + std::to_string(lines.numbers.front()), "header", expected_header, got + "'");
  }
  lines.triplets = header == kTripletHeader;
  for (size_t i = 1; i < lines.rows.size(); ++i) {
    if (lines.rows[i].size() != 6) {
      ThrowInputError(path + ":" + std::to_string(lines.numbers[i]), "fields", "6 comma-separated fields",
                      std::to_string(lines.rows[i].size()));
    }
  }
  return lines;
}

double ParseNumber(const std::string& text, const std::string& source, const std::string& field) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value))
    ThrowInputError(source, field, "a number", "'" + text + "'");
  return value;
}

double ParseUnitValue(const std::string& text, const std::string& source, const std::string& field) {
  const double value = ParseNumber(text, source, field);
  if (value < 0.0 || value > 1.0) {
    ThrowInputError(
        source, field,
        value > 1.0 && value <= 255.0 ? "a value in [0, 1] (0-255 values: divide by 255)" : "a value in [0, 1]", text);
  }
  return value;
}

int ParsePixel(const std::string& text, const std::string& source, const std::string& field) {
  const double value = ParseNumber(text, source, field);
  if (value != std::floor(value) || std::abs(value) > 1e9) {
    ThrowInputError(source, field, "an integer pixel coordinate", text);
  }
  return static_cast<int>(value);
}

std::vector<PixelPair> PixelPairsFromLines(const CsvLines& lines, const std::string& path) {
  if (lines.triplets) {
    ThrowInputError(path + ":" + std::to_string(lines.numbers.front()), "header",
                    "model_image,x,y,scene_image,x,y (pixel pairs)", "mr,mg,mb,sr,sg,sb (RGB triplets)");
  }
  std::vector<PixelPair> pairs;
  for (size_t i = 1; i < lines.rows.size(); ++i) {
    const std::vector<std::string>& row = lines.rows[i];
    const std::string source = path + ":" + std::to_string(lines.numbers[i]);
    for (int k : {0, 3}) {
      if (row[k].empty()) ThrowInputError(source, kPixelFields[k], "an image path", "nothing");
    }
    pairs.push_back({row[0],
                     {ParsePixel(row[1], source, kPixelFields[1]), ParsePixel(row[2], source, kPixelFields[2])},
                     row[3],
                     {ParsePixel(row[4], source, kPixelFields[4]), ParsePixel(row[5], source, kPixelFields[5])},
                     lines.numbers[i]});
  }
  return pairs;
}

// Mean colour in [0, 1] over the window around `pixel`, clipped to the image; the pixel itself must lie inside.
Eigen::Vector3d MeanColor(const cv::Mat& rgb, const cv::Point& pixel, int radius, const std::string& source,
                          const std::string& field, const std::string& image_path) {
  if (pixel.x < 0 || pixel.y < 0 || pixel.x >= rgb.cols || pixel.y >= rgb.rows) {
    ThrowInputError(source, field,
                    "a pixel inside the " + std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows) + " image " +
                        image_path + " (x in 0.." + std::to_string(rgb.cols - 1) + ", y in 0.." +
                        std::to_string(rgb.rows - 1) + ")",
                    "(" + std::to_string(pixel.x) + ", " + std::to_string(pixel.y) + ")");
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int y = std::max(0, pixel.y - radius); y <= std::min(rgb.rows - 1, pixel.y + radius); ++y) {
    for (int x = std::max(0, pixel.x - radius); x <= std::min(rgb.cols - 1, pixel.x + radius); ++x, ++count) {
      const cv::Vec3b& color = rgb.at<cv::Vec3b>(y, x);
      sum += Eigen::Vector3d(color[0], color[1], color[2]);
    }
  }
  return sum / (255.0 * count);
}

std::string Shortest(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::ofstream OpenForWriting(const std::string& path) {
  std::ofstream file(path);
  if (!file) ThrowInputError(path, "file", "a writable path");
  return file;
}

}  // namespace

void PairCsvOptions::Check() const {
  if (window_radius_px < 0) ThrowInputError("pair CSV options", "window_radius_px", ">= 0 pixels");
}

std::vector<PixelPair> ReadPixelPairsCsv(const std::string& path) {
  return PixelPairsFromLines(ReadCsvLines(path), path);
}

std::vector<ColorPair> ColorPairsFromPixels(const std::vector<PixelPair>& pixel_pairs, const std::string& base_dir,
                                            const PairCsvOptions& options, const std::string& source) {
  options.Check();
  std::map<std::string, cv::Mat> images;  // each image read once
  auto image = [&](const std::string& relative, const std::string& where, const char* field) -> const cv::Mat& {
    const std::string path = (std::filesystem::path(base_dir) / relative).string();
    auto found = images.find(path);
    if (found != images.end()) return found->second;
    try {
      return images.emplace(path, ReadColorImage(path)).first->second;
    } catch (const InputError& error) {
      throw InputError(where + ": " + field + ": " + error.what());
    }
  };
  std::vector<ColorPair> pairs;
  for (const PixelPair& pixel_pair : pixel_pairs) {
    const std::string where = pixel_pair.line > 0 ? source + ":" + std::to_string(pixel_pair.line) : source;
    const cv::Mat& model = image(pixel_pair.model_image, where, "model_image");
    const cv::Mat& scene = image(pixel_pair.scene_image, where, "scene_image");
    pairs.push_back(
        {MeanColor(model, pixel_pair.model_pixel, options.window_radius_px, where, "model x,y", pixel_pair.model_image),
         MeanColor(scene, pixel_pair.scene_pixel, options.window_radius_px, where, "scene x,y",
                   pixel_pair.scene_image)});
  }
  return pairs;
}

std::vector<ColorPair> ReadColorPairsCsv(const std::string& path, const PairCsvOptions& options) {
  options.Check();
  const CsvLines lines = ReadCsvLines(path);
  if (!lines.triplets) {
    return ColorPairsFromPixels(PixelPairsFromLines(lines, path), std::filesystem::path(path).parent_path().string(),
                                options, path);
  }
  std::vector<ColorPair> pairs;
  for (size_t i = 1; i < lines.rows.size(); ++i) {
    const std::string source = path + ":" + std::to_string(lines.numbers[i]);
    ColorPair pair;
    for (int k = 0; k < 3; ++k) {
      pair.model[k] = ParseUnitValue(lines.rows[i][k], source, kTripletHeader[k]);
      pair.scene[k] = ParseUnitValue(lines.rows[i][k + 3], source, kTripletHeader[k + 3]);
    }
    pairs.push_back(pair);
  }
  return pairs;
}

void WriteColorPairsCsv(const std::string& path, const std::vector<ColorPair>& pairs) {
  std::ofstream file = OpenForWriting(path);
  file << "mr,mg,mb,sr,sg,sb\n";
  for (const ColorPair& pair : pairs) {
    file << Shortest(pair.model[0]) << ',' << Shortest(pair.model[1]) << ',' << Shortest(pair.model[2]) << ','
         << Shortest(pair.scene[0]) << ',' << Shortest(pair.scene[1]) << ',' << Shortest(pair.scene[2]) << '\n';
  }
  if (!file.flush()) ThrowInputError(path, "file", "a writable path", "a write error");
}

void WritePixelPairsCsv(const std::string& path, const std::vector<PixelPair>& pairs) {
  std::ofstream file = OpenForWriting(path);
  file << "model_image,x,y,scene_image,x,y\n";
  for (const PixelPair& pair : pairs) {
    for (const std::string* image : {&pair.model_image, &pair.scene_image}) {
      if (image->find_first_of(",\n") != std::string::npos) {
        ThrowInputError(path, "image path", "a path without commas or line breaks", *image);
      }
    }
    file << pair.model_image << ',' << pair.model_pixel.x << ',' << pair.model_pixel.y << ',' << pair.scene_image << ','
         << pair.scene_pixel.x << ',' << pair.scene_pixel.y << '\n';
  }
  if (!file.flush()) ThrowInputError(path, "file", "a writable path", "a write error");
}

}  // namespace ecv
