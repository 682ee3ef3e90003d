// The model library in SQLite (through modeldb/sql.h): opening with the version check, adding and replacing
// models in one transaction, listing, removing, symmetry flags and colour matrices. Loading and verifying are
// in model_database_read.cpp.

#include "modeldb/model_database.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "modeldb/content_hash.h"
#include "modeldb/model_database_impl.h"
#include "modeldb/schema.h"

namespace ecv {

using namespace detail;  // NOLINT(google-build-using-namespace): this library's own internals

namespace {

// The views of `record` are complete: each descriptor row names a primitive of its view.
void CheckRecord(const ModelRecord& record, const std::string& path) {
  if (record.name.empty()) ThrowInputError(path, "model name", "a non-empty name");
  if (record.views.empty()) ThrowInputError(path, "model " + record.name, "at least one view");
  for (const ModelView& view : record.views) {
    const Descriptors& descriptors = view.descriptors;
    const bool shaped = descriptors.values.rows == 0 ||
                        (descriptors.values.type() == CV_32F && descriptors.values.cols == kDescriptorSize);
    if (!shaped || static_cast<size_t>(descriptors.values.rows) != descriptors.primitive.size()) {
      ThrowInputError(path, "model " + record.name + " view " + std::to_string(view.index),
                      "one row of 96 float32 per described primitive");
    }
    for (const int primitive : descriptors.primitive) {
      if (primitive < 0 || static_cast<size_t>(primitive) >= view.primitives.size()) {
        ThrowInputError(path, "model " + record.name + " view " + std::to_string(view.index),
                        "descriptor rows that refer to its primitives", std::to_string(primitive));
      }
    }
  }
}

void InsertPrimitives(SqlConnection& connection, int64_t view_id, const ModelView& view) {
  std::vector<int> row_of(view.primitives.size(), -1);
  for (size_t row = 0; row < view.descriptors.primitive.size(); ++row) {
    row_of[static_cast<size_t>(view.descriptors.primitive[row])] = static_cast<int>(row);
  }
  SqlStatement insert = connection.Prepare(
      "INSERT INTO primitives (view_id, primitive_index, type, x, y, z, ox, oy, oz, r, g, b, u, v, magnitude, "
      "image_orientation) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  SqlStatement describe = connection.Prepare("INSERT INTO descriptors (primitive_id, value) VALUES (?, ?)");
  for (size_t i = 0; i < view.primitives.size(); ++i) {
    const Primitive& p = view.primitives[i];
    insert.Bind(1, view_id).Bind(2, static_cast<int64_t>(i)).Bind(3, static_cast<int>(p.type));
    const float values[] = {p.position.x(),    p.position.y(), p.position.z(),     p.orientation.x(), p.orientation.y(),
                            p.orientation.z(), p.color.x(),    p.color.y(),        p.color.z(),       p.pixel.x(),
                            p.pixel.y(),       p.magnitude,    p.image_orientation};
    for (int k = 0; k < 13; ++k) insert.Bind(4 + k, static_cast<double>(values[k]));
    insert.Run();
    if (row_of[i] < 0) continue;
    describe.Bind(1, connection.LastInsertRowId())
        .BindBlob(2, view.descriptors.values.ptr<float>(row_of[i]), kDescriptorSize * sizeof(float));
    describe.Run();
  }
}

// The model's row; with the id of the model it replaces, so that a model keeps its number (its BOP obj_id).
int64_t InsertModelRow(SqlConnection& connection, const ModelRecord& record, std::optional<int64_t> id) {
  SqlStatement insert = connection.Prepare(
      "INSERT INTO models (name, mesh_path, mesh_sha256, unit, object_from_mesh, diameter_m, symmetric, "
      "build_options, num_views, num_primitives, num_descriptors, descriptor_sha256, created, id) "
      "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  insert.Bind(1, record.name).Bind(2, record.mesh_path).Bind(3, record.mesh_sha256).Bind(4, record.unit);
  insert.Bind(5, PoseText(record.object_from_mesh)).Bind(6, record.diameter_m).Bind(7, record.symmetric ? 1 : 0);
  insert.Bind(8, record.build_options_json.empty() ? std::string("{}") : record.build_options_json);
  insert.Bind(9, static_cast<int>(record.views.size())).Bind(10, record.NumPrimitives());
  insert.Bind(11, record.NumDescriptors()).Bind(12, record.DescriptorSha256()).Bind(13, UtcNow());
  if (id) insert.Bind(14, *id);  // unbound: NULL, a new number
  insert.Run();
  return connection.LastInsertRowId();
}

void InsertView(SqlConnection& connection, int64_t model_id, const ModelView& view) {
  SqlStatement insert = connection.Prepare(
      "INSERT INTO views (model_id, view_index, fx, fy, cx, cy, width, height, camera_from_object) "
      "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
  const PinholeCamera& c = view.camera;
  insert.Bind(1, model_id).Bind(2, view.index).Bind(3, c.fx).Bind(4, c.fy).Bind(5, c.cx).Bind(6, c.cy);
  insert.Bind(7, c.width).Bind(8, c.height).Bind(9, PoseText(view.camera_from_object));
  insert.Run();
  InsertPrimitives(connection, connection.LastInsertRowId(), view);
}

void InsertMeshBlob(SqlConnection& connection, int64_t model_id, const std::vector<unsigned char>& blob) {
  SqlStatement insert = connection.Prepare("INSERT INTO meshes (model_id, sha256, data) VALUES (?, ?, ?)");
  insert.Bind(1, model_id).Bind(2, Sha256Hex(blob.data(), blob.size())).BindBlob(3, blob.data(), blob.size());
  insert.Run();
}

void WriteColorMatrix(SqlConnection& connection, int64_t model_id, const ColorMatrixRecord& matrix,
                      const std::string& created) {
  SqlStatement insert = connection.Prepare(
      "INSERT OR REPLACE INTO color_matrices (model_id, a00, a01, a02, a10, a11, a12, a20, a21, a22, rms, source, "
      "created) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  insert.Bind(1, model_id);
  for (int k = 0; k < 9; ++k) insert.Bind(2 + k, matrix.model_to_scene(k / 3, k % 3));
  insert.Bind(11, matrix.rms).Bind(12, matrix.source).Bind(13, created);
  insert.Run();
}

// "descriptor.soft_binning = false" for each setting whose value differs between two settings JSONs.
std::pair<std::string, std::string> SettingDifferences(const std::string& library, const std::string& model) {
  const nlohmann::json a = nlohmann::json::parse(library, nullptr, false).flatten();
  const nlohmann::json b = nlohmann::json::parse(model, nullptr, false).flatten();
  std::string in_library, in_model;
  for (const auto& item : b.items()) {
    if (a.contains(item.key()) && a.at(item.key()) == item.value()) continue;
    std::string key = item.key().substr(1);
    std::replace(key.begin(), key.end(), '/', '.');
    in_library +=
        (in_library.empty() ? "" : ", ") + key + " = " + (a.contains(item.key()) ? a.at(item.key()).dump() : "?");
    in_model += (in_model.empty() ? "" : ", ") + key + " = " + item.value().dump();
  }
  return {in_library, in_model};
}

// The library's feature settings must be the record's, unless the record is (or replaces) its only model.
void AdoptFeatureSettings(SqlConnection& connection, const ModelRecord& record) {
  const std::string settings = FeatureSettingsToJson(record.features);
  SqlStatement others = connection.Prepare("SELECT count(*) FROM models WHERE name != ?");
  others.Bind(1, record.name);
  others.Step();
  const std::string stored = MetaValue(connection, "features");
  if (others.Int(0) > 0 && stored != settings) {
    const auto [in_library, in_model] = SettingDifferences(stored, settings);
    ThrowInputError(connection.path(), "feature settings of model \"" + record.name + "\"",
                    "the library's (" + in_library +
                        "): every model of a library is built with the same settings; build it into another library",
                    in_model);
  }
  SqlStatement write = connection.Prepare("INSERT OR REPLACE INTO meta (key, value) VALUES ('features', ?)");
  write.Bind(1, settings);
  write.Run();
}

}  // namespace

void ModelDatabaseOptions::Check() const {
  if (busy_timeout_ms < 0) {
    ThrowInputError("model database options", "busy_timeout_ms", "a time >= 0 ms", std::to_string(busy_timeout_ms));
  }
}

ModelDatabase::ModelDatabase(const std::string& path, OpenMode mode, const ModelDatabaseOptions& options)
    : impl_(std::make_unique<Impl>(Impl{OpenLibrary(path, mode, options), mode != OpenMode::kReadOnly})) {}

// A library its writer has finished is left with a rollback journal, so that its readers add no files beside it.
ModelDatabase::~ModelDatabase() {
  if (impl_ && impl_->writable) impl_->connection.LeaveWriteAheadLog();
}

ModelDatabase::ModelDatabase(ModelDatabase&&) noexcept = default;
ModelDatabase& ModelDatabase::operator=(ModelDatabase&&) noexcept = default;

const std::string& ModelDatabase::path() const {
  return impl_->connection.path();
}

std::optional<FeatureSettings> ModelDatabase::feature_settings() const {
  SqlConnection& connection = impl_->connection;
  SqlStatement count = connection.Prepare("SELECT count(*) FROM models");
  count.Step();
  if (count.Int(0) == 0) return std::nullopt;
  return FeatureSettingsFromJson(MetaValue(connection, "features"), connection.path() + ": meta features",
                                 StoredFeatureDefaults());
}

AddModelResult ModelDatabase::AddModel(const ModelRecord& record, const InsertProgress& progress) {
  return Insert(record, std::nullopt, progress);
}

AddModelResult ModelDatabase::AddModel(const StoredModel& model, const InsertProgress& progress) {
  return Insert(model.record, model.color_matrix, progress);
}

AddModelResult ModelDatabase::Insert(const ModelRecord& record, const std::optional<ColorMatrixRecord>& color_matrix,
                                     const InsertProgress& progress) {
  SqlConnection& connection = impl_->connection;
  CheckRecord(record, connection.path());
  const auto start = std::chrono::steady_clock::now();
  AddModelResult result;
  SqlTransaction transaction(connection);
  AdoptFeatureSettings(connection, record);
  std::optional<ColorMatrixRecord> kept_matrix;
  const std::optional<int64_t> old_id = ModelId(connection, record.name);
  if (old_id) {
    result.replaced = true;
    const std::optional<ColorMatrixRecord> matrix = ReadColorMatrix(connection, *old_id);
    SqlStatement hash = connection.Prepare("SELECT mesh_sha256 FROM models WHERE id = ?");
    hash.Bind(1, *old_id);
    const bool same_mesh = hash.Step() && hash.Text(0) == record.mesh_sha256;
    if (matrix && same_mesh) kept_matrix = matrix;
    result.color_matrix_kept = matrix && same_mesh;
    result.color_matrix_dropped = matrix && !same_mesh;
    SqlStatement remove = connection.Prepare("DELETE FROM models WHERE id = ?");  // cascades to views, ...
    remove.Bind(1, *old_id);
    remove.Run();
  }
  const int64_t model_id = InsertModelRow(connection, record, old_id);
  for (size_t v = 0; v < record.views.size(); ++v) {
    InsertView(connection, model_id, record.views[v]);
    if (progress) progress(static_cast<int>(v + 1), static_cast<int>(record.views.size()));
  }
  if (!record.mesh_blob.empty()) InsertMeshBlob(connection, model_id, record.mesh_blob);
  if (record.point_pairs) detail::InsertPointPairs(connection, model_id, *record.point_pairs);
  const std::optional<ColorMatrixRecord>& matrix = color_matrix ? color_matrix : kept_matrix;
  if (matrix) WriteColorMatrix(connection, model_id, *matrix, matrix->created);
  transaction.Commit();
  result.insert_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::vector<ModelSummary> ModelDatabase::ListModels() const {
  SqlStatement select = impl_->connection.Prepare(std::string(kSummarySelect) + " ORDER BY m.name");
  std::vector<ModelSummary> models;
  while (select.Step()) models.push_back(ReadSummary(select, impl_->connection.path()));
  return models;
}

std::optional<ModelSummary> ModelDatabase::FindModel(const std::string& name) const {
  SqlStatement select = impl_->connection.Prepare(std::string(kSummarySelect) + " WHERE m.name = ?");
  select.Bind(1, name);
  if (!select.Step()) return std::nullopt;
  return ReadSummary(select, impl_->connection.path());
}

bool ModelDatabase::RemoveModel(const std::string& name) {
  SqlTransaction transaction(impl_->connection);
  SqlStatement remove = impl_->connection.Prepare("DELETE FROM models WHERE name = ?");
  remove.Bind(1, name);
  remove.Run();
  const bool removed = impl_->connection.Changes() > 0;
  transaction.Commit();
  return removed;
}

void ModelDatabase::SetSymmetric(const std::string& name, bool symmetric) {
  SqlTransaction transaction(impl_->connection);
  const int64_t id = RequireModelId(impl_->connection, name);
  SqlStatement update = impl_->connection.Prepare("UPDATE models SET symmetric = ? WHERE id = ?");
  update.Bind(1, symmetric ? 1 : 0).Bind(2, id);
  update.Run();
  transaction.Commit();
}

void ModelDatabase::SetColorMatrix(const std::string& name, const ColorMatrixRecord& matrix) {
  if (!matrix.model_to_scene.allFinite() || !std::isfinite(matrix.rms)) {
    ThrowInputError(path(), "colour matrix of " + name, "finite values");
  }
  SqlTransaction transaction(impl_->connection);
  WriteColorMatrix(impl_->connection, RequireModelId(impl_->connection, name), matrix, UtcNow());
  transaction.Commit();
}

std::optional<ColorMatrixRecord> ModelDatabase::GetColorMatrix(const std::string& name) const {
  return ReadColorMatrix(impl_->connection, RequireModelId(impl_->connection, name));
}

bool ModelDatabase::ClearColorMatrix(const std::string& name) {
  SqlTransaction transaction(impl_->connection);
  SqlStatement remove = impl_->connection.Prepare("DELETE FROM color_matrices WHERE model_id = ?");
  remove.Bind(1, RequireModelId(impl_->connection, name));
  remove.Run();
  const bool cleared = impl_->connection.Changes() > 0;
  transaction.Commit();
  return cleared;
}

ModelDbMigration MigrateModelDatabase(const std::string& path, const ModelDatabaseOptions& options) {
  options.Check();
  SqlConnection connection = OpenConnection(path, OpenMode::kReadWrite, options);
  const MigrationResult migrated = MigrateSchema(connection);
  connection.LeaveWriteAheadLog();
  return {migrated.from_version, migrated.to_version, migrated.steps, migrated.notes};
}

}  // namespace ecv
