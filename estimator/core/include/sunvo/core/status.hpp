#pragma once
// Status and Expected<T>: how library code reports failure. Library code never ends the process;
// it returns one of these and the program decides what to do.

#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace sunvo {

enum class StatusCode {
  kOk = 0,
  kInvalidArgument,     // bad input: a config value, a malformed line, an out-of-range parameter
  kNotFound,            // a missing file, frame or key
  kParseError,          // a file whose content does not follow its format
  kIoError,             // a read or write that failed at the OS level
  kDeviceError,         // a device fault (V4L2, GPIO, serial)
  kTimeout,             // a deadline passed
  kFailedPrecondition,  // called in the wrong state
  kInternal,
};

const char* toString(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status ok() { return {}; }
  bool isOk() const { return code_ == StatusCode::kOk; }
  explicit operator bool() const { return isOk(); }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // "<code>: <message>", or "ok".
  std::string toString() const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

inline Status invalidArgument(std::string m) {
  return {StatusCode::kInvalidArgument, std::move(m)};
}
inline Status notFound(std::string m) {
  return {StatusCode::kNotFound, std::move(m)};
}
inline Status parseError(std::string m) {
  return {StatusCode::kParseError, std::move(m)};
}
inline Status ioError(std::string m) {
  return {StatusCode::kIoError, std::move(m)};
}
inline Status failedPrecondition(std::string m) {
  return {StatusCode::kFailedPrecondition, std::move(m)};
}

// A value or the Status that explains why there is none.
template <typename T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : value_(std::move(value)) {}          // NOLINT(google-explicit-constructor)
  Expected(Status status) : status_(std::move(status)) {}  // NOLINT(google-explicit-constructor)

  bool hasValue() const { return value_.has_value(); }
  explicit operator bool() const { return hasValue(); }
  const Status& status() const { return status_; }
  T& value() & { return *value_; }
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }
  T& operator*() & { return *value_; }
  const T& operator*() const& { return *value_; }
  T* operator->() { return &*value_; }
  const T* operator->() const { return &*value_; }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace sunvo

// Propagates a failed Status from an expression returning Status.
#define SUNVO_RETURN_IF_ERROR(expr)                  \
  do {                                               \
    ::sunvo::Status sunvo_status_ = (expr);          \
    if (!sunvo_status_.isOk()) return sunvo_status_; \
  } while (false)
