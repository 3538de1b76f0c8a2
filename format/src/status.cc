#include "calf/format/status.h"

#include <cstdio>

namespace calf {

ErrorKind error_kind(ErrorId id) {
  switch (id) {
#define CALF_ERROR_KIND_CASE(name, number, kind, summary) \
  case ErrorId::name:                                     \
    return ErrorKind::kind;
    CALF_ERROR_LIST(CALF_ERROR_KIND_CASE)
#undef CALF_ERROR_KIND_CASE
    case ErrorId::kOk:
      break;
  }
  return ErrorKind::kInternal;
}

const char* error_summary(ErrorId id) {
  switch (id) {
#define CALF_ERROR_SUMMARY_CASE(name, number, kind, summary) \
  case ErrorId::name:                                        \
    return summary;
    CALF_ERROR_LIST(CALF_ERROR_SUMMARY_CASE)
#undef CALF_ERROR_SUMMARY_CASE
    case ErrorId::kOk:
      break;
  }
  return "";
}

std::string error_code_string(ErrorId id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "CALF-E%03d", static_cast<int>(id));
  return buf;
}

std::string Status::to_string() const {
  if (ok()) return "ok";
  return error_code_string(id_) + " " + message_;
}

Status Status::with_context(std::string_view context) const& {
  Status copy = *this;
  return std::move(copy).with_context(context);
}

Status Status::with_context(std::string_view context) && {
  if (!ok() && !context.empty()) message_ = std::string(context) + ": " + message_;
  return std::move(*this);
}

}  // namespace calf
