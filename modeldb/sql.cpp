// The only file that calls SQLite: a small RAII layer (connection, statement, transaction) whose errors name
// the database file and the statement.

#include "modeldb/sql.h"

#include <sqlite3.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <utility>

namespace ecv {
namespace {

SqlErrorKind KindOf(int code) {
  switch (code & 0xFF) {
    case SQLITE_NOTADB: return SqlErrorKind::kNotADatabase;
    case SQLITE_CANTOPEN: return SqlErrorKind::kCannotOpen;
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return SqlErrorKind::kBusy;
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_AUTH: return SqlErrorKind::kReadOnly;
    case SQLITE_CORRUPT: return SqlErrorKind::kCorrupt;
    case SQLITE_CONSTRAINT: return SqlErrorKind::kConstraint;
    case SQLITE_FULL:
    case SQLITE_IOERR: return SqlErrorKind::kFull;
    default: return SqlErrorKind::kOther;
  }
}

// "file:PATH?immutable=1" with the characters that URIs reserve escaped.
std::string ImmutableUri(const std::string& path) {
  std::string uri = "file:";
  for (const char c : path) {
    if (c == '?' || c == '#' || c == '%') {
      static const char kHex[] = "0123456789ABCDEF";
      const auto byte = static_cast<unsigned char>(c);
      uri += {'%', kHex[byte >> 4], kHex[byte & 0xF]};
    } else {
      uri += c;
    }
  }
  return uri + "?immutable=1";
}

bool DirectoryWritable(const std::string& path) {
  std::filesystem::path directory = std::filesystem::absolute(path).parent_path();
  return access(directory.c_str(), W_OK) == 0;
}

}  // namespace

struct SqlConnection::Impl {
  std::string path;
  sqlite3* db = nullptr;
  bool immutable = false;
  int lock_timeout_ms = 0;
  std::chrono::steady_clock::time_point busy_since;
  bool said_waiting = false;

  // SQLite's busy handler: waits in steps of 20 ms up to lock_timeout_ms for another process's lock, and says once
  // (after a second) what it is waiting for, so that a writer queued behind another does not look hung.
  static int WaitForLock(void* self, int count) {
    auto* impl = static_cast<Impl*>(self);
    const auto now = std::chrono::steady_clock::now();
    if (count == 0) impl->busy_since = now;
    const auto waited = std::chrono::duration_cast<std::chrono::milliseconds>(now - impl->busy_since).count();
    if (waited >= impl->lock_timeout_ms) return 0;
    if (waited >= 1000 && !impl->said_waiting) {
      impl->said_waiting = true;
      std::fprintf(stderr, "ecvpose: %s: waiting for the library's lock, held by another process (up to %d s)\n",
                   impl->path.c_str(), impl->lock_timeout_ms / 1000);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return 1;
  }

  ~Impl() { Close(); }
  void Close() {
    if (db != nullptr) sqlite3_close_v2(db);
    db = nullptr;
  }

  [[noreturn]] void Fail(int code, const std::string& context) const {
    const std::string detail = db != nullptr ? sqlite3_errmsg(db) : sqlite3_errstr(code);
    throw SqlError(path + ": " + context + ": " + detail, KindOf(code));
  }

  void Open(const std::string& name, int flags, int busy_timeout_ms) {
    Close();
    const int code = sqlite3_open_v2(name.c_str(), &db, flags | SQLITE_OPEN_URI, nullptr);
    if (code != SQLITE_OK) Fail(code, "cannot open");
    sqlite3_extended_result_codes(db, 1);
    lock_timeout_ms = busy_timeout_ms;
    sqlite3_busy_handler(db, &Impl::WaitForLock, this);
  }

  // Reads the header, so that a file that is not a database fails here rather than at the first query.
  int Probe() const { return sqlite3_exec(db, "PRAGMA schema_version", nullptr, nullptr, nullptr); }
};

SqlConnection::SqlConnection(const std::string& path, SqlOpenMode mode, int busy_timeout_ms)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  const bool memory = path == ":memory:";
  if (!memory && std::filesystem::is_directory(path)) {
    throw SqlError(path + ": is a directory, not a model library file", SqlErrorKind::kCannotOpen);
  }
  if (mode != SqlOpenMode::kCreate && !memory && !std::filesystem::is_regular_file(path)) {
    throw SqlError(path + ": no such file", SqlErrorKind::kCannotOpen);
  }
  const int flags = mode == SqlOpenMode::kReadOnly    ? SQLITE_OPEN_READONLY
                    : mode == SqlOpenMode::kReadWrite ? SQLITE_OPEN_READWRITE
                                                      : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
  impl_->Open(path, flags, busy_timeout_ms);
  int code = impl_->Probe();
  // A WAL database in a location we cannot write has no shared-memory file to coordinate through; nobody can
  // be writing it, so it is read as immutable.
  if (code != SQLITE_OK && mode == SqlOpenMode::kReadOnly && KindOf(code) != SqlErrorKind::kNotADatabase && !memory &&
      !DirectoryWritable(path)) {
    impl_->Open(ImmutableUri(path), SQLITE_OPEN_READONLY, busy_timeout_ms);
    impl_->immutable = true;
    code = impl_->Probe();
  }
  if (code != SQLITE_OK) impl_->Fail(code, "cannot read");
  // A writer checks at once that it can take the write lock (e.g. no stale read-only -shm file beside the library),
  // rather than after the work whose result it would store.
  if (mode != SqlOpenMode::kReadOnly && !memory) {
    code = sqlite3_exec(impl_->db, "BEGIN IMMEDIATE; ROLLBACK", nullptr, nullptr, nullptr);
    if (code != SQLITE_OK) {
      RollbackIfActive();
      impl_->Fail(code, "cannot write");
    }
  }
}

bool SqlConnection::LeaveWriteAheadLog() noexcept {
  if (!impl_ || impl_->db == nullptr || impl_->path == ":memory:" || impl_->immutable) return false;
  sqlite3_busy_handler(impl_->db, nullptr, nullptr);  // another connection's lock: give up at once
  const int code = sqlite3_exec(impl_->db, "PRAGMA journal_mode = DELETE", nullptr, nullptr, nullptr);
  sqlite3_busy_handler(impl_->db, &Impl::WaitForLock, impl_.get());
  sqlite3_stmt* statement = nullptr;
  bool left = false;
  if (code == SQLITE_OK && sqlite3_prepare_v2(impl_->db, "PRAGMA journal_mode", -1, &statement, nullptr) == SQLITE_OK &&
      sqlite3_step(statement) == SQLITE_ROW) {
    const auto* mode = reinterpret_cast<const char*>(sqlite3_column_text(statement, 0));
    left = mode != nullptr && std::string(mode) == "delete";
  }
  sqlite3_finalize(statement);
  return left;
}

SqlConnection::~SqlConnection() = default;
SqlConnection::SqlConnection(SqlConnection&&) noexcept = default;
SqlConnection& SqlConnection::operator=(SqlConnection&&) noexcept = default;

void SqlConnection::Execute(const std::string& sql) {
  char* error = nullptr;
  const int code = sqlite3_exec(impl_->db, sql.c_str(), nullptr, nullptr, &error);
  if (code != SQLITE_OK) {
    const std::string detail = error != nullptr ? error : sqlite3_errstr(code);
    sqlite3_free(error);
    throw SqlError(impl_->path + ": " + sql.substr(0, 60) + ": " + detail, KindOf(code));
  }
}

int64_t SqlConnection::LastInsertRowId() const {
  return sqlite3_last_insert_rowid(impl_->db);
}

void SqlConnection::RollbackIfActive() noexcept {
  if (impl_ && impl_->db != nullptr && sqlite3_get_autocommit(impl_->db) == 0) {
    sqlite3_exec(impl_->db, "ROLLBACK", nullptr, nullptr, nullptr);
  }
}

bool SqlConnection::read_only() const {
  return sqlite3_db_readonly(impl_->db, "main") == 1;
}

int SqlConnection::Changes() const {
  return sqlite3_changes(impl_->db);
}

const std::string& SqlConnection::path() const {
  return impl_->path;
}

bool SqlConnection::immutable() const {
  return impl_->immutable;
}

struct SqlStatement::Impl {
  const SqlConnection::Impl* connection = nullptr;
  sqlite3_stmt* statement = nullptr;
  ~Impl() { sqlite3_finalize(statement); }

  // Throws with the statement's text and the engine's message, leaving the statement reset for reuse.
  [[noreturn]] void Fail(int code) const {
    const std::string sql = sqlite3_sql(statement);
    const std::string detail = sqlite3_errmsg(connection->db);
    sqlite3_reset(statement);
    throw SqlError(connection->path + ": " + sql.substr(0, 60) + ": " + detail, KindOf(code));
  }
  void Check(int code) const {
    if (code != SQLITE_OK) Fail(code);
  }
};

SqlStatement SqlConnection::Prepare(const std::string& sql) {
  auto statement = std::make_unique<SqlStatement::Impl>();
  statement->connection = impl_.get();
  const int code =
      sqlite3_prepare_v2(impl_->db, sql.c_str(), static_cast<int>(sql.size()), &statement->statement, nullptr);
  if (code != SQLITE_OK) impl_->Fail(code, sql.substr(0, 60));
  return SqlStatement(std::move(statement));
}

SqlStatement::SqlStatement(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SqlStatement::~SqlStatement() = default;
SqlStatement::SqlStatement(SqlStatement&&) noexcept = default;
SqlStatement& SqlStatement::operator=(SqlStatement&&) noexcept = default;

SqlStatement& SqlStatement::Bind(int index, int64_t value) {
  impl_->Check(sqlite3_bind_int64(impl_->statement, index, value));
  return *this;
}

SqlStatement& SqlStatement::Bind(int index, double value) {
  impl_->Check(sqlite3_bind_double(impl_->statement, index, value));
  return *this;
}

SqlStatement& SqlStatement::Bind(int index, const std::string& value) {
  impl_->Check(
      sqlite3_bind_text(impl_->statement, index, value.data(), static_cast<int>(value.size()), SQLITE_TRANSIENT));
  return *this;
}

SqlStatement& SqlStatement::BindBlob(int index, const void* data, size_t size) {
  // An empty vector's data() may be null, which SQLite would bind as NULL instead of an empty blob.
  if (size == 0) {
    impl_->Check(sqlite3_bind_zeroblob(impl_->statement, index, 0));
  } else {
    impl_->Check(sqlite3_bind_blob64(impl_->statement, index, data, size, SQLITE_TRANSIENT));
  }
  return *this;
}

SqlStatement& SqlStatement::BindNull(int index) {
  impl_->Check(sqlite3_bind_null(impl_->statement, index));
  return *this;
}

bool SqlStatement::Step() {
  const int code = sqlite3_step(impl_->statement);
  if (code == SQLITE_ROW) return true;
  if (code == SQLITE_DONE) return false;
  impl_->Fail(code);
}

void SqlStatement::Run() {
  while (Step()) {
  }
  Reset();
}

void SqlStatement::Reset() {
  sqlite3_reset(impl_->statement);
}

int64_t SqlStatement::Int(int column) const {
  return sqlite3_column_int64(impl_->statement, column);
}

double SqlStatement::Double(int column) const {
  return sqlite3_column_double(impl_->statement, column);
}

std::string SqlStatement::Text(int column) const {
  const unsigned char* text = sqlite3_column_text(impl_->statement, column);
  return text != nullptr ? std::string(reinterpret_cast<const char*>(text)) : std::string();
}

bool SqlStatement::IsNull(int column) const {
  return sqlite3_column_type(impl_->statement, column) == SQLITE_NULL;
}

const void* SqlStatement::Blob(int column, size_t* size) const {
  const void* data = sqlite3_column_blob(impl_->statement, column);
  *size = static_cast<size_t>(sqlite3_column_bytes(impl_->statement, column));
  return data;
}

SqlTransaction::SqlTransaction(SqlConnection& connection, Kind kind) : connection_(connection) {
  connection_.Execute(kind == Kind::kWrite ? "BEGIN IMMEDIATE" : "BEGIN");
}

SqlTransaction::~SqlTransaction() {
  if (open_) connection_.RollbackIfActive();
}

void SqlTransaction::Commit() {
  connection_.Execute("COMMIT");
  open_ = false;
}

}  // namespace ecv
