#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "modeldb/model_record.h"

namespace ecv {

/// How a library file is opened.
enum class OpenMode {
  kReadOnly,   ///< must exist; never written (a location without write access works too)
  kReadWrite,  ///< must exist
  kCreate,     ///< created (with the current schema) when missing or empty
};

/// Settings of a library connection.
struct ModelDatabaseOptions {
  /// How long to wait for another process's write lock (a writer storing a model), milliseconds.
  int busy_timeout_ms = 60000;

  void Check() const;
};

/// What AddModel did.
struct AddModelResult {
  bool replaced = false;              ///< a model of that name was there and is now replaced
  bool color_matrix_kept = false;     ///< the replaced model's colour matrix was kept (same mesh content)
  bool color_matrix_dropped = false;  ///< the replaced model had one, but the mesh content differs
  double insert_ms = 0.0;             ///< time of the transaction, milliseconds
};

/// Called after each view is written inside AddModel's transaction: (views written, views in all).
using InsertProgress = std::function<void(int done, int total)>;

/// Result of Verify: an empty `problems` means the library is consistent.
struct VerifyReport {
  std::vector<std::string> problems;  ///< one line each, naming the model or table
  int models = 0;
  int views = 0;
  long long primitives = 0;
  long long descriptors = 0;
  bool ok() const { return problems.empty(); }
};

/// The object library in one SQLite file (schema in modeldb/README.md): models, their meshes, views, primitives in
/// the object frame, descriptors, colour matrices, and the feature settings every model was built with.
/// Every change is one transaction: a model is in the library whole or not at all. While a writer has the file
/// open it is write-ahead logged (readers load while it adds); a writer that closes it last leaves it with a
/// rollback journal, so that readers leave no -wal or -shm file. One object must not be used by two threads at once.
class ModelDatabase {
 public:
  /// Opens `path` (":memory:" for a database in memory). Throws InputError naming the file for a missing
  /// file, a file that is not an SQLite database or not an ecvpose library, an older schema (naming the
  /// migrate command) or a newer one (naming the ecvpose version needed), and a location that cannot be
  /// written when `mode` writes.
  ModelDatabase(const std::string& path, OpenMode mode, const ModelDatabaseOptions& options = {});
  ~ModelDatabase();
  ModelDatabase(ModelDatabase&&) noexcept;
  ModelDatabase& operator=(ModelDatabase&&) noexcept;

  const std::string& path() const;

  /// The feature settings of the library's models; nullopt while it holds none.
  std::optional<FeatureSettings> feature_settings() const;

  /// Stores `record` in one transaction, replacing a model of the same name atomically (its colour matrix is
  /// kept when the mesh content is the same). Throws InputError when the record's feature settings differ
  /// from the library's, or for an empty name or a record without views.
  AddModelResult AddModel(const ModelRecord& record, const InsertProgress& progress = {});
  /// AddModel of a model as another library stored it (LoadModels): its colour matrix, if it has one, is stored in
  /// the same transaction, with its creation time.
  AddModelResult AddModel(const StoredModel& model, const InsertProgress& progress = {});

  /// All models, by name.
  std::vector<ModelSummary> ListModels() const;

  /// One model; nullopt when there is none of that name.
  std::optional<ModelSummary> FindModel(const std::string& name) const;

  /// Removes a model with its views and colour matrix; false when there was none.
  bool RemoveModel(const std::string& name);

  /// Sets the symmetry flag of a model (throws InputError naming the model when unknown).
  void SetSymmetric(const std::string& name, bool symmetric);

  /// Stores (or replaces) the colour matrix of a model; throws InputError for an unknown model or a matrix
  /// that is not finite.
  void SetColorMatrix(const std::string& name, const ColorMatrixRecord& matrix);
  std::optional<ColorMatrixRecord> GetColorMatrix(const std::string& name) const;
  /// False when the model had none.
  bool ClearColorMatrix(const std::string& name);

  /// Whole models with their views; `names` empty = all. Read in one transaction, so a writer that commits
  /// meanwhile is either seen entirely or not at all. Throws InputError naming an unknown model.
  std::vector<StoredModel> LoadModels(const std::vector<std::string>& names = {}) const;

  /// SQLite's integrity and foreign-key checks, stored counts against the rows, view and primitive numbering, the
  /// stored values (rigid poses, a finite diameter, view cameras), and (when `check_descriptors`) the digests of
  /// every model's descriptors and stored mesh.
  VerifyReport Verify(bool check_descriptors = true) const;

 private:
  struct Impl;
  AddModelResult Insert(const ModelRecord& record, const std::optional<ColorMatrixRecord>& color_matrix,
                        const InsertProgress& progress);

  std::unique_ptr<Impl> impl_;
};

/// Result of MigrateModelDatabase.
struct ModelDbMigration {
  int from_version = 0;
  int to_version = 0;
  std::vector<std::string> steps;  ///< steps run, empty when the file was already current
  std::vector<std::string> notes;  ///< what the steps could not do, one line each naming the model
};

/// Brings a library of an older schema to the current one in one transaction (all or nothing). Throws
/// InputError for a newer or foreign file.
ModelDbMigration MigrateModelDatabase(const std::string& path, const ModelDatabaseOptions& options = {});

}  // namespace ecv
