#include "modeldb_test_util.h"

#include <cstring>
#include <random>

#include "modeldb/model_builder.h"
#include "modeldb/sql.h"

namespace ecv::test {
namespace {

std::string PoseJson(const Eigen::Isometry3d& pose) {
  std::string text = "[";
  char number[64];
  for (int r = 0; r < 4; ++r) {
    text += r > 0 ? ",[" : "[";
    for (int c = 0; c < 4; ++c) {
      std::snprintf(number, sizeof(number), "%s%.17g", c > 0 ? "," : "", pose.matrix()(r, c));
      text += number;
    }
    text += "]";
  }
  return text + "]";
}

bool SameBits(const void* a, const void* b, size_t size) {
  return std::memcmp(a, b, size) == 0;
}

bool SamePrimitive(const Primitive& a, const Primitive& b) {
  return a.type == b.type && SameBits(a.position.data(), b.position.data(), 12) &&
         SameBits(a.orientation.data(), b.orientation.data(), 12) && SameBits(a.color.data(), b.color.data(), 12) &&
         SameBits(a.pixel.data(), b.pixel.data(), 8) && SameBits(&a.magnitude, &b.magnitude, 4) &&
         SameBits(&a.image_orientation, &b.image_orientation, 4);
}

}  // namespace

ModelRecord SyntheticModel(const std::string& name, int views, int primitives, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  ModelRecord record;
  record.name = name;
  record.mesh_path = "/synthetic/" + name + ".obj";
  record.mesh_sha256 = std::string(64, static_cast<char>('a' + seed % 6));
  record.diameter_m = 0.1 + unit(random);
  record.object_from_mesh.translation() = Eigen::Vector3d(0.01, -0.02, 0.1 * unit(random));
  record.build_options_json = R"({"views":)" + std::to_string(views) + "}";
  for (int v = 0; v < views; ++v) {
    ModelView view;
    view.index = v;
    view.camera = YcbVideoCamera();
    view.camera_from_object = Eigen::Translation3d(0, 0, 0.5 + unit(random)) *
                              Eigen::AngleAxisd(6.0 * unit(random), Eigen::Vector3d(1, 2, 3).normalized());
    std::vector<int> described;
    for (int i = 0; i < primitives; ++i) {
      Primitive p;
      p.type = unit(random) < 0.3F ? PrimitiveType::kSegment : PrimitiveType::kTexlet;
      p.position = Eigen::Vector3f(unit(random), unit(random), unit(random)) * 0.2F;
      p.orientation = Eigen::Vector3f(unit(random) - 0.5F, unit(random) - 0.5F, 1.0F).normalized();
      p.color = {unit(random), unit(random), unit(random)};
      p.pixel = {640.0F * unit(random), 480.0F * unit(random)};
      p.magnitude = unit(random);
      p.image_orientation = 3.14F * unit(random);
      view.primitives.push_back(p);
      if (i % 5 != 4) described.push_back(i);
    }
    view.descriptors.values.create(static_cast<int>(described.size()), kDescriptorSize, CV_32F);
    for (int row = 0; row < view.descriptors.values.rows; ++row) {
      for (int k = 0; k < kDescriptorSize; ++k) view.descriptors.values.at<float>(row, k) = unit(random);
    }
    view.descriptors.primitive = described;
    record.views.push_back(std::move(view));
  }
  return record;
}

void WritePrototypeLibrary(const std::string& path, const std::vector<ModelRecord>& models) {
  SqlConnection db(path, SqlOpenMode::kCreate, 1000);
  db.Execute(R"sql(
BEGIN;
CREATE TABLE settings (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE models (id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, mesh_path TEXT NOT NULL,
  mesh_sha256 TEXT NOT NULL, unit TEXT NOT NULL, object_from_mesh TEXT NOT NULL, diameter_m REAL NOT NULL,
  created TEXT NOT NULL);
CREATE TABLE views (id INTEGER PRIMARY KEY, model_id INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
  view_index INTEGER NOT NULL, fx REAL NOT NULL, fy REAL NOT NULL, cx REAL NOT NULL, cy REAL NOT NULL,
  width INTEGER NOT NULL, height INTEGER NOT NULL, camera_from_object TEXT NOT NULL,
  UNIQUE (model_id, view_index)) STRICT;
CREATE TABLE primitives (id INTEGER PRIMARY KEY, view_id INTEGER NOT NULL REFERENCES views(id) ON DELETE CASCADE,
  primitive_index INTEGER NOT NULL, type INTEGER NOT NULL CHECK (type IN (0, 1)),
  x REAL NOT NULL, y REAL NOT NULL, z REAL NOT NULL, ox REAL NOT NULL, oy REAL NOT NULL, oz REAL NOT NULL,
  r REAL NOT NULL, g REAL NOT NULL, b REAL NOT NULL, u REAL NOT NULL, v REAL NOT NULL,
  magnitude REAL NOT NULL, image_orientation REAL NOT NULL, UNIQUE (view_id, primitive_index)) STRICT;
CREATE TABLE descriptors (primitive_id INTEGER PRIMARY KEY REFERENCES primitives(id) ON DELETE CASCADE,
  value BLOB NOT NULL CHECK (length(value) = 384)) STRICT;
)sql");
  if (!models.empty()) {
    SqlStatement setting = db.Prepare("INSERT INTO settings VALUES ('features', ?)");
    setting.Bind(1, FeatureSettingsToJson(models.front().features)).Run();
  }
  SqlStatement model = db.Prepare("INSERT INTO models VALUES (NULL, ?, ?, ?, ?, ?, ?, '2020-01-01T00:00:00Z')");
  SqlStatement view = db.Prepare("INSERT INTO views VALUES (NULL, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  SqlStatement primitive =
      db.Prepare("INSERT INTO primitives VALUES (NULL, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  SqlStatement descriptor = db.Prepare("INSERT INTO descriptors VALUES (?, ?)");
  for (const ModelRecord& record : models) {
    model.Bind(1, record.name).Bind(2, record.mesh_path).Bind(3, record.mesh_sha256).Bind(4, record.unit);
    model.Bind(5, PoseJson(record.object_from_mesh)).Bind(6, record.diameter_m).Run();
    const int64_t model_id = db.LastInsertRowId();
    for (const ModelView& v : record.views) {
      const PinholeCamera& c = v.camera;
      view.Bind(1, model_id).Bind(2, v.index).Bind(3, c.fx).Bind(4, c.fy).Bind(5, c.cx).Bind(6, c.cy);
      view.Bind(7, c.width).Bind(8, c.height).Bind(9, PoseJson(v.camera_from_object)).Run();
      const int64_t view_id = db.LastInsertRowId();
      std::vector<int> row_of(v.primitives.size(), -1);
      for (size_t r = 0; r < v.descriptors.primitive.size(); ++r)
        row_of[static_cast<size_t>(v.descriptors.primitive[r])] = static_cast<int>(r);
      for (size_t i = 0; i < v.primitives.size(); ++i) {
        const Primitive& p = v.primitives[i];
        primitive.Bind(1, view_id).Bind(2, static_cast<int64_t>(i)).Bind(3, static_cast<int>(p.type));
        const float f[] = {p.position.x(),    p.position.y(), p.position.z(),     p.orientation.x(), p.orientation.y(),
                           p.orientation.z(), p.color.x(),    p.color.y(),        p.color.z(),       p.pixel.x(),
                           p.pixel.y(),       p.magnitude,    p.image_orientation};
        for (int k = 0; k < 13; ++k) primitive.Bind(4 + k, static_cast<double>(f[k]));
        primitive.Run();
        if (row_of[i] < 0) continue;
        descriptor.Bind(1, db.LastInsertRowId()).BindBlob(2, v.descriptors.values.ptr<float>(row_of[i]), 384).Run();
      }
    }
  }
  db.Execute("COMMIT");
}

std::string CompareViews(const std::vector<ModelView>& expected, const std::vector<ModelView>& actual) {
  if (expected.size() != actual.size()) {
    return std::to_string(expected.size()) + " views expected, " + std::to_string(actual.size()) + " found";
  }
  for (size_t v = 0; v < expected.size(); ++v) {
    const ModelView& a = expected[v];
    const ModelView& b = actual[v];
    const std::string where = "view " + std::to_string(v) + ": ";
    if (a.index != b.index) return where + "index";
    if (!SameBits(&a.camera.fx, &b.camera.fx, 4 * sizeof(double)) || a.camera.width != b.camera.width ||
        a.camera.height != b.camera.height) {
      return where + "camera";
    }
    if (!SameBits(a.camera_from_object.data(), b.camera_from_object.data(), 16 * sizeof(double))) {
      return where + "camera_from_object";
    }
    if (a.primitives.size() != b.primitives.size()) return where + "number of primitives";
    for (size_t i = 0; i < a.primitives.size(); ++i) {
      if (!SamePrimitive(a.primitives[i], b.primitives[i])) return where + "primitive " + std::to_string(i);
    }
    if (a.descriptors.primitive != b.descriptors.primitive) return where + "descriptor rows";
    if (a.descriptors.values.rows != b.descriptors.values.rows) return where + "number of descriptors";
    if (a.descriptors.values.rows > 0 && !SameBits(a.descriptors.values.ptr<float>(), b.descriptors.values.ptr<float>(),
                                                   a.descriptors.values.total() * sizeof(float))) {
      return where + "descriptor values";
    }
  }
  return "";
}

PinholeCamera SmallCamera() {
  const PinholeCamera full = YcbVideoCamera();
  return {full.fx / 2, full.fy / 2, (full.cx + 0.5) / 2 - 0.5, (full.cy + 0.5) / 2 - 0.5, 320, 240};
}

std::string DemoMeshDirectory() {
  return std::string(ECV_SOURCE_DIR) + "/models/meshes";
}

}  // namespace ecv::test
