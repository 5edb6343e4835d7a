// The C API's status names, versions and the thread's last error.
#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <cstring>

#include "c_api/handles.h"
#include "keyanim/version.h"

// The C header repeats what the C++ one says; they must agree.
static_assert(KEYANIM_C_VERSION_MAJOR == KEYANIM_VERSION_MAJOR && KEYANIM_C_VERSION_MINOR == KEYANIM_VERSION_MINOR &&
              KEYANIM_C_VERSION_PATCH == KEYANIM_VERSION_PATCH);
static_assert(KEYANIM_OK == int(keyanim::Status::ok) && KEYANIM_TRUNCATED == int(keyanim::Status::truncated) &&
              KEYANIM_BAD_SIGNATURE == int(keyanim::Status::bad_signature) &&
              KEYANIM_UNSUPPORTED_VERSION == int(keyanim::Status::unsupported_version) &&
              KEYANIM_RESERVED_BITS_SET == int(keyanim::Status::reserved_bits_set) &&
              KEYANIM_CORRUPT == int(keyanim::Status::corrupt) &&
              KEYANIM_CHECKSUM_MISMATCH == int(keyanim::Status::checksum_mismatch) &&
              KEYANIM_TRAILING_BYTES == int(keyanim::Status::trailing_bytes) &&
              KEYANIM_LIMIT_EXCEEDED == int(keyanim::Status::limit_exceeded) &&
              KEYANIM_ZSTD_ERROR == int(keyanim::Status::zstd_error) &&
              KEYANIM_INVALID_ARGUMENT == int(keyanim::Status::invalid_argument) &&
              KEYANIM_OUTPUT_TOO_SMALL == int(keyanim::Status::output_too_small) &&
              KEYANIM_IO_ERROR == int(keyanim::Status::io_error));
static_assert(sizeof(keyanim_transform) == sizeof(keyanim::Transform) &&
              alignof(keyanim_transform) == alignof(keyanim::Transform) &&
              offsetof(keyanim_transform, translation) == offsetof(keyanim::Transform, translation) &&
              offsetof(keyanim_transform, pad) == offsetof(keyanim::Transform, reserved));

namespace keyanim::c_api {
namespace {

// Plain data (no constructor), so that reaching it costs no thread-local guard; written only on
// failure. Longer sentences are cut at the buffer's end.
struct LastError {
  keyanim_status status;
  uint64_t offset;
  char section[32];
  char detail[512];
};
thread_local LastError t_last;

void copy_text(char* to, size_t size, const char* from) {
  std::snprintf(to, size, "%s", from);
}

std::atomic<const void*> g_freed_clip{nullptr}, g_freed_cursor{nullptr}, g_freed_rigs{nullptr};

}  // namespace

keyanim_status fail(Status status, const char* function, const char* what, ...) noexcept {
  LastError& e = t_last;
  e.status = static_cast<keyanim_status>(status);
  e.offset = 0;
  e.section[0] = '\0';
  const int n = std::snprintf(e.detail, sizeof e.detail, "%s: ", function);
  va_list args;
  va_start(args, what);
  if (n > 0 && size_t(n) < sizeof e.detail) std::vsnprintf(e.detail + n, sizeof e.detail - size_t(n), what, args);
  va_end(args);
  return e.status;
}

keyanim_status fail_load(const ErrorInfo& info) noexcept {
  LastError& e = t_last;
  e.status = static_cast<keyanim_status>(info.status);
  e.offset = info.byte_offset;
  copy_text(e.section, sizeof e.section, info.section.c_str());
  copy_text(e.detail, sizeof e.detail, info.detail.c_str());
  return e.status;
}

void forget_freed(const void* handle) noexcept {
  const void* h = handle;
  g_freed_clip.compare_exchange_strong(h, nullptr, std::memory_order_relaxed);
  h = handle;
  g_freed_cursor.compare_exchange_strong(h, nullptr, std::memory_order_relaxed);
  h = handle;
  g_freed_rigs.compare_exchange_strong(h, nullptr, std::memory_order_relaxed);
}
bool was_freed_clip(const void* handle) noexcept { return g_freed_clip.load(std::memory_order_relaxed) == handle; }
bool was_freed_cursor(const void* handle) noexcept { return g_freed_cursor.load(std::memory_order_relaxed) == handle; }
void note_freed_clip(const void* handle) noexcept { g_freed_clip.store(handle, std::memory_order_relaxed); }
void note_freed_cursor(const void* handle) noexcept { g_freed_cursor.store(handle, std::memory_order_relaxed); }
bool was_freed_rigs(const void* handle) noexcept { return g_freed_rigs.load(std::memory_order_relaxed) == handle; }
void note_freed_rigs(const void* handle) noexcept { g_freed_rigs.store(handle, std::memory_order_relaxed); }

}  // namespace keyanim::c_api

using keyanim::c_api::t_last;

extern "C" {

uint32_t keyanim_version(void) {
  return (uint32_t{KEYANIM_VERSION_MAJOR} << 16) | (uint32_t{KEYANIM_VERSION_MINOR} << 8) | KEYANIM_VERSION_PATCH;
}
const char* keyanim_version_string(void) { return KEYANIM_VERSION_STRING; }
uint32_t keyanim_format_version(void) {
  return (uint32_t{keyanim::kQuatFormatVersionMajor} << 16) | keyanim::kQuatFormatVersionMinor;
}
uint32_t keyanim_format_oldest_version(void) { return uint32_t{keyanim::kOldestFormatVersionMajor} << 16; }

const char* keyanim_status_name(keyanim_status status) {
  // status_string names every Status; numbers outside uint16_t, or unused ones, are unknown.
  if (status < 0 || status > UINT16_MAX) return "unknown_status";
  return keyanim::status_string(static_cast<keyanim::Status>(status));
}

keyanim_status keyanim_last_error_status(void) { return t_last.status; }
const char* keyanim_last_error_section(void) { return t_last.section; }
uint64_t keyanim_last_error_offset(void) { return t_last.offset; }
const char* keyanim_last_error_detail(void) { return t_last.detail; }
void keyanim_last_error_clear(void) {
  t_last.status = KEYANIM_OK;
  t_last.offset = 0;
  t_last.section[0] = t_last.detail[0] = '\0';
}

}  // extern "C"
