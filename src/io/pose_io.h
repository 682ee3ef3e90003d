#pragma once

#include <map>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace ecv {

// Pose files are JSON objects whose values are 4x4 nested row-major matrices in metres, e.g.
// {"camera_from_object": [[r11, r12, r13, tx], [...], [...], [0, 0, 0, 1]]}.

/// 4x4 nested row-major JSON array of a rigid transform.
nlohmann::json PoseToJson(const Eigen::Isometry3d& pose);

/// Rigid transform from a 4x4 nested array; throws InputError naming `source` and `field` unless it is
/// one (4 rows of 4 numbers, a rotation, last row 0 0 0 1).
Eigen::Isometry3d PoseFromJson(const nlohmann::json& value, const std::string& source, const std::string& field);

/// Reads key `key` of the pose file `path`.
Eigen::Isometry3d ReadPoseFile(const std::string& path, const std::string& key = "camera_from_object");

/// Writes the named poses to `path` (written to a temporary file first, then renamed).
void WritePoseFile(const std::string& path, const std::map<std::string, Eigen::Isometry3d>& poses);

/// Parses a JSON file (a regular file of at most 256 MB), throwing InputError naming the file when it is none, and
/// with the line and column on malformed text.
nlohmann::json ReadJsonFile(const std::string& path);

/// Writes `value` to `path` atomically (temporary file, then rename); throws InputError if it cannot.
void WriteJsonFile(const std::string& path, const nlohmann::json& value);

}  // namespace ecv
