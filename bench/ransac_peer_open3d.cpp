// Open3D's correspondence RANSAC through bench/ransac_open3d.py: input and output files, one process.

#include "ransac_peer_open3d.h"

#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "bench_util.h"
#include "core/pose.h"

namespace ecv::bench {
namespace {

PeerPose ParseRun(const std::string& line, const std::string& source) {
  std::istringstream fields(line);
  int seed = 0;
  double fitness = 0.0;
  PeerPose pose;
  fields >> seed >> pose.time_ms >> pose.cpu_ms >> fitness;
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) fields >> matrix(r, c);
  }
  if (!fields) throw std::runtime_error(source + ": unreadable line '" + line + "'");
  pose.returned = fitness > 0.0;  // Open3D always returns a pose; fitness 0 means no inlier at all
  pose.b_from_a = RigidFromMatrix(matrix, source, "pose");
  return pose;
}

}  // namespace

void WriteOpen3dInput(const std::vector<Eigen::Vector3f>& object_points,
                      const std::vector<Eigen::Vector3f>& scene_points,
                      const std::vector<Correspondence>& correspondences, const std::filesystem::path& directory) {
  std::filesystem::create_directories(directory);
  auto write_points = [](const std::vector<Eigen::Vector3f>& points, const std::filesystem::path& path) {
    std::ofstream file(path);
    file.precision(9);
    for (const Eigen::Vector3f& p : points) file << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    if (!file) throw std::runtime_error("could not write " + path.string());
  };
  write_points(object_points, directory / "a.txt");
  write_points(scene_points, directory / "b.txt");
  std::ofstream file(directory / "correspondences.txt");
  for (const Correspondence& c : correspondences) file << c.object << ' ' << c.scene << '\n';
  if (!file) throw std::runtime_error("could not write " + (directory / "correspondences.txt").string());
}

std::vector<PeerPose> RunOpen3dRansac(const std::filesystem::path& directory, const Open3dRansacOptions& options,
                                      std::string* problem) {
  const std::filesystem::path output = directory / "open3d_runs.txt";
  std::filesystem::remove(output);
  const std::string command =
      "OMP_NUM_THREADS=" + std::to_string(options.threads) + " " + ShellQuoted(options.python) + " " +
      ShellQuoted(options.script) + " " + ShellQuoted(directory.string()) + " " + ShellQuoted(output.string()) +
      " --runs " + std::to_string(options.runs) + " --iterations " + std::to_string(options.max_iterations) +
      " --confidence " + Fixed(options.confidence, 6) + " --distance " + Fixed(options.max_correspondence_distance, 6) +
      " --similarity " + Fixed(options.similarity_threshold, 6);
  const int code = RunShellCommand(command);
  if (code != 0) {
    *problem = code == 3 ? "Open3D is not installed for " + options.python +
                               " (install: apt-get install -y python3-open3d); Open3D skipped"
                         : "ransac_open3d.py failed (exit code " + std::to_string(code) + "); Open3D skipped";
    return {};
  }
  std::vector<PeerPose> poses;
  std::ifstream file(output);
  std::string line;
  while (std::getline(file, line)) poses.push_back(ParseRun(line, output.string()));
  if (static_cast<int>(poses.size()) != options.runs) {
    *problem = "ransac_open3d.py wrote " + std::to_string(poses.size()) + " runs, not " + std::to_string(options.runs);
    return {};
  }
  return poses;
}

}  // namespace ecv::bench
