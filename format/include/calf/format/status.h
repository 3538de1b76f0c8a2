// Status and Expected<T>: what every calf library function that can fail returns.
//
// Library code never throws, exits, aborts or prints on bad input (DESIGN.md). It returns a
// Status whose id is stable (format/include/calf/format/errors.h) and whose message names the file,
// field, pixel or value at fault and what was expected, e.g.
//   CALF-E022 depth 0.25 at pixel (3, 17) is below z_near 0.5
// Callers add context as the error travels up with with_context(): the container layer prefixes
// the chunk, the command prefixes the file name.
#pragma once

#include <cassert>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>

#include "calf/format/errors.h"

namespace calf {

class [[nodiscard]] Status {
 public:
  // Success.
  Status() = default;
  // A failure: `id` must not be ErrorId::kOk.
  Status(ErrorId id, std::string message) : id_(id), message_(std::move(message)) {
    assert(id != ErrorId::kOk);
  }
  static Status Ok() { return Status(); }

  bool ok() const { return id_ == ErrorId::kOk; }
  ErrorId id() const { return id_; }
  ErrorKind kind() const { return error_kind(id_); }
  int number() const { return static_cast<int>(id_); }
  // The message without the id: "chunk 37: stored length ... exceeds file size 1234".
  const std::string& message() const { return message_; }
  // "CALF-E012 chunk 37: ...", or "ok". This is the one line a command prints.
  std::string to_string() const;
  // The same error with "context: " put in front of its message (no-op on success), e.g.
  // status.with_context("clip.calf") -> "CALF-E012 clip.calf: chunk 37: ...".
  Status with_context(std::string_view context) const&;
  Status with_context(std::string_view context) &&;

  // Marks a status as deliberately ignored (best-effort cleanup paths).
  void ignore_error() const {}

 private:
  ErrorId id_ = ErrorId::kOk;
  std::string message_;
};

// "CALF-E012" for ErrorId(12).
std::string error_code_string(ErrorId id);

// A value or the Status that explains why there is none. Access to value() on an error is a
// caller bug (asserted in debug builds).
template <typename T>
class [[nodiscard]] Expected {
  static_assert(!std::is_same_v<std::decay_t<T>, Status>, "Expected<Status> is meaningless");

 public:
  Expected(T value) : v_(std::in_place_index<0>, std::move(value)) {}        // NOLINT: implicit
  Expected(Status status) : v_(std::in_place_index<1>, std::move(status)) {  // NOLINT: implicit
    assert(!std::get<1>(v_).ok());
  }
  Expected(ErrorId id, std::string message) : Expected(Status(id, std::move(message))) {}

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & {
    assert(ok());
    return std::get<0>(v_);
  }
  const T& value() const& {
    assert(ok());
    return std::get<0>(v_);
  }
  T&& value() && {
    assert(ok());
    return std::get<0>(std::move(v_));
  }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  // Status::Ok() on success, else the error.
  Status status() const& { return ok() ? Status() : std::get<1>(v_); }
  Status status() && { return ok() ? Status() : std::get<1>(std::move(v_)); }

  Expected with_context(std::string_view context) && {
    if (ok()) return std::move(*this);
    return std::get<1>(std::move(v_)).with_context(context);
  }

 private:
  std::variant<T, Status> v_;
};

}  // namespace calf

#define CALF_INTERNAL_CONCAT2(a, b) a##b
#define CALF_INTERNAL_CONCAT(a, b) CALF_INTERNAL_CONCAT2(a, b)

// Returns the Status of `expr` from the enclosing function if it is an error.
#define CALF_RETURN_IF_ERROR(expr)               \
  do {                                           \
    ::calf::Status calf_status_ = (expr);        \
    if (!calf_status_.ok()) return calf_status_; \
  } while (false)

// `lhs = *expr` when `expr` (an Expected) holds a value, else returns its Status. `lhs` may be a
// declaration: CALF_ASSIGN_OR_RETURN(auto file, open_file(path));
#define CALF_ASSIGN_OR_RETURN(lhs, expr) \
  CALF_INTERNAL_ASSIGN_OR_RETURN(CALF_INTERNAL_CONCAT(calf_expected_, __LINE__), lhs, expr)
#define CALF_INTERNAL_ASSIGN_OR_RETURN(tmp, lhs, expr) \
  auto tmp = (expr);                                   \
  if (!tmp.ok()) return std::move(tmp).status();       \
  lhs = std::move(tmp).value()
