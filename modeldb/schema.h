#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "modeldb/sql.h"

namespace ecv {

/// Schema version this ecvpose writes and reads (SQLite `PRAGMA user_version`).
inline constexpr int kModelDbSchemaVersion = 3;

/// `PRAGMA application_id` of an ecvpose model library ("ECVP").
inline constexpr int kModelDbApplicationId = 0x45435650;

/// What a database file holds, before anything is read from it.
struct SchemaState {
  enum class Kind {
    kEmpty,    ///< no tables at all (a new file)
    kCurrent,  ///< a library of kModelDbSchemaVersion
    kOlder,    ///< a library of an older version that a migration step can bring up to date
    kNewer,    ///< a library written by a newer ecvpose
    kForeign,  ///< an SQLite database that is not an ecvpose library
  };
  Kind kind = Kind::kEmpty;
  int version = 0;                  ///< user_version
  std::string newer_needs_ecvpose;  ///< kNewer: ecvpose version the file asks for, if it says
  std::string detail;               ///< kForeign: what it holds instead
};

/// Reads the version, application id and tables of `connection`'s database.
SchemaState InspectSchema(SqlConnection& connection);

/// Creates the tables of the current version in one transaction and records `created_by` (ecvpose version)
/// in the meta table. The database must be empty.
void CreateSchema(SqlConnection& connection);

/// One migration step: brings a library of `from_version` to `from_version + 1` (inside the caller's
/// transaction); returns what the user should know of what it could not do, one line each.
struct MigrationStep {
  int from_version;
  const char* description;
  std::vector<std::string> (*apply)(SqlConnection& connection);
};

/// The migration steps, oldest first.
const std::vector<MigrationStep>& MigrationSteps();

/// Result of MigrateSchema.
struct MigrationResult {
  int from_version = 0;
  int to_version = 0;
  std::vector<std::string> steps;  ///< descriptions of the steps run (empty when already current)
  std::vector<std::string> notes;  ///< what the steps could not do, e.g. a model left without point pair points
};

/// Runs every step from the database's version to the current one in ONE transaction (all or nothing),
/// then checks foreign keys. Throws InputError for a newer or foreign database.
MigrationResult MigrateSchema(SqlConnection& connection);

/// Value of `key` in the meta table; "" when absent.
std::string MetaValue(SqlConnection& connection, const std::string& key);

/// SHA-256 of a stored model's descriptor values in view and primitive order (as ModelRecord::DescriptorSha256).
std::string StoredDescriptorSha256(SqlConnection& connection, int64_t model_id);

/// The refusal for a database that is not of the current version: names the file, both versions and what to
/// do (the `ecvpose modeldb migrate` command, or the ecvpose version needed).
std::string SchemaRefusal(const std::string& path, const SchemaState& state);

}  // namespace ecv
