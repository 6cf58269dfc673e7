// A thin layer over SQLite 3 (Debian's libsqlite3): a database and its prepared statements as owning values, and
// every failure as a Status naming the file, what was being done and SQLite's message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "patrolmap/core/status.h"

struct sqlite3;
struct sqlite3_stmt;

namespace patrolmap {

class SqliteStatement;

class SqliteDatabase {
 public:
  enum class Mode { kReadOnly, kReadWrite };  // kReadWrite creates the file when missing
  static Status Open(const std::string& path, Mode mode, SqliteDatabase* database);

  SqliteDatabase();
  ~SqliteDatabase();
  SqliteDatabase(SqliteDatabase&&) noexcept;
  SqliteDatabase& operator=(SqliteDatabase&&) noexcept;

  // Runs statements that return no rows (schema, pragmas, transactions).
  Status Execute(const std::string& sql);
  // `doing` names the statement in errors ("reading topics"); the SQL itself when empty.
  Status Prepare(const std::string& sql, SqliteStatement* statement, const std::string& doing = "");
  // Whether the database has a table of that name.
  bool HasTable(const std::string& name);
  Status Close();

  // DataLoss "PATH: DOING: SQLite's message", saying the file is damaged where SQLite found it so.
  Status Error(const std::string& doing) const;
  const std::string& path() const { return path_; }

 private:
  struct Closer {
    void operator()(sqlite3* database) const;
  };
  std::unique_ptr<sqlite3, Closer> handle_;
  std::string path_;
};

// A prepared statement: bind its parameters (from 1), Step through its rows, read their columns (from 0), and
// Reset it to run again.
class SqliteStatement {
 public:
  SqliteStatement& Bind(int index, std::int64_t value);
  SqliteStatement& Bind(int index, double value);
  SqliteStatement& Bind(int index, const std::string& text);
  SqliteStatement& BindBlob(int index, const void* data, std::size_t size);
  SqliteStatement& BindNull(int index);

  // True with a row to read, false when done or on failure (then *status says why).
  bool Step(Status* status);
  // Steps a statement that returns no rows, then resets it.
  Status Run();
  void Reset();

  bool IsNull(int column) const;
  std::int64_t Int(int column) const;
  double Real(int column) const;
  std::string Text(int column) const;
  const unsigned char* Blob(int column, std::size_t* size) const;

 private:
  friend class SqliteDatabase;
  struct Finalizer {
    void operator()(sqlite3_stmt* statement) const;
  };
  std::unique_ptr<sqlite3_stmt, Finalizer> handle_;
  const SqliteDatabase* database_ = nullptr;
  std::string doing_;
};

}  // namespace patrolmap
