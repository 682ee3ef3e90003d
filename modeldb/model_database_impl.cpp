// Opening a library file (errors that say what is wrong with it) and the small readers shared by the
// database's operations.

#include "modeldb/model_database_impl.h"

#include <cmath>
#include <ctime>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "modeldb/point_pair_record.h"
#include "modeldb/schema.h"

namespace ecv::detail {
namespace {

SqlOpenMode SqlMode(OpenMode mode) {
  switch (mode) {
    case OpenMode::kReadOnly: return SqlOpenMode::kReadOnly;
    case OpenMode::kReadWrite: return SqlOpenMode::kReadWrite;
    case OpenMode::kCreate: break;
  }
  return SqlOpenMode::kCreate;
}

[[noreturn]] void ThrowOpenError(const std::string& path, OpenMode mode, const SqlError& error) {
  switch (error.kind()) {
    case SqlErrorKind::kNotADatabase:
      throw InputError(path + ": not an SQLite database (expected an ecvpose model library)");
    case SqlErrorKind::kCannotOpen:
      if (mode != OpenMode::kCreate && !std::filesystem::exists(path)) {
        throw InputError(path + ": no such model library (build one with `ecvpose modeldb build ... --db " + path +
                         "`)");
      }
      if (mode != OpenMode::kReadOnly) {
        throw InputError(path + ": cannot write the model library here (is the location writable?): " + error.what());
      }
      throw InputError(path + ": cannot open the model library: " + error.what());
    case SqlErrorKind::kReadOnly:
      throw InputError(path + ": the model library cannot be written (read-only file or location): " + error.what());
    case SqlErrorKind::kCorrupt: throw InputError(path + ": the model library is damaged: " + error.what());
    default: throw error;
  }
}

}  // namespace

SqlConnection OpenConnection(const std::string& path, OpenMode mode, const ModelDatabaseOptions& options) {
  options.Check();
  if (mode == OpenMode::kCreate && path != ":memory:") {
    const std::filesystem::path directory = std::filesystem::absolute(path).parent_path();
    if (!std::filesystem::is_directory(directory)) {
      ThrowInputError(path, "", "a file in an existing directory", directory.string() + " is not one");
    }
  }
  try {
    SqlConnection connection(path, SqlMode(mode), options.busy_timeout_ms);
    if (mode != OpenMode::kReadOnly && connection.read_only()) {
      throw InputError(path + ": the model library cannot be written (read-only file or location)");
    }
    return connection;
  } catch (const SqlError& error) {
    ThrowOpenError(path, mode, error);
  }
}

SqlConnection OpenLibrary(const std::string& path, OpenMode mode, const ModelDatabaseOptions& options) {
  SqlConnection connection = OpenConnection(path, mode, options);
  try {
    connection.Execute("PRAGMA foreign_keys = ON");
    SchemaState state = InspectSchema(connection);
    if (state.kind == SchemaState::Kind::kEmpty && mode == OpenMode::kCreate) {
      UseWriteAheadLog(connection);
      CreateSchema(connection);
    } else if (state.kind != SchemaState::Kind::kCurrent) {
      throw InputError(SchemaRefusal(path, state));
    }
    if (mode != OpenMode::kReadOnly) UseWriteAheadLog(connection);
  } catch (const SqlError& error) {
    ThrowOpenError(path, mode, error);
  }
  return connection;
}

void UseWriteAheadLog(SqlConnection& connection) {
  SqlStatement mode = connection.Prepare("PRAGMA journal_mode");
  if (mode.Step() && mode.Text(0) != "wal" && mode.Text(0) != "memory") {
    mode.Reset();
    connection.Execute("PRAGMA journal_mode = WAL");
  }
}

std::string PoseText(const Eigen::Isometry3d& pose) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({pose.matrix()(r, 0), pose.matrix()(r, 1), pose.matrix()(r, 2), pose.matrix()(r, 3)});
  }
  return rows.dump();
}

Eigen::Isometry3d PoseFromText(const std::string& text, const std::string& source) {
  const nlohmann::json rows = nlohmann::json::parse(text, nullptr, false);
  Eigen::Isometry3d pose;
  bool valid = rows.is_array() && rows.size() == 4;
  for (int r = 0; valid && r < 4; ++r) {
    const nlohmann::json& row = rows[static_cast<size_t>(r)];
    valid = row.is_array() && row.size() == 4;
    for (int c = 0; valid && c < 4; ++c) {
      valid = row[static_cast<size_t>(c)].is_number();
      if (valid) pose.matrix()(r, c) = row[static_cast<size_t>(c)].get<double>();
    }
  }
  if (!valid || !pose.matrix().allFinite()) ThrowInputError(source, "pose", "a 4x4 nested array of numbers", text);
  return pose;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::optional<int64_t> ModelId(SqlConnection& connection, const std::string& name) {
  SqlStatement select = connection.Prepare("SELECT id FROM models WHERE name = ?");
  select.Bind(1, name);
  if (!select.Step()) return std::nullopt;
  return select.Int(0);
}

int64_t RequireModelId(SqlConnection& connection, const std::string& name) {
  if (const std::optional<int64_t> id = ModelId(connection, name)) return *id;
  SqlStatement names = connection.Prepare("SELECT name FROM models ORDER BY name");
  std::string known;
  while (names.Step()) known += (known.empty() ? "" : ", ") + names.Text(0);
  ThrowInputError(connection.path(), "model", "one of the library's models (" + (known.empty() ? "none" : known) + ")",
                  "\"" + name + "\"");
}

std::optional<ColorMatrixRecord> ReadColorMatrix(SqlConnection& connection, int64_t model_id) {
  SqlStatement select = connection.Prepare(
      "SELECT a00, a01, a02, a10, a11, a12, a20, a21, a22, rms, source, created FROM color_matrices "
      "WHERE model_id = ?");
  select.Bind(1, model_id);
  if (!select.Step()) return std::nullopt;
  ColorMatrixRecord matrix;
  for (int k = 0; k < 9; ++k) matrix.model_to_scene(k / 3, k % 3) = select.Double(k);
  matrix.rms = select.Double(9);
  matrix.source = select.Text(10);
  matrix.created = select.Text(11);
  return matrix;
}

ModelSummary ReadSummary(const SqlStatement& row, const std::string& path) {
  ModelSummary summary;
  summary.name = row.Text(0);
  summary.mesh_path = row.Text(1);
  summary.mesh_sha256 = row.Text(2);
  summary.unit = row.Text(3);
  summary.object_from_mesh = PoseFromText(row.Text(4), path + ": model " + summary.name + ": object_from_mesh");
  summary.diameter_m = row.Double(5);
  summary.symmetric = row.Int(6) != 0;
  summary.build_options_json = row.Text(7);
  summary.num_views = static_cast<int>(row.Int(8));
  summary.num_primitives = static_cast<int>(row.Int(9));
  summary.num_descriptors = static_cast<int>(row.Int(10));
  summary.descriptor_sha256 = row.Text(11);
  summary.created = row.Text(12);
  summary.has_color_matrix = row.Int(13) != 0;
  summary.mesh_blob_bytes = row.Int(14);
  summary.id = row.Int(15);
  summary.point_pair_points = static_cast<int>(row.Int(16));
  summary.point_pairs = row.Int(17);
  summary.point_pair_refusal = row.Text(18);
  return summary;
}

void InsertPointPairs(SqlConnection& connection, int64_t model_id, const PointPairRecord& record) {
  SqlStatement insert = connection.Prepare(
      "INSERT INTO point_pairs (model_id, settings, num_points, num_pairs, points, refusal) VALUES (?, ?, ?, ?, ?, ?)");
  const std::vector<unsigned char> points = EncodeOrientedPoints(record.points);
  insert.Bind(1, model_id).Bind(2, PpfSamplingToJson(record.sampling));
  insert.Bind(3, static_cast<int64_t>(record.points.size())).Bind(4, record.pairs);
  insert.BindBlob(5, points.data(), points.size()).Bind(6, record.refusal);
  insert.Run();
}

}  // namespace ecv::detail
