#include "keyanim/offline/error.h"

#include <cinttypes>
#include <cstdio>
#include <system_error>
#include <utility>

namespace keyanim::offline {

const char* error_kind_string(ErrorKind kind) noexcept {
  switch (kind) {
    case ErrorKind::invalid_argument: return "invalid_argument";
    case ErrorKind::malformed: return "malformed";
    case ErrorKind::unsupported: return "unsupported";
    case ErrorKind::limit: return "limit";
    case ErrorKind::io: return "io";
  }
  return "unknown";
}

Error::Error(ErrorKind kind, std::string message, std::string file)
    : kind_(kind), file_(std::move(file)), message_(std::move(message)) {
  compose();
}

Error Error::bvh(std::string file, uint32_t line, uint32_t column, std::string message, ErrorKind kind) {
  Error e;
  e.kind_ = kind;
  e.file_ = std::move(file);
  e.line_ = line;
  e.column_ = line > 0 ? column : 0;
  e.message_ = std::move(message);
  e.compose();
  return e;
}

Error Error::kanim(std::string file, const ErrorInfo& info) {
  Error e;
  switch (info.status) {
    case Status::unsupported_version: e.kind_ = ErrorKind::unsupported; break;
    case Status::limit_exceeded: e.kind_ = ErrorKind::limit; break;
    case Status::io_error: e.kind_ = ErrorKind::io; break;
    case Status::invalid_argument:
    case Status::output_too_small: e.kind_ = ErrorKind::invalid_argument; break;
    default: e.kind_ = ErrorKind::malformed; break;
  }
  e.file_ = std::move(file);
  e.section_ = info.section.empty() ? "?" : info.section;
  e.byte_offset_ = info.byte_offset;
  e.status_ = info.status;
  e.message_ = info.detail;
  e.compose();
  return e;
}

Error Error::io(std::string file, const std::string& what, int system_error) {
  Error e;
  e.kind_ = ErrorKind::io;
  e.file_ = std::move(file);
  e.system_error_ = system_error;
  e.message_ = what + ": " + std::generic_category().message(system_error);
  e.compose();
  return e;
}

void Error::compose() {
  text_ = file_;
  if (line_ > 0) {
    text_ += ":" + std::to_string(line_) + ":" + std::to_string(column_);
  } else if (!section_.empty()) {
    char where[80];
    std::snprintf(where, sizeof where, "offset %" PRIu64 " (0x%" PRIX64 ")", byte_offset_, byte_offset_);
    text_ += (text_.empty() ? "section " : ": section ") + section_ + ", " + where + ": " + status_string(status_);
  }
  text_ += (text_.empty() ? "" : ": ") + message_;
}

}  // namespace keyanim::offline
