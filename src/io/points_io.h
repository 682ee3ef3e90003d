#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace ecv {

/// Points of a whitespace-separated text file with "x y z" per line (e.g. YCB-Video's points.xyz),
/// scaled by `metres_per_unit`. Throws InputError naming the file and line on a malformed line.
std::vector<Eigen::Vector3d> ReadXyzFile(const std::string& path, double metres_per_unit = 1.0);

/// The finite points (x y z, metres) of any .pcd file, organized or not; NaN points are skipped. Throws
/// InputError naming the file when it is missing, unreadable or has no x, y, z fields.
std::vector<Eigen::Vector3f> ReadPcdPoints(const std::string& path);

}  // namespace ecv
