#include "keyanim/status.h"

namespace keyanim {

const char* status_string(Status s) noexcept {
  switch (s) {
    case Status::ok: return "ok";
    case Status::truncated: return "truncated";
    case Status::bad_signature: return "bad_signature";
    case Status::unsupported_version: return "unsupported_version";
    case Status::reserved_bits_set: return "reserved_bits_set";
    case Status::corrupt: return "corrupt";
    case Status::checksum_mismatch: return "checksum_mismatch";
    case Status::trailing_bytes: return "trailing_bytes";
    case Status::limit_exceeded: return "limit_exceeded";
    case Status::zstd_error: return "zstd_error";
    case Status::invalid_argument: return "invalid_argument";
    case Status::output_too_small: return "output_too_small";
    case Status::io_error: return "io_error";
  }
  return "unknown_status";
}

}  // namespace keyanim
