// Errors as values. Functions that can fail return Status or Expected<T>;
// only main() turns them into a message and an exit code.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace depthbench {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,  // bad input: a flag, a file, a field (exit 2)
  kNotFound,         // a file, device or name that does not exist (exit 2)
  kUnavailable,      // no Vulkan device, a driver failure (exit 2)
  kCompileError,     // a shader that does not compile (exit 2)
  kIoError,          // a file that cannot be read or written (exit 2)
  kInterrupted,      // stopped by SIGINT or SIGTERM (exit 128 + signal; base/interrupt.h)
  kInternal,         // a bug in depthbench itself
};

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return {}; }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }

  // Prepends context ("reading baseline.json: ") to the message.
  Status WithContext(const std::string& context) const {
    if (ok()) return *this;
    return Status(code_, context + ": " + message_);
  }

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

inline Status InvalidArgument(std::string message) { return Status(StatusCode::kInvalidArgument, std::move(message)); }
inline Status NotFound(std::string message) { return Status(StatusCode::kNotFound, std::move(message)); }
inline Status Unavailable(std::string message) { return Status(StatusCode::kUnavailable, std::move(message)); }
inline Status CompileError(std::string message) { return Status(StatusCode::kCompileError, std::move(message)); }
inline Status IoError(std::string message) { return Status(StatusCode::kIoError, std::move(message)); }
inline Status Internal(std::string message) { return Status(StatusCode::kInternal, std::move(message)); }
// An options struct's own check failed: "Violated constraint: <constraint>",
// the constraint named as a reader of the struct would write it.
inline Status ViolatedConstraint(const std::string& constraint) {
  return InvalidArgument("Violated constraint: " + constraint);
}

// A value or the Status that explains why there is none.
template <class T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : state_(std::move(value)) {}         // NOLINT: implicit by design
  Expected(Status status) : state_(std::move(status)) {}  // NOLINT: implicit by design

  bool ok() const { return std::holds_alternative<T>(state_); }
  const Status& status() const {
    static const Status kOk;
    return ok() ? kOk : std::get<Status>(state_);
  }
  T& value() & { return std::get<T>(state_); }
  const T& value() const& { return std::get<T>(state_); }
  T&& value() && { return std::get<T>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Status> state_;
};

// Moves an Expected's value into `target`, or returns its Status: the
// single-statement form for assignments that are conditional.
template <class T, class U>
Status StoreInto(Expected<U> from, T& target) {
  if (!from.ok()) return from.status();
  target = std::move(from).value();
  return Status::Ok();
}

}  // namespace depthbench

// Returns early with the Status of an expression that failed.
#define DB_RETURN_IF_ERROR(expr)              \
  do {                                        \
    ::depthbench::Status db_status_ = (expr); \
    if (!db_status_.ok()) return db_status_;  \
  } while (false)

#define DB_CONCAT_INNER(a, b) a##b
#define DB_CONCAT(a, b) DB_CONCAT_INNER(a, b)
// Declares `lhs` from an Expected, or returns its Status. Several
// statements: never the body of an unbraced if or loop (use StoreInto).
#define DB_ASSIGN_OR_RETURN(lhs, expr)                                                            \
  auto DB_CONCAT(db_expected_, __LINE__) = (expr);                                                \
  if (!DB_CONCAT(db_expected_, __LINE__).ok()) return DB_CONCAT(db_expected_, __LINE__).status(); \
  lhs = std::move(DB_CONCAT(db_expected_, __LINE__)).value()
