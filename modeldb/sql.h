#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

namespace ecv {

/// What went wrong in the storage engine, for callers that react differently (e.g. to a file that is not a
/// database, or to a database that another process holds locked).
enum class SqlErrorKind { kNotADatabase, kCannotOpen, kBusy, kReadOnly, kCorrupt, kConstraint, kFull, kOther };

/// An error of the storage engine; the message names the database file and the statement.
class SqlError : public std::runtime_error {
 public:
  SqlError(const std::string& message, SqlErrorKind kind) : std::runtime_error(message), kind_(kind) {}
  SqlErrorKind kind() const { return kind_; }

 private:
  SqlErrorKind kind_;
};

enum class SqlOpenMode {
  kReadOnly,   ///< the file must exist; never written (a location without write access is read as immutable)
  kReadWrite,  ///< the file must exist
  kCreate,     ///< created when missing
};

class SqlStatement;

/// One connection to an SQLite database file (or ":memory:"). The only place that calls SQLite; nothing of
/// SQLite appears in this header. Not for use by two threads at once.
class SqlConnection {
 public:
  /// Opens `path`; waits up to `busy_timeout_ms` for locks held by other connections. Throws SqlError.
  SqlConnection(const std::string& path, SqlOpenMode mode, int busy_timeout_ms);
  ~SqlConnection();
  SqlConnection(SqlConnection&&) noexcept;
  SqlConnection& operator=(SqlConnection&&) noexcept;
  SqlConnection(const SqlConnection&) = delete;
  SqlConnection& operator=(const SqlConnection&) = delete;

  /// Runs one or more statements without results.
  void Execute(const std::string& sql);

  /// Compiles one statement.
  SqlStatement Prepare(const std::string& sql);

  /// Row id of the last row inserted by this connection.
  int64_t LastInsertRowId() const;

  /// True when the engine opened the file read-only (no write access to it).
  bool read_only() const;

  /// Rows changed by the last INSERT, UPDATE or DELETE.
  int Changes() const;

  /// Rolls back the open transaction, if any; never throws (for destructors and error paths).
  void RollbackIfActive() noexcept;

  /// Switches a write-ahead-logged file back to a rollback journal (the log checkpointed into the file), so that
  /// readers leave no -wal or -shm file beside it. Does not wait: false, and the file stays as it is, while another
  /// connection has it open. Never throws (for destructors).
  bool LeaveWriteAheadLog() noexcept;

  const std::string& path() const;

  /// True when opened read-only because the location cannot be written (no WAL shared memory possible).
  bool immutable() const;

 private:
  friend class SqlStatement;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A compiled statement; parameters are numbered from 1, result columns from 0.
class SqlStatement {
 public:
  ~SqlStatement();
  SqlStatement(SqlStatement&&) noexcept;
  SqlStatement& operator=(SqlStatement&&) noexcept;
  SqlStatement(const SqlStatement&) = delete;
  SqlStatement& operator=(const SqlStatement&) = delete;

  SqlStatement& Bind(int index, int64_t value);
  SqlStatement& Bind(int index, int value) { return Bind(index, static_cast<int64_t>(value)); }
  SqlStatement& Bind(int index, double value);
  SqlStatement& Bind(int index, const std::string& value);
  SqlStatement& BindBlob(int index, const void* data, size_t size);
  SqlStatement& BindNull(int index);

  /// Advances: true when a result row is ready, false when the statement has finished. Throws SqlError.
  bool Step();

  /// Runs a statement without results to its end.
  void Run();

  /// Makes the statement ready to run again; bindings are kept until rebound.
  void Reset();

  int64_t Int(int column) const;
  double Double(int column) const;
  std::string Text(int column) const;
  bool IsNull(int column) const;
  /// Bytes of a BLOB column, valid until the next Step or Reset; `size` receives their number.
  const void* Blob(int column, size_t* size) const;

 private:
  friend class SqlConnection;
  struct Impl;
  explicit SqlStatement(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// A transaction: BEGIN IMMEDIATE (takes the write lock at once) for writing, BEGIN for a consistent read
/// snapshot; ROLLBACK on destruction unless committed.
class SqlTransaction {
 public:
  enum class Kind { kWrite, kRead };
  explicit SqlTransaction(SqlConnection& connection, Kind kind = Kind::kWrite);
  ~SqlTransaction();
  SqlTransaction(const SqlTransaction&) = delete;
  SqlTransaction& operator=(const SqlTransaction&) = delete;

  void Commit();

 private:
  SqlConnection& connection_;
  bool open_ = true;
};

}  // namespace ecv
