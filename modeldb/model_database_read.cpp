// Reading whole models back (one read transaction, so a concurrent writer is seen whole or not at all) and
// verifying a library's consistency.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>

#include "core/camera.h"
#include "core/error.h"
#include "core/pose.h"
#include "modeldb/content_hash.h"
#include "modeldb/model_database.h"
#include "modeldb/model_database_impl.h"
#include "modeldb/schema.h"

namespace ecv {

using namespace detail;  // NOLINT(google-build-using-namespace): this library's own internals

namespace {

// Primitives of one view in index order, with the descriptors of those that have one.
void ReadPrimitives(SqlConnection& connection, int64_t view_id, ModelView* view) {
  SqlStatement select = connection.Prepare(
      "SELECT p.type, p.x, p.y, p.z, p.ox, p.oy, p.oz, p.r, p.g, p.b, p.u, p.v, p.magnitude, p.image_orientation, "
      "d.value FROM primitives p LEFT JOIN descriptors d ON d.primitive_id = p.id WHERE p.view_id = ? "
      "ORDER BY p.primitive_index");
  select.Bind(1, view_id);
  std::vector<float> values;
  while (select.Step()) {
    Primitive p;
    p.type = select.Int(0) == 0 ? PrimitiveType::kSegment : PrimitiveType::kTexlet;
    float f[13];
    for (int k = 0; k < 13; ++k) f[k] = static_cast<float>(select.Double(1 + k));
    p.position = {f[0], f[1], f[2]};
    p.orientation = {f[3], f[4], f[5]};
    p.color = {f[6], f[7], f[8]};
    p.pixel = {f[9], f[10]};
    p.magnitude = f[11];
    p.image_orientation = f[12];
    if (!select.IsNull(14)) {
      size_t size = 0;
      const void* blob = select.Blob(14, &size);  // length 384 is a CHECK constraint of the table
      const size_t offset = values.size();
      values.resize(offset + kDescriptorSize);
      std::memcpy(values.data() + offset, blob, std::min(size, kDescriptorSize * sizeof(float)));
      view->descriptors.primitive.push_back(static_cast<int>(view->primitives.size()));
    }
    view->primitives.push_back(p);
  }
  const int rows = static_cast<int>(view->descriptors.primitive.size());
  view->descriptors.values.create(rows, kDescriptorSize, CV_32F);
  if (rows > 0) std::memcpy(view->descriptors.values.ptr<float>(), values.data(), values.size() * sizeof(float));
}

std::vector<ModelView> ReadViews(SqlConnection& connection, int64_t model_id, const std::string& source) {
  SqlStatement select = connection.Prepare(
      "SELECT id, view_index, fx, fy, cx, cy, width, height, camera_from_object FROM views WHERE model_id = ? "
      "ORDER BY view_index");
  select.Bind(1, model_id);
  std::vector<ModelView> views;
  while (select.Step()) {
    ModelView view;
    view.index = static_cast<int>(select.Int(1));
    view.camera = {select.Double(2),
                   select.Double(3),
                   select.Double(4),
                   select.Double(5),
                   static_cast<int>(select.Int(6)),
                   static_cast<int>(select.Int(7))};
    view.camera_from_object =
        PoseFromText(select.Text(8), source + " view " + std::to_string(view.index) + ": camera_from_object");
    ReadPrimitives(connection, select.Int(0), &view);
    views.push_back(std::move(view));
  }
  return views;
}

std::optional<PointPairRecord> ReadPointPairs(SqlConnection& connection, int64_t model_id, const std::string& source) {
  SqlStatement select =
      connection.Prepare("SELECT settings, num_pairs, points, refusal FROM point_pairs WHERE model_id = ?");
  select.Bind(1, model_id);
  if (!select.Step()) return std::nullopt;
  PointPairRecord record;
  record.sampling = PpfSamplingFromJson(select.Text(0), source + ": point_pairs.settings");
  record.pairs = select.Int(1);
  size_t size = 0;
  const auto* data = static_cast<const unsigned char*>(select.Blob(2, &size));
  record.points = DecodeOrientedPoints(data, size, source + ": point_pairs.points");
  record.refusal = select.Text(3);
  return record;
}

ModelRecord ReadModel(SqlConnection& connection, const std::string& name, const FeatureSettings& features) {
  const int64_t id = RequireModelId(connection, name);
  SqlStatement select = connection.Prepare(std::string(kSummarySelect) + " WHERE m.id = ?");
  select.Bind(1, id);
  select.Step();
  const ModelSummary summary = ReadSummary(select, connection.path());
  ModelRecord record;
  record.id = summary.id;
  record.name = summary.name;
  record.mesh_path = summary.mesh_path;
  record.mesh_sha256 = summary.mesh_sha256;
  record.unit = summary.unit;
  record.object_from_mesh = summary.object_from_mesh;
  record.diameter_m = summary.diameter_m;
  record.symmetric = summary.symmetric;
  record.build_options_json = summary.build_options_json;
  record.features = features;
  record.views = ReadViews(connection, id, connection.path() + ": model " + name);
  SqlStatement mesh = connection.Prepare("SELECT data FROM meshes WHERE model_id = ?");
  mesh.Bind(1, id);
  if (mesh.Step()) {
    size_t size = 0;
    const auto* data = static_cast<const unsigned char*>(mesh.Blob(0, &size));
    record.mesh_blob.assign(data, data + size);
  }
  record.point_pairs = ReadPointPairs(connection, id, connection.path() + ": model " + name);
  return record;
}

// Rows returned by a check query, one problem line each (first column joined with `prefix`).
void CollectProblems(SqlConnection& connection, const std::string& sql, const std::string& prefix,
                     std::vector<std::string>* problems) {
  SqlStatement select = connection.Prepare(sql);
  while (select.Step()) problems->push_back(prefix + select.Text(0));
}

// Stored counts against the rows, and view and primitive numbers 0..n-1 without gaps.
void CheckCounts(SqlConnection& connection, std::vector<std::string>* problems) {
  CollectProblems(connection,
                  "SELECT m.name || ': ' || m.num_views || ' views stored, ' || count(v.id) || ' present' "
                  "FROM models m LEFT JOIN views v ON v.model_id = m.id GROUP BY m.id "
                  "HAVING count(v.id) != m.num_views OR (count(v.id) > 0 AND "
                  "(min(v.view_index) != 0 OR max(v.view_index) != count(v.id) - 1))",
                  "model ", problems);
  CollectProblems(connection,
                  "SELECT m.name || ': ' || m.num_primitives || ' primitives and ' || m.num_descriptors || "
                  "' descriptors stored, ' || count(p.id) || ' and ' || count(d.primitive_id) || ' present' "
                  "FROM models m LEFT JOIN views v ON v.model_id = m.id LEFT JOIN primitives p ON p.view_id = v.id "
                  "LEFT JOIN descriptors d ON d.primitive_id = p.id GROUP BY m.id "
                  "HAVING count(p.id) != m.num_primitives OR count(d.primitive_id) != m.num_descriptors",
                  "model ", problems);
  CollectProblems(connection,
                  "SELECT m.name || ' view ' || v.view_index || ': primitive numbers not 0..n-1' FROM views v "
                  "JOIN models m ON m.id = v.model_id JOIN primitives p ON p.view_id = v.id GROUP BY v.id "
                  "HAVING min(p.primitive_index) != 0 OR max(p.primitive_index) != count(p.id) - 1",
                  "model ", problems);
}

void CheckDescriptorDigests(SqlConnection& connection, std::vector<std::string>* problems) {
  SqlStatement models = connection.Prepare("SELECT id, name, descriptor_sha256 FROM models ORDER BY name");
  while (models.Step()) {
    if (StoredDescriptorSha256(connection, models.Int(0)) != models.Text(2)) {
      problems->push_back("model " + models.Text(1) + ": descriptor values differ from those stored (digest)");
    }
  }
}

void CheckMeshDigests(SqlConnection& connection, std::vector<std::string>* problems) {
  SqlStatement meshes = connection.Prepare(
      "SELECT m.name, x.sha256, x.data FROM meshes x JOIN models m ON m.id = x.model_id ORDER BY m.name");
  while (meshes.Step()) {
    size_t size = 0;
    const void* data = meshes.Blob(2, &size);
    if (Sha256Hex(data, size) != meshes.Text(1)) {
      problems->push_back("model " + meshes.Text(0) + ": stored mesh differs from the one written (digest)");
    }
  }
}

// InputError naming `source` and `field` unless `text` is a rigid 4x4 transform (as written: to rounding).
void CheckStoredPose(const std::string& text, const std::string& source, const std::string& field) {
  RigidFromMatrix(PoseFromText(text, source + ": " + field).matrix(), source, field, 1e-6);
}

// The values a load needs, row by row: rigid poses, a finite diameter > 0, view cameras with finite intrinsics and a
// positive size. Each bad value is one problem naming its model, view and field.
void CheckStoredValues(SqlConnection& connection, std::vector<std::string>* problems) {
  const auto note = [problems](const std::function<void()>& check) {
    try {
      check();
    } catch (const InputError& error) {
      problems->push_back(error.what());
    }
  };
  SqlStatement models = connection.Prepare("SELECT name, object_from_mesh, diameter_m FROM models ORDER BY name");
  while (models.Step()) {
    const std::string model = "model " + models.Text(0);
    note([&] { CheckStoredPose(models.Text(1), model, "object_from_mesh"); });
    const double diameter = models.Double(2);
    if (!std::isfinite(diameter) || diameter <= 0.0) {
      problems->push_back(model + ": diameter_m: expected a finite size > 0 m, got " + std::to_string(diameter));
    }
  }
  SqlStatement views = connection.Prepare(
      "SELECT m.name, v.view_index, v.camera_from_object, v.fx, v.fy, v.cx, v.cy, v.width, v.height FROM views v "
      "JOIN models m ON m.id = v.model_id ORDER BY m.name, v.view_index");
  while (views.Step()) {
    const std::string view = "model " + views.Text(0) + " view " + std::to_string(views.Int(1));
    note([&] { CheckStoredPose(views.Text(2), view, "camera_from_object"); });
    const PinholeCamera camera{views.Double(3),
                               views.Double(4),
                               views.Double(5),
                               views.Double(6),
                               static_cast<int>(views.Int(7)),
                               static_cast<int>(views.Int(8))};
    note([&] { camera.Check(view + ": camera"); });
  }
}

}  // namespace

std::vector<StoredModel> ModelDatabase::LoadModels(const std::vector<std::string>& names) const {
  SqlConnection& connection = impl_->connection;
  SqlTransaction snapshot(connection, SqlTransaction::Kind::kRead);
  std::vector<std::string> wanted = names;
  if (wanted.empty()) {
    SqlStatement all = connection.Prepare("SELECT name FROM models ORDER BY name");
    while (all.Step()) wanted.push_back(all.Text(0));
  }
  std::vector<StoredModel> models;
  if (wanted.empty()) return models;
  const FeatureSettings features = FeatureSettingsFromJson(
      MetaValue(connection, "features"), connection.path() + ": meta features", StoredFeatureDefaults());
  for (const std::string& name : wanted) {
    StoredModel model{ReadModel(connection, name, features), std::nullopt};
    model.color_matrix = ReadColorMatrix(connection, RequireModelId(connection, name));
    models.push_back(std::move(model));
  }
  snapshot.Commit();
  return models;
}

VerifyReport ModelDatabase::Verify(bool check_descriptors) const {
  SqlConnection& connection = impl_->connection;
  SqlTransaction snapshot(connection, SqlTransaction::Kind::kRead);
  VerifyReport report;
  SqlStatement integrity = connection.Prepare("PRAGMA integrity_check");
  while (integrity.Step()) {
    if (integrity.Text(0) != "ok") report.problems.push_back("integrity: " + integrity.Text(0));
  }
  CollectProblems(connection,
                  "SELECT \"table\" || ' row ' || rowid || ' refers to a missing ' || parent "
                  "FROM pragma_foreign_key_check",
                  "foreign key: ", &report.problems);
  CheckCounts(connection, &report.problems);
  CheckStoredValues(connection, &report.problems);
  SqlStatement counts = connection.Prepare(
      "SELECT (SELECT count(*) FROM models), (SELECT count(*) FROM views), (SELECT count(*) FROM primitives), "
      "(SELECT count(*) FROM descriptors)");
  counts.Step();
  report.models = static_cast<int>(counts.Int(0));
  report.views = static_cast<int>(counts.Int(1));
  report.primitives = counts.Int(2);
  report.descriptors = counts.Int(3);
  if (report.models > 0) {
    try {
      FeatureSettingsFromJson(MetaValue(connection, "features"), "meta features", StoredFeatureDefaults());
    } catch (const InputError& error) {
      report.problems.push_back(error.what());
    }
  }
  if (check_descriptors) {
    CheckDescriptorDigests(connection, &report.problems);
    CheckMeshDigests(connection, &report.problems);
  }
  snapshot.Commit();
  return report;
}

}  // namespace ecv
