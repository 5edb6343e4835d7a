// Status codes returned by every runtime entry point. Values are gapped and append-only: a
// number, once released, never changes meaning (tools and logs depend on them).
#pragma once
#include <cstdint>
#include <string>

namespace keyanim {

enum class Status : uint16_t {
  ok = 0,
  truncated = 10,            // the data ends before a structure it declares
  bad_signature = 12,        // not a .kanim file
  unsupported_version = 14,  // a major version this decoder does not know
  reserved_bits_set = 16,    // a reserved bit or reserved enum value is used
  corrupt = 20,              // a field breaks a rule of the spec
  checksum_mismatch = 22,    // the whole-file CRC-32 does not match
  trailing_bytes = 24,       // bytes after the checksum
  limit_exceeded = 30,       // a declared count is above the caller's DecodeLimits
  zstd_error = 40,           // zstd refused a compressed stream
  invalid_argument = 50,     // caller error (frame out of range, null pointer ...)
  output_too_small = 52,     // caller's output span is too short
  io_error = 60,             // the file could not be read
};

// Short, stable, lower-case name of a status ("checksum_mismatch").
const char* status_string(Status s) noexcept;

// Where and why a load failed: the section ("header", "KEYS" ...), the absolute byte offset in
// the file, and a sentence for humans.
struct ErrorInfo {
  Status status = Status::ok;
  uint64_t byte_offset = 0;
  std::string section;
  std::string detail;
};

}  // namespace keyanim
