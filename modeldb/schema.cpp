// The library's tables, the version check and the migration steps. Version 1 is the first released schema;
// version 0 is the prototype layout (see kPrototypeTables) that step 0 -> 1 brings up to date; version 2 adds the
// models' meshes (the table `meshes`), so that a library verifies its poses without the mesh files; version 3 adds
// the models' point pair points (the table `point_pairs`).

#include "modeldb/schema.h"

#include <algorithm>
#include <cstdio>
#include <tuple>

#include "core/error.h"
#include "core/version.h"
#include "io/mesh_blob.h"
#include "modeldb/content_hash.h"
#include "modeldb/model_database_impl.h"
#include "modeldb/point_pair_record.h"

namespace ecv {
namespace {

// The ecvpose version that introduced each schema version (index = version), for the refusal of a newer file.
const char* const kFirstEcvposeOfVersion[] = {"0.0 (prototype)", "0.1.0", "0.2.0", "0.3.0"};
static_assert(sizeof(kFirstEcvposeOfVersion) / sizeof(kFirstEcvposeOfVersion[0]) == kModelDbSchemaVersion + 1,
              "name the ecvpose version that introduces each schema version");

const char* const kModelsTable = R"sql(
CREATE TABLE models (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  mesh_path TEXT NOT NULL,
  mesh_sha256 TEXT NOT NULL,
  unit TEXT NOT NULL,
  object_from_mesh TEXT NOT NULL,
  diameter_m REAL NOT NULL,
  symmetric INTEGER NOT NULL DEFAULT 0 CHECK (symmetric IN (0, 1)),
  build_options TEXT NOT NULL,
  num_views INTEGER NOT NULL,
  num_primitives INTEGER NOT NULL,
  num_descriptors INTEGER NOT NULL,
  descriptor_sha256 TEXT NOT NULL,
  created TEXT NOT NULL) STRICT;
)sql";

// Views, primitives and descriptors: the same in the prototype layout and in version 1.
const char* const kViewTables = R"sql(
CREATE TABLE views (
  id INTEGER PRIMARY KEY,
  model_id INTEGER NOT NULL REFERENCES models(id) ON DELETE CASCADE,
  view_index INTEGER NOT NULL,
  fx REAL NOT NULL, fy REAL NOT NULL, cx REAL NOT NULL, cy REAL NOT NULL,
  width INTEGER NOT NULL, height INTEGER NOT NULL,
  camera_from_object TEXT NOT NULL,
  UNIQUE (model_id, view_index)) STRICT;
CREATE TABLE primitives (
  id INTEGER PRIMARY KEY,
  view_id INTEGER NOT NULL REFERENCES views(id) ON DELETE CASCADE,
  primitive_index INTEGER NOT NULL,
  type INTEGER NOT NULL CHECK (type IN (0, 1)),
  x REAL NOT NULL, y REAL NOT NULL, z REAL NOT NULL,
  ox REAL NOT NULL, oy REAL NOT NULL, oz REAL NOT NULL,
  r REAL NOT NULL, g REAL NOT NULL, b REAL NOT NULL,
  u REAL NOT NULL, v REAL NOT NULL,
  magnitude REAL NOT NULL, image_orientation REAL NOT NULL,
  UNIQUE (view_id, primitive_index)) STRICT;
CREATE TABLE descriptors (
  primitive_id INTEGER PRIMARY KEY REFERENCES primitives(id) ON DELETE CASCADE,
  value BLOB NOT NULL CHECK (length(value) = 384)) STRICT;
)sql";

const char* const kMetaAndColorTables = R"sql(
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL) STRICT;
CREATE TABLE color_matrices (
  model_id INTEGER PRIMARY KEY REFERENCES models(id) ON DELETE CASCADE,
  a00 REAL NOT NULL, a01 REAL NOT NULL, a02 REAL NOT NULL,
  a10 REAL NOT NULL, a11 REAL NOT NULL, a12 REAL NOT NULL,
  a20 REAL NOT NULL, a21 REAL NOT NULL, a22 REAL NOT NULL,
  rms REAL NOT NULL,
  source TEXT NOT NULL,
  created TEXT NOT NULL) STRICT;
)sql";

// Version 2: each model's mesh as rendered (object frame, metres; io/mesh_blob.h), with the SHA-256 of its bytes.
// A model stored by an older ecvpose has no row: its mesh is read from mesh_path.
const char* const kMeshesTable = R"sql(
CREATE TABLE meshes (
  model_id INTEGER PRIMARY KEY REFERENCES models(id) ON DELETE CASCADE,
  sha256 TEXT NOT NULL,
  data BLOB NOT NULL) STRICT;
)sql";

// Version 3: each model's point pair points (modeldb/point_pair_record.h): how they were drawn from the mesh
// (settings, JSON), the points (num_points x 6 float32: position and normal), the pairs of their table, and, for a
// mesh too small, flat or coarse for point pairs, the refusal (no points). A model without a row has none made.
const char* const kPointPairsTable = R"sql(
CREATE TABLE point_pairs (
  model_id INTEGER PRIMARY KEY REFERENCES models(id) ON DELETE CASCADE,
  settings TEXT NOT NULL,
  num_points INTEGER NOT NULL CHECK (num_points >= 0),
  num_pairs INTEGER NOT NULL CHECK (num_pairs >= 0),
  points BLOB NOT NULL CHECK (length(points) = 24 * num_points),
  refusal TEXT NOT NULL DEFAULT '') STRICT;
)sql";

// Tables of the prototype layout (user_version 0, no application id): models without the symmetric flag,
// build options, counts and descriptor digest; no colour matrices; settings in a `settings` table.
const std::vector<std::string> kPrototypeTables = {"descriptors", "models", "primitives", "settings", "views"};

std::vector<std::string> TableNames(SqlConnection& connection) {
  SqlStatement statement = connection.Prepare(
      "SELECT name FROM sqlite_schema WHERE type = 'table' AND name NOT LIKE 'sqlite_%' ORDER BY name");
  std::vector<std::string> names;
  while (statement.Step()) names.push_back(statement.Text(0));
  return names;
}

int PragmaInt(SqlConnection& connection, const std::string& pragma) {
  SqlStatement statement = connection.Prepare("PRAGMA " + pragma);
  return statement.Step() ? static_cast<int>(statement.Int(0)) : 0;
}

void WriteVersionMeta(SqlConnection& connection) {
  SqlStatement insert = connection.Prepare("INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)");
  insert.Bind(1, std::string("min_ecvpose_version"))
      .Bind(2, std::string(kFirstEcvposeOfVersion[kModelDbSchemaVersion]));
  insert.Run();
  insert.Bind(1, std::string("written_by")).Bind(2, std::string("ecvpose ") + kVersion);
  insert.Run();
  connection.Execute("PRAGMA application_id = " + std::to_string(kModelDbApplicationId) +
                     "; PRAGMA user_version = " + std::to_string(kModelDbSchemaVersion));
}

// Step 0 -> 1: settings become meta, models gain the symmetric flag (0), build options, counts and the
// descriptor digest; colour matrices appear.
std::vector<std::string> MigrateFromPrototype(SqlConnection& connection) {
  connection.Execute(kMetaAndColorTables);
  connection.Execute("INSERT INTO meta (key, value) SELECT key, value FROM settings; DROP TABLE settings;");
  connection.Execute(std::string(kModelsTable).replace(std::string(kModelsTable).find("models"), 6, "models_v1"));
  connection.Execute(R"sql(
INSERT INTO models_v1 (id, name, mesh_path, mesh_sha256, unit, object_from_mesh, diameter_m, symmetric,
                       build_options, num_views, num_primitives, num_descriptors, descriptor_sha256, created)
SELECT m.id, m.name, m.mesh_path, m.mesh_sha256, m.unit, m.object_from_mesh, m.diameter_m, 0,
       '{"migrated_from_schema":0}',
       (SELECT count(*) FROM views v WHERE v.model_id = m.id),
       (SELECT count(*) FROM primitives p JOIN views v ON p.view_id = v.id WHERE v.model_id = m.id),
       (SELECT count(*) FROM descriptors d JOIN primitives p ON d.primitive_id = p.id
          JOIN views v ON p.view_id = v.id WHERE v.model_id = m.id),
       '', m.created
FROM models m;
DROP TABLE models;
ALTER TABLE models_v1 RENAME TO models;
)sql");
  SqlStatement ids = connection.Prepare("SELECT id FROM models");
  SqlStatement update = connection.Prepare("UPDATE models SET descriptor_sha256 = ? WHERE id = ?");
  while (ids.Step()) {
    update.Bind(1, StoredDescriptorSha256(connection, ids.Int(0))).Bind(2, ids.Int(0));
    update.Run();
  }
  return {};
}

// Step 1 -> 2: the meshes table, empty (models already stored keep reading their mesh files).
std::vector<std::string> AddMeshesTable(SqlConnection& connection) {
  connection.Execute(kMeshesTable);
  return {};
}

// Step 2 -> 3: the point pairs table, with the points of every model whose mesh is stored, drawn from it with
// today's defaults. A model that reads its mesh file gets none: its file may have changed since the build.
std::vector<std::string> AddPointPairs(SqlConnection& connection) {
  connection.Execute(kPointPairsTable);
  std::vector<std::string> notes;
  SqlStatement models = connection.Prepare(
      "SELECT m.id, m.name, x.data FROM models m LEFT JOIN meshes x ON x.model_id = m.id ORDER BY m.name");
  while (models.Step()) {
    const std::string name = models.Text(1);
    size_t size = 0;
    const auto* data = static_cast<const unsigned char*>(models.Blob(2, &size));
    if (size == 0) {
      notes.push_back("model " + name + ": no stored mesh, so no point pair points; build it again " +
                      "(`ecvpose modeldb build MESH --name " + name + " --db " + connection.path() + "`) to add them");
      continue;
    }
    const PointPairRecord record =
        MakePointPairRecord(DecodeMeshBlob(data, size, connection.path() + ": model " + name + ": stored mesh", false));
    if (!record.refusal.empty()) notes.push_back("model " + name + ": no point pair points: " + record.refusal);
    detail::InsertPointPairs(connection, models.Int(0), record);
  }
  return notes;
}

}  // namespace

SchemaState InspectSchema(SqlConnection& connection) {
  SchemaState state;
  state.version = PragmaInt(connection, "user_version");
  const int application_id = PragmaInt(connection, "application_id");
  const std::vector<std::string> tables = TableNames(connection);
  if (tables.empty() && state.version == 0) return state;
  if (application_id == kModelDbApplicationId && state.version >= 1) {
    if (state.version == kModelDbSchemaVersion) {
      state.kind = SchemaState::Kind::kCurrent;
    } else if (state.version > kModelDbSchemaVersion) {
      state.kind = SchemaState::Kind::kNewer;
      if (std::count(tables.begin(), tables.end(), "meta") > 0) {
        try {
          state.newer_needs_ecvpose = MetaValue(connection, "min_ecvpose_version");
        } catch (const SqlError&) {
          // a newer meta table of another shape: the refusal says "a newer ecvpose"
        }
      }
    } else {
      state.kind = SchemaState::Kind::kOlder;
    }
    return state;
  }
  if (application_id == 0 && state.version == 0 && tables == kPrototypeTables) {
    state.kind = SchemaState::Kind::kOlder;
    return state;
  }
  state.kind = SchemaState::Kind::kForeign;
  std::string names;
  for (const std::string& table : tables) names += (names.empty() ? "" : ", ") + table;
  state.detail = "tables " + (names.empty() ? std::string("(none)") : names) + ", user_version " +
                 std::to_string(state.version) + ", application_id " + std::to_string(application_id);
  return state;
}

void CreateSchema(SqlConnection& connection) {
  SqlTransaction transaction(connection);
  // Another process may have created it between our look and our write lock.
  const SchemaState state = InspectSchema(connection);
  if (state.kind == SchemaState::Kind::kCurrent) return;
  if (state.kind != SchemaState::Kind::kEmpty) throw InputError(SchemaRefusal(connection.path(), state));
  connection.Execute(kModelsTable);
  connection.Execute(kViewTables);
  connection.Execute(kMetaAndColorTables);
  connection.Execute(kMeshesTable);
  connection.Execute(kPointPairsTable);
  WriteVersionMeta(connection);
  transaction.Commit();
}

const std::vector<MigrationStep>& MigrationSteps() {
  static const std::vector<MigrationStep> steps = {
      {0, "0 -> 1: prototype layout to the first release (symmetric flag, counts, descriptor digest, colour matrices)",
       MigrateFromPrototype},
      {1, "1 -> 2: a table for the models' meshes (models stored before keep reading their mesh files)",
       AddMeshesTable},
      {2, "2 -> 3: the models' point pair points, drawn from their stored meshes (shape-driven pose hypotheses)",
       AddPointPairs},
  };
  return steps;
}

MigrationResult MigrateSchema(SqlConnection& connection) {
  MigrationResult result;
  SchemaState state = InspectSchema(connection);
  result.from_version = result.to_version = state.version;
  if (state.kind == SchemaState::Kind::kCurrent) return result;
  if (state.kind != SchemaState::Kind::kOlder) throw InputError(SchemaRefusal(connection.path(), state));
  // Tables are rebuilt: foreign keys must not cascade while one is dropped (the pragma has no effect inside a
  // transaction). They are checked before the commit instead.
  connection.Execute("PRAGMA foreign_keys = OFF");
  try {
    SqlTransaction transaction(connection);
    for (int version = state.version; version < kModelDbSchemaVersion; ++version) {
      const auto& steps = MigrationSteps();
      const auto step = std::find_if(steps.begin(), steps.end(),
                                     [version](const MigrationStep& s) { return s.from_version == version; });
      if (step == steps.end())
        ThrowInputError(connection.path(), "schema version", "a version with a migration step",
                        std::to_string(version));
      const std::vector<std::string> notes = step->apply(connection);
      result.steps.push_back(step->description);
      result.notes.insert(result.notes.end(), notes.begin(), notes.end());
    }
    if (connection.Prepare("PRAGMA foreign_key_check").Step()) {
      ThrowInputError(connection.path(), "foreign keys", "every view, primitive and descriptor to have its owner");
    }
    WriteVersionMeta(connection);
    transaction.Commit();
  } catch (...) {
    connection.Execute("PRAGMA foreign_keys = ON");
    throw;
  }
  connection.Execute("PRAGMA foreign_keys = ON");
  result.to_version = kModelDbSchemaVersion;
  return result;
}

std::string MetaValue(SqlConnection& connection, const std::string& key) {
  SqlStatement statement = connection.Prepare("SELECT value FROM meta WHERE key = ?");
  statement.Bind(1, key);
  return statement.Step() ? statement.Text(0) : std::string();
}

std::string StoredDescriptorSha256(SqlConnection& connection, int64_t model_id) {
  SqlStatement statement = connection.Prepare(
      "SELECT d.value FROM views v JOIN primitives p ON p.view_id = v.id JOIN descriptors d ON d.primitive_id = p.id "
      "WHERE v.model_id = ? ORDER BY v.view_index, p.primitive_index");
  statement.Bind(1, model_id);
  Sha256 hash;
  while (statement.Step()) {
    size_t size = 0;
    const void* data = statement.Blob(0, &size);
    hash.Update(data, size);
  }
  return hash.HexDigest();
}

namespace {

// True when version `a` ("MAJOR.MINOR.PATCH") is later than `b`; versions that do not parse are not later.
bool LaterVersion(const std::string& a, const std::string& b) {
  int a1 = 0, a2 = 0, a3 = 0, b1 = 0, b2 = 0, b3 = 0;
  if (std::sscanf(a.c_str(), "%d.%d.%d", &a1, &a2, &a3) != 3 ||
      std::sscanf(b.c_str(), "%d.%d.%d", &b1, &b2, &b3) != 3) {
    return false;
  }
  return std::tie(a1, a2, a3) > std::tie(b1, b2, b3);
}

}  // namespace

std::string SchemaRefusal(const std::string& path, const SchemaState& state) {
  const std::string current = std::to_string(kModelDbSchemaVersion);
  switch (state.kind) {
    case SchemaState::Kind::kOlder:
      return path + ": model library of schema version " + std::to_string(state.version) + "; this ecvpose (" +
             kVersion + ") reads version " + current + ": run `ecvpose modeldb migrate --db " + path +
             "` to migrate it (one transaction; all or nothing)";
    case SchemaState::Kind::kNewer:
      return path + ": model library of schema version " + std::to_string(state.version) + "; this ecvpose (" +
             kVersion + ") reads versions up to " + current + ": use ecvpose " +
             (LaterVersion(state.newer_needs_ecvpose, kVersion) ? state.newer_needs_ecvpose + " or newer"
                                                                : std::string("of a newer release"));
    case SchemaState::Kind::kForeign:
      return path + ": not an ecvpose model library (an SQLite database with " + state.detail + ")";
    case SchemaState::Kind::kEmpty: return path + ": not an ecvpose model library (an empty database)";
    case SchemaState::Kind::kCurrent: break;
  }
  return path + ": model library of schema version " + current;
}

}  // namespace ecv
