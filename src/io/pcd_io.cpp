// Organized point clouds and point lists from .pcd files (read by io/pcd_file, which checks them first).

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>

#include "core/error.h"
#include "io/files.h"
#include "io/frame_io.h"
#include "io/pcd_file.h"
#include "io/points_io.h"

namespace ecv {
namespace {

// The cloud's x, y and z fields, each a single number; throws naming the file when one is missing.
std::array<const PcdField*, 3> XyzFields(const std::string& path, const PcdLayout& layout) {
  std::array<const PcdField*, 3> xyz = {layout.Find("x"), layout.Find("y"), layout.Find("z")};
  for (const PcdField* field : xyz) {
    if (field == nullptr || field->count != 1) ThrowInputError(path, "FIELDS", "x, y and z, one number each");
  }
  return xyz;
}

PcdCloud ReadExisting(const std::string& path) {
  if (!PathExists(path)) ThrowInputError(path, "point cloud", "an existing .pcd file", "no such file");
  return ReadPcdFile(path);
}

}  // namespace

void ReadOrganizedPcd(const std::string& path, cv::Mat* points, cv::Mat* color) {
  const PcdCloud cloud = ReadExisting(path);
  const PcdLayout& layout = cloud.layout;
  const std::array<const PcdField*, 3> xyz = XyzFields(path, layout);
  const PcdField* rgb = layout.Find("rgba");
  if (rgb == nullptr) rgb = layout.Find("rgb");
  if (rgb == nullptr || rgb->size != 4 || rgb->count != 1) {
    ThrowInputError(path, "FIELDS", "x y z with a 4-byte rgb or rgba (a packed colour)");
  }
  if (layout.height <= 1 || layout.width > (1 << 16) || layout.height > (1 << 16)) {
    ThrowInputError(path, "HEIGHT", "an organized cloud (HEIGHT > 1, one point per pixel, at most 65536 x 65536)",
                    std::to_string(layout.width) + " x " + std::to_string(layout.height));
  }
  const int width = static_cast<int>(layout.width), height = static_cast<int>(layout.height);
  points->create(height, width, CV_32FC3);
  color->create(height, width, CV_8UC3);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const uint64_t i = static_cast<uint64_t>(v) * layout.width + u;
      points->at<cv::Vec3f>(v, u) = {static_cast<float>(cloud.Value(i, *xyz[0])),
                                     static_cast<float>(cloud.Value(i, *xyz[1])),
                                     static_cast<float>(cloud.Value(i, *xyz[2]))};
      const uint32_t packed = cloud.Bits32(i, *rgb);  // 0xAARRGGBB
      color->at<cv::Vec3b>(v, u) = {static_cast<uchar>(packed >> 16), static_cast<uchar>(packed >> 8),
                                    static_cast<uchar>(packed)};
    }
  }
}

std::vector<Eigen::Vector3f> ReadPcdPoints(const std::string& path) {
  const PcdCloud cloud = ReadExisting(path);
  const std::array<const PcdField*, 3> xyz = XyzFields(path, cloud.layout);
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.layout.Points());
  for (uint64_t i = 0; i < cloud.layout.Points(); ++i) {
    const Eigen::Vector3d p(cloud.Value(i, *xyz[0]), cloud.Value(i, *xyz[1]), cloud.Value(i, *xyz[2]));
    if (p.allFinite()) points.push_back(p.cast<float>());
  }
  return points;
}

LoadedFrame LoadPcdFrame(const std::string& path) {
  LoadedFrame loaded;
  RgbdFrame& frame = loaded.rgbd;
  frame.name = path;
  cv::Mat points;
  ReadOrganizedPcd(path, &points, &frame.color);
  frame.depth.create(points.size(), CV_32FC1);
  for (int v = 0; v < points.rows; ++v) {
    for (int u = 0; u < points.cols; ++u) {
      const cv::Vec3f& p = points.at<cv::Vec3f>(v, u);
      const bool valid = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && p[2] > 0.0F;
      frame.depth.at<float>(v, u) = valid ? p[2] : 0.0F;
    }
  }
  frame.camera = FitPinholeCamera(points, path).camera;
  frame.Check();
  return loaded;
}

}  // namespace ecv
