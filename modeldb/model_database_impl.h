#pragma once

// Internal to ecv_modeldb: what model_database.cpp and model_database_read.cpp share. Not an API.

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "modeldb/model_database.h"
#include "modeldb/sql.h"

namespace ecv {

struct ModelDatabase::Impl {
  SqlConnection connection;
  bool writable = false;
};

namespace detail {

/// Opens the SQLite file, turning the engine's errors into InputErrors that say what is wrong with the file.
SqlConnection OpenConnection(const std::string& path, OpenMode mode, const ModelDatabaseOptions& options);

/// OpenConnection plus the schema check (and creation of a new library).
SqlConnection OpenLibrary(const std::string& path, OpenMode mode, const ModelDatabaseOptions& options);

/// Switches the file to write-ahead logging (readers do not wait for a writer) unless it is already.
void UseWriteAheadLog(SqlConnection& connection);

/// A pose as stored: 4x4 nested row-major JSON, every double exact.
std::string PoseText(const Eigen::Isometry3d& pose);
Eigen::Isometry3d PoseFromText(const std::string& text, const std::string& source);

/// Current UTC time, ISO 8601 ("2026-11-21T23:14:20Z").
std::string UtcNow();

std::optional<int64_t> ModelId(SqlConnection& connection, const std::string& name);
/// ModelId, or InputError naming the library, the model and the models it has.
int64_t RequireModelId(SqlConnection& connection, const std::string& name);

std::optional<ColorMatrixRecord> ReadColorMatrix(SqlConnection& connection, int64_t model_id);

/// Columns of a model summary, read by ReadSummary (append WHERE / ORDER BY).
inline constexpr const char* kSummarySelect =
    "SELECT m.name, m.mesh_path, m.mesh_sha256, m.unit, m.object_from_mesh, m.diameter_m, m.symmetric, "
    "m.build_options, m.num_views, m.num_primitives, m.num_descriptors, m.descriptor_sha256, m.created, "
    "EXISTS (SELECT 1 FROM color_matrices c WHERE c.model_id = m.id), "
    "coalesce((SELECT length(x.data) FROM meshes x WHERE x.model_id = m.id), 0), m.id, "
    "coalesce((SELECT p.num_points FROM point_pairs p WHERE p.model_id = m.id), -1), "
    "coalesce((SELECT p.num_pairs FROM point_pairs p WHERE p.model_id = m.id), 0), "
    "coalesce((SELECT p.refusal FROM point_pairs p WHERE p.model_id = m.id), '') FROM models m";
ModelSummary ReadSummary(const SqlStatement& row, const std::string& path);

/// Stores a model's point pair points (schema version 3).
void InsertPointPairs(SqlConnection& connection, int64_t model_id, const PointPairRecord& record);

}  // namespace detail
}  // namespace ecv
