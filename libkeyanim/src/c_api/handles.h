// The C API's handles and its one error convention: what a keyanim_clip and a keyanim_cursor
// hold, the thread's last error, and the checks every entry point makes on its handles.
#pragma once
#include <cstddef>
#include <cstdint>

#include "keyanim.h"
#include "keyanim/clip.h"

// Opaque to C. A clip handle is a Clip (copies share its image); a cursor keeps a Clip of its
// own, so that it may outlive the handle it was made from.
struct keyanim_clip {
  keyanim::Clip clip;
};
struct keyanim_cursor {
  keyanim::Clip clip;
  keyanim::Cursor cursor;
};
struct keyanim_rig_cache {
  keyanim::RigCache rigs;
};
// keyanim_skeleton is never defined: a pointer to one is a keyanim::Skeleton inside a clip.

namespace keyanim::c_api {

inline const keyanim_skeleton* to_handle(const Skeleton& s) { return reinterpret_cast<const keyanim_skeleton*>(&s); }
inline const Skeleton& of_handle(const keyanim_skeleton* s) { return *reinterpret_cast<const Skeleton*>(s); }

// Records a failure of `function` as the calling thread's last error; returns its status so
// that an entry point can `return fail(...)`. `what` is a printf format.
keyanim_status fail(Status status, const char* function, const char* what, ...) noexcept
    __attribute__((format(printf, 3, 4)));
// Records a load's failure: the loader's section, offset and sentence.
keyanim_status fail_load(const ErrorInfo& info) noexcept;

// The most recently freed clip, cursor and rig cache (any thread), so that freeing one twice, or using it
// right after, is refused rather than undefined. Cleared when the allocator hands the same
// address to a new handle.
void forget_freed(const void* handle) noexcept;
bool was_freed_clip(const void* handle) noexcept;
bool was_freed_cursor(const void* handle) noexcept;
void note_freed_clip(const void* handle) noexcept;
void note_freed_cursor(const void* handle) noexcept;
bool was_freed_rigs(const void* handle) noexcept;
void note_freed_rigs(const void* handle) noexcept;

// The handle's Clip, or null (with the last error recorded) for NULL or the last freed clip.
inline const Clip* clip_of(const keyanim_clip* h, const char* function) noexcept {
  if (h == nullptr) return fail(Status::invalid_argument, function, "clip is NULL"), nullptr;
  if (was_freed_clip(h)) return fail(Status::invalid_argument, function, "clip was freed"), nullptr;
  return &h->clip;
}
inline keyanim_cursor* cursor_of(keyanim_cursor* h, const char* function) noexcept {
  if (h == nullptr) return fail(Status::invalid_argument, function, "cursor is NULL"), nullptr;
  if (was_freed_cursor(h)) return fail(Status::invalid_argument, function, "cursor was freed"), nullptr;
  return h;
}

}  // namespace keyanim::c_api
