#include "patrolmap/core/sqlite.h"

#include <sqlite3.h>

namespace patrolmap {

void SqliteDatabase::Closer::operator()(sqlite3* database) const { sqlite3_close(database); }
void SqliteStatement::Finalizer::operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }

SqliteDatabase::SqliteDatabase() = default;
SqliteDatabase::~SqliteDatabase() = default;
SqliteDatabase::SqliteDatabase(SqliteDatabase&&) noexcept = default;
SqliteDatabase& SqliteDatabase::operator=(SqliteDatabase&&) noexcept = default;

Status SqliteDatabase::Open(const std::string& path, Mode mode, SqliteDatabase* database) {
  sqlite3* raw = nullptr;
  const int flags = mode == Mode::kReadOnly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
  const int code = sqlite3_open_v2(path.c_str(), &raw, flags, nullptr);
  database->handle_.reset(raw);
  database->path_ = path;
  if (code != SQLITE_OK) return database->Error("cannot open");
  return Status::Ok();
}

Status SqliteDatabase::Error(const std::string& doing) const {
  if (!handle_) return Status::IoError(path_ + ": " + doing + ": out of memory");
  const std::string message = sqlite3_errmsg(handle_.get());
  const int code = sqlite3_errcode(handle_.get());
  if (code == SQLITE_CORRUPT || code == SQLITE_NOTADB) {
    return Status::DataLoss(path_ + ": truncated or damaged database (SQLite: " + message + ")");
  }
  if (code == SQLITE_FULL || code == SQLITE_IOERR || code == SQLITE_CANTOPEN || code == SQLITE_READONLY) {
    return Status::IoError(path_ + ": " + doing + ": " + message);
  }
  return Status::DataLoss(path_ + ": " + doing + ": " + message);
}

Status SqliteDatabase::Execute(const std::string& sql) {
  if (sqlite3_exec(handle_.get(), sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) return Error(sql);
  return Status::Ok();
}

Status SqliteDatabase::Prepare(const std::string& sql, SqliteStatement* statement, const std::string& doing) {
  const std::string& what = doing.empty() ? sql : doing;
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(handle_.get(), sql.c_str(), -1, &raw, nullptr) != SQLITE_OK) return Error(what);
  statement->handle_.reset(raw);
  statement->database_ = this;
  statement->doing_ = what;
  return Status::Ok();
}

bool SqliteDatabase::HasTable(const std::string& name) {
  SqliteStatement statement;
  if (!Prepare("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?", &statement).ok()) return false;
  Status status;
  return statement.Bind(1, name).Step(&status);
}

Status SqliteDatabase::Close() {
  if (handle_ && sqlite3_close(handle_.get()) != SQLITE_OK) return Error("cannot close");
  (void)handle_.release();
  return Status::Ok();
}

SqliteStatement& SqliteStatement::Bind(int index, std::int64_t value) {
  sqlite3_bind_int64(handle_.get(), index, value);
  return *this;
}

SqliteStatement& SqliteStatement::Bind(int index, double value) {
  sqlite3_bind_double(handle_.get(), index, value);
  return *this;
}

SqliteStatement& SqliteStatement::Bind(int index, const std::string& text) {
  sqlite3_bind_text(handle_.get(), index, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
  return *this;
}

SqliteStatement& SqliteStatement::BindBlob(int index, const void* data, std::size_t size) {
  // A zero-length blob is a blob, not NULL: SQLite needs a pointer for it.
  static const char kEmpty = 0;
  sqlite3_bind_blob64(handle_.get(), index, size == 0 ? &kEmpty : data, size, SQLITE_TRANSIENT);
  return *this;
}

SqliteStatement& SqliteStatement::BindNull(int index) {
  sqlite3_bind_null(handle_.get(), index);
  return *this;
}

bool SqliteStatement::Step(Status* status) {
  const int code = sqlite3_step(handle_.get());
  if (code == SQLITE_ROW) return true;
  if (code != SQLITE_DONE) *status = database_->Error(doing_);
  return false;
}

Status SqliteStatement::Run() {
  Status status;
  while (Step(&status)) {
  }
  Reset();
  return status;
}

void SqliteStatement::Reset() {
  sqlite3_reset(handle_.get());
  sqlite3_clear_bindings(handle_.get());
}

bool SqliteStatement::IsNull(int column) const { return sqlite3_column_type(handle_.get(), column) == SQLITE_NULL; }
std::int64_t SqliteStatement::Int(int column) const { return sqlite3_column_int64(handle_.get(), column); }
double SqliteStatement::Real(int column) const { return sqlite3_column_double(handle_.get(), column); }

std::string SqliteStatement::Text(int column) const {
  const unsigned char* text = sqlite3_column_text(handle_.get(), column);
  const int size = sqlite3_column_bytes(handle_.get(), column);
  return text == nullptr ? std::string()
                         : std::string(reinterpret_cast<const char*>(text), static_cast<std::size_t>(size));
}

const unsigned char* SqliteStatement::Blob(int column, std::size_t* size) const {
  const void* data = sqlite3_column_blob(handle_.get(), column);
  *size = static_cast<std::size_t>(sqlite3_column_bytes(handle_.get(), column));
  return static_cast<const unsigned char*>(data);
}

}  // namespace patrolmap
