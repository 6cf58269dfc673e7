// Status: the result of an operation that can fail because of bad input or the
// environment (a missing file, a malformed line). Programmer errors are not a
// Status: they abort through PATROLMAP_CHECK.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

namespace patrolmap {

enum class StatusCode {
  kOk = 0,
  kEndOfStream,      // a source has no more items; not an error
  kNotFound,         // a file or folder does not exist
  kInvalidArgument,  // bad option or configuration value
  kDataLoss,         // a file exists but its content is malformed or corrupt
  kIoError,          // the operating system refused a read or write
};

class Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return Status(); }
  static Status EndOfStream() { return Status(StatusCode::kEndOfStream, "end of stream"); }
  static Status NotFound(std::string message) { return {StatusCode::kNotFound, std::move(message)}; }
  static Status InvalidArgument(std::string message) { return {StatusCode::kInvalidArgument, std::move(message)}; }
  static Status DataLoss(std::string message) { return {StatusCode::kDataLoss, std::move(message)}; }
  static Status IoError(std::string message) { return {StatusCode::kIoError, std::move(message)}; }

  bool ok() const { return code_ == StatusCode::kOk; }
  bool end_of_stream() const { return code_ == StatusCode::kEndOfStream; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

}  // namespace patrolmap

// Aborts with file and line when a programmer invariant is broken.
#define PATROLMAP_CHECK(condition)                                                       \
  do {                                                                                   \
    if (!(condition)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                      \
    }                                                                                    \
  } while (false)

// Returns the status from the enclosing function when it is not ok.
#define PATROLMAP_RETURN_IF_ERROR(expression)   \
  do {                                          \
    ::patrolmap::Status status_ = (expression); \
    if (!status_.ok()) return status_;          \
  } while (false)
