// Organized point clouds through PCL's io (kept in this one file: PCL headers are slow to compile).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>

#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/points_io.h"

namespace ecv {
namespace {

// Runs `read`, turning what PCL throws on a malformed file (e.g. std::out_of_range from its header parser) into an
// InputError naming it.
template <typename Read>
auto WithPclErrors(const std::string& path, Read read) {
  try {
    return read();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& error) {
    ThrowInputError(path, "PCD", "a file PCL reads", error.what());
  }
}

// The file's points (its `header` read already) as PCL stores them, checked before PCL converts them: as many as WIDTH
// x HEIGHT, each of POINT_STEP bytes, every field inside a point. PCL trusts the header and would index past its data
// otherwise.
template <typename Point>
pcl::PointCloud<Point> ReadCheckedCloud(const std::string& path, const pcl::PCLPointCloud2& header,
                                        pcl::PCDReader& reader) {
  // Every point takes at least a byte of the file: a header that claims more is refused before PCL allocates them.
  const uint64_t claimed = static_cast<uint64_t>(header.width) * header.height;
  const uint64_t bytes = std::filesystem::file_size(path);
  // Binary points take POINT_STEP bytes each; ASCII ones at least two per field; compressed ones LZF's at most
  // ~100:1.
  const uint64_t step = std::max<uint64_t>(header.point_step, 1);
  if (claimed > bytes || step > (1U << 20) || claimed * step > 100 * bytes) {
    ThrowInputError(path, "WIDTH x HEIGHT", "as many points as the file can hold",
                    std::to_string(claimed) + " points of " + std::to_string(step) + " bytes in " +
                        std::to_string(bytes) + " bytes");
  }
  pcl::PCLPointCloud2 blob;
  if (reader.read(path, blob) < 0) ThrowInputError(path, "DATA", "readable point data");
  const uint64_t count = static_cast<uint64_t>(blob.width) * blob.height;
  if (count == 0) ThrowInputError(path, "POINTS", "at least one point", "none");
  if (blob.point_step == 0 || blob.data.size() != count * blob.point_step) {
    ThrowInputError(path, "DATA", "WIDTH x HEIGHT points of POINT_STEP bytes each",
                    std::to_string(blob.data.size()) + " bytes for " + std::to_string(count) + " points");
  }
  for (const pcl::PCLPointField& field : blob.fields) {
    const uint64_t size = static_cast<uint64_t>(pcl::getFieldSize(field.datatype)) * std::max(field.count, 1U);
    if (size == 0 || field.offset + size > blob.point_step) {
      ThrowInputError(path, "FIELDS", "fields that fit in a point", "field " + field.name + " does not");
    }
  }
  pcl::PointCloud<Point> cloud;
  pcl::fromPCLPointCloud2(blob, cloud);
  if (cloud.size() != count)
    ThrowInputError(path, "DATA", std::to_string(count) + " points", std::to_string(cloud.size()));
  return cloud;
}

void ReadOrganizedPcdUnguarded(const std::string& path, cv::Mat* points, cv::Mat* color) {
  if (!std::filesystem::exists(path)) ThrowInputError(path, "point cloud", "an existing .pcd file", "no such file");
  pcl::PCLPointCloud2 header;
  pcl::PCDReader reader;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_offset = 0;
  if (reader.readHeader(path, header, origin, orientation, version, data_type, data_offset) < 0) {
    ThrowInputError(path, "PCD header", "a valid PCD file");
  }
  bool has_color = false;
  for (const pcl::PCLPointField& field : header.fields) has_color |= field.name == "rgb" || field.name == "rgba";
  if (!has_color) ThrowInputError(path, "FIELDS", "x y z with rgb or rgba");
  if (header.height <= 1) {
    ThrowInputError(path, "HEIGHT", "an organized cloud (HEIGHT > 1, one point per pixel)",
                    std::to_string(header.height));
  }

  const pcl::PointCloud<pcl::PointXYZRGBA> cloud = ReadCheckedCloud<pcl::PointXYZRGBA>(path, header, reader);
  const int width = static_cast<int>(cloud.width), height = static_cast<int>(cloud.height);
  points->create(height, width, CV_32FC3);
  color->create(height, width, CV_8UC3);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const pcl::PointXYZRGBA& p = cloud.at(u, v);
      points->at<cv::Vec3f>(v, u) = {p.x, p.y, p.z};
      color->at<cv::Vec3b>(v, u) = {p.r, p.g, p.b};
    }
  }
}

std::vector<Eigen::Vector3f> ReadPcdPointsUnguarded(const std::string& path) {
  if (!std::filesystem::exists(path)) ThrowInputError(path, "point cloud", "an existing .pcd file", "no such file");
  pcl::PCLPointCloud2 header;
  pcl::PCDReader reader;
  if (reader.readHeader(path, header) < 0) ThrowInputError(path, "PCD header", "a valid PCD file");
  int xyz = 0;
  for (const pcl::PCLPointField& field : header.fields)
    xyz += field.name == "x" || field.name == "y" || field.name == "z";
  if (xyz != 3) ThrowInputError(path, "FIELDS", "x, y and z");
  const pcl::PointCloud<pcl::PointXYZ> cloud = ReadCheckedCloud<pcl::PointXYZ>(path, header, reader);
  std::vector<Eigen::Vector3f> points;
  points.reserve(cloud.size());
  for (const pcl::PointXYZ& p : cloud) {
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) points.emplace_back(p.x, p.y, p.z);
  }
  return points;
}

}  // namespace

void ReadOrganizedPcd(const std::string& path, cv::Mat* points, cv::Mat* color) {
  WithPclErrors(path, [&] {
    ReadOrganizedPcdUnguarded(path, points, color);
    return 0;
  });
}

std::vector<Eigen::Vector3f> ReadPcdPoints(const std::string& path) {
  return WithPclErrors(path, [&] { return ReadPcdPointsUnguarded(path); });
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
