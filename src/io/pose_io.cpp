#include "io/pose_io.h"

#include <filesystem>

#include "core/error.h"
#include "core/pose.h"
#include "io/atomic_file.h"
#include "io/files.h"

namespace ecv {

nlohmann::json PoseToJson(const Eigen::Isometry3d& pose) {
  nlohmann::json rows = nlohmann::json::array();
  const Eigen::Matrix4d& matrix = pose.matrix();
  for (int r = 0; r < 4; ++r) rows.push_back({matrix(r, 0), matrix(r, 1), matrix(r, 2), matrix(r, 3)});
  return rows;
}

Eigen::Isometry3d PoseFromJson(const nlohmann::json& value, const std::string& source, const std::string& field) {
  constexpr const char* kExpected = "a 4x4 nested row-major array of numbers (metres)";
  if (!value.is_array() || value.size() != 4) ThrowInputError(source, field, kExpected);
  Eigen::Matrix4d matrix;
  for (size_t r = 0; r < 4; ++r) {
    if (!value[r].is_array() || value[r].size() != 4) ThrowInputError(source, field, kExpected);
    for (size_t c = 0; c < 4; ++c) {
      if (!value[r][c].is_number()) ThrowInputError(source, field, kExpected);
      matrix(static_cast<int>(r), static_cast<int>(c)) = value[r][c].get<double>();
    }
  }
  return RigidFromMatrix(matrix, source, field);
}

Eigen::Isometry3d ReadPoseFile(const std::string& path, const std::string& key) {
  const nlohmann::json json = ReadJsonFile(path);
  if (!json.is_object() || !json.contains(key)) ThrowInputError(path, key, "a key \"" + key + "\" holding a 4x4 pose");
  return PoseFromJson(json[key], path, key);
}

void WritePoseFile(const std::string& path, const std::map<std::string, Eigen::Isometry3d>& poses) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [key, pose] : poses) json[key] = PoseToJson(pose);
  WriteJsonFile(path, json);
}

nlohmann::json ReadJsonFile(const std::string& path) {
  // A regular file of at most 256 MB: BOP's largest scene_gt.json files hold a few.
  constexpr size_t kMaxBytes = size_t{256} << 20;
  const std::string text = ReadFileBytes(path, "JSON file", kMaxBytes);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& error) {
    // error.what() gives "[json.exception.parse_error.101] parse error at line L, column C: ..." (or a number out of
    // range: out_of_range.406).
    ThrowInputError(path, "JSON", "well-formed JSON", error.what());
  }
}

void WriteJsonFile(const std::string& path, const nlohmann::json& value) {
  WriteFileAtomically(path, value.dump(2) + "\n");
}

}  // namespace ecv
