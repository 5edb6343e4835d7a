// The offline side's one way of failing: every function of keyanim::offline returns its product
// and throws offline::Error when it cannot make it (the runtime, keyanim/clip.h, returns Status
// with ErrorInfo instead and never throws). The error says what kind of failure it is, so that a
// caller can react (the CLI picks its exit code by kind), and where it is: a place in BVH text
// (file, line, column) or in a .kanim file (section, byte offset).
#pragma once
#include <cstdint>
#include <exception>
#include <string>

#include "keyanim/status.h"

namespace keyanim::offline {

enum class ErrorKind : uint8_t {
  invalid_argument,  // the caller's settings or arguments make no sense (a bad tolerance, a frame
                     // range beyond the clip, two motions that do not share a skeleton)
  malformed,         // the input is damaged or breaks a rule (BVH syntax, a .kanim rule, a value
                     // the codec cannot store)
  unsupported,       // valid input using a version or feature this build does not know
  limit,             // a limit was reached (a declared count, a size, the tolerance's precision)
  io,                // a file could not be read or written (system_error holds errno)
};

// "invalid_argument", "malformed", ...
const char* error_kind_string(ErrorKind kind) noexcept;

class Error : public std::exception {
 public:
  // A failure that is not about a place in a file.
  Error(ErrorKind kind, std::string message, std::string file = {});
  // A place in BVH text: 1-based line and byte column (line 0: not about a place in the text).
  static Error bvh(std::string file, uint32_t line, uint32_t column, std::string message,
                   ErrorKind kind = ErrorKind::malformed);
  // A .kanim the loader refused (ErrorInfo from Clip::load): its section, offset and status.
  static Error kanim(std::string file, const ErrorInfo& info);
  // A system call failed on `file`: `what` ("cannot open file") and errno's text.
  static Error io(std::string file, const std::string& what, int system_error);

  ErrorKind kind() const noexcept { return kind_; }
  const std::string& file() const noexcept { return file_; }
  uint32_t line() const noexcept { return line_; }      // 0: not a place in text
  uint32_t column() const noexcept { return column_; }  // 0 with line 0
  const std::string& section() const noexcept { return section_; }  // "": not a place in a .kanim
  uint64_t byte_offset() const noexcept { return byte_offset_; }    // meaningful with a section
  Status status() const noexcept { return status_; }    // the loader's status for a .kanim, else ok
  int system_error() const noexcept { return system_error_; }  // errno for io, else 0
  const std::string& message() const noexcept { return message_; }  // without the place
  // The whole text: "file:line:column: message" (BVH), "file: section S, offset N (0xN):
  // status: message" (.kanim), "file: message", or the message alone without a file.
  const char* what() const noexcept override { return text_.c_str(); }

 private:
  Error() = default;
  void compose();
  ErrorKind kind_ = ErrorKind::invalid_argument;
  std::string file_;
  uint32_t line_ = 0, column_ = 0;
  std::string section_;
  uint64_t byte_offset_ = 0;
  Status status_ = Status::ok;
  int system_error_ = 0;
  std::string message_, text_;
};

}  // namespace keyanim::offline
