#pragma once

// Status and StatusOr<T>: how format/ (and everything that reads untrusted bytes)
// reports failure. No exceptions: format/ also builds with Emscripten where
// exceptions are disabled.

#include <string>
#include <utility>
#include <variant>

namespace casual3d {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,    // The caller passed something out of range.
  kInvalidData,        // Bytes are malformed, truncated or inconsistent.
  kUnsupportedVersion, // A container's major version is not one we read.
  kLimitExceeded,      // A size is beyond a documented limit.
  kNotFound,           // A file or entry does not exist.
  kIoError,            // The operating system refused a read or write.
  kInternal,           // A bug: an invariant did not hold.
};

const char* StatusCodeName(StatusCode code);

class Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // "invalid data: manifest.json: missing field 'width'".
  std::string ToString() const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

inline Status InvalidArgument(std::string m) { return {StatusCode::kInvalidArgument, std::move(m)}; }
inline Status InvalidData(std::string m) { return {StatusCode::kInvalidData, std::move(m)}; }
inline Status UnsupportedVersion(std::string m) {
  return {StatusCode::kUnsupportedVersion, std::move(m)};
}
inline Status LimitExceeded(std::string m) { return {StatusCode::kLimitExceeded, std::move(m)}; }
inline Status NotFound(std::string m) { return {StatusCode::kNotFound, std::move(m)}; }
inline Status IoError(std::string m) { return {StatusCode::kIoError, std::move(m)}; }
inline Status InternalError(std::string m) { return {StatusCode::kInternal, std::move(m)}; }

// Holds either a value or a non-OK status.
template <typename T>
class StatusOr {
 public:
  StatusOr(Status status) : data_(std::move(status)) {}  // NOLINT: implicit by design.
  StatusOr(T value) : data_(std::move(value)) {}         // NOLINT: implicit by design.

  bool ok() const { return std::holds_alternative<T>(data_); }
  const Status& status() const {
    static const Status kOkStatus;
    return ok() ? kOkStatus : std::get<Status>(data_);
  }
  // Precondition: ok().
  const T& value() const& { return std::get<T>(data_); }
  T& value() & { return std::get<T>(data_); }
  T&& value() && { return std::get<T>(std::move(data_)); }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

 private:
  std::variant<Status, T> data_;
};

}  // namespace casual3d

// Returns from the enclosing function if `expr` is a non-OK Status.
#define CASUAL3D_RETURN_IF_ERROR(expr)          \
  do {                                          \
    ::casual3d::Status casual3d_status_ = (expr); \
    if (!casual3d_status_.ok()) return casual3d_status_; \
  } while (0)

#define CASUAL3D_CONCAT_INNER_(a, b) a##b
#define CASUAL3D_CONCAT_(a, b) CASUAL3D_CONCAT_INNER_(a, b)
// Declares `lhs` from a StatusOr expression or returns its status.
#define CASUAL3D_ASSIGN_OR_RETURN(lhs, expr)                                  \
  auto CASUAL3D_CONCAT_(casual3d_or_, __LINE__) = (expr);                     \
  if (!CASUAL3D_CONCAT_(casual3d_or_, __LINE__).ok())                         \
    return CASUAL3D_CONCAT_(casual3d_or_, __LINE__).status();                 \
  lhs = std::move(CASUAL3D_CONCAT_(casual3d_or_, __LINE__)).value()
