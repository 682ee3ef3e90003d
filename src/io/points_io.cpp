#include "io/points_io.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "io/files.h"

namespace ecv {

std::vector<Eigen::Vector3d> ReadXyzFile(const std::string& path, double metres_per_unit) {
  RequireRegularFile(path, "points");
  std::ifstream stream(path);
  std::vector<Eigen::Vector3d> points;
  std::string line;
  for (int number = 1; std::getline(stream, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream fields(line);
    Eigen::Vector3d point;
    if (!(fields >> point.x() >> point.y() >> point.z()) || !point.allFinite()) {
      ThrowInputError(path, "line " + std::to_string(number), "three numbers x y z", "'" + line + "'");
    }
    points.push_back(point * metres_per_unit);
  }
  if (points.empty()) ThrowInputError(path, "points", "at least one line x y z", "none");
  return points;
}

}  // namespace ecv
