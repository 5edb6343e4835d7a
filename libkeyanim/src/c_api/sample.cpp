// The C API's sampling, with and without a cursor: each entry point checks its handle and
// forwards to Clip's sample calls, which check the position and the output's size. The failure
// path alone formats a sentence; the success path adds a null test and a relaxed atomic load.
#include <cmath>
#include <new>

#include "c_api/handles.h"

using keyanim::Clip;
using keyanim::Cursor;
using keyanim::Status;
using keyanim::Transform;
using namespace keyanim::c_api;

namespace {

// What a sample call is asked for: channels (floats) or transforms of one kind.
enum class Kind { channels, local, model };

// Records why `s` (not ok) came back: the position, or the output's size.
keyanim_status explain(Status s, const char* fn, const Clip& clip, double x, bool is_time, const void* out,
                       size_t count, Kind kind) {
  if (std::isnan(x)) return fail(s, fn, "the %s is NaN", is_time ? "time" : "frame position");
  const size_t need = kind == Kind::channels ? clip.channel_count() : clip.skeleton().joints.size();
  const char* what = kind == Kind::channels ? "floats" : "transforms";
  if (s == Status::output_too_small) return fail(s, fn, "out holds %zu %s, the clip needs %zu", count, what, need);
  if (out == nullptr) return fail(s, fn, "out is NULL");
  return fail(s, fn, "%s", keyanim::status_string(s));
}

// One sample call of `kind` at x (a frame position, or seconds), through `cursor` if given.
keyanim_status sample(const char* fn, const Clip& clip, Cursor* cursor, double x, bool is_time, void* out,
                      size_t count, Kind kind) noexcept {
  // A NULL buffer is refused even when the clip needs 0 values: it is always a caller's slip.
  if (out == nullptr) return fail(Status::invalid_argument, fn, "out is NULL");
  Status s;
  if (kind == Kind::channels) {
    const std::span<float> o(static_cast<float*>(out), count);
    s = is_time ? clip.sample_time(x, o, cursor) : clip.sample(x, o, cursor);
  } else {
    // Time to position as Clip::sample_time does it (the pose calls take positions only).
    const double ft = clip.frame_time();
    const double f = is_time ? (std::isnan(x) ? x : ft > 0.0 ? x / ft : 0.0) : x;
    // keyanim_transform and keyanim::Transform have one layout (static_asserts in error.cpp).
    const std::span<Transform> o(static_cast<Transform*>(out), count);
    s = kind == Kind::local ? clip.sample_local(f, o, cursor) : clip.sample_model(f, o, cursor);
  }
  return s == Status::ok ? KEYANIM_OK : explain(s, fn, clip, x, is_time, out, count, kind);
}

keyanim_status clip_sample(const char* fn, const keyanim_clip* h, double x, bool is_time, void* out, size_t count,
                           Kind kind) noexcept {
  const Clip* clip = clip_of(h, fn);
  return clip ? sample(fn, *clip, nullptr, x, is_time, out, count, kind) : KEYANIM_INVALID_ARGUMENT;
}

keyanim_status cursor_sample(const char* fn, keyanim_cursor* h, double x, bool is_time, void* out, size_t count,
                             Kind kind) noexcept {
  keyanim_cursor* c = cursor_of(h, fn);
  return c ? sample(fn, c->clip, &c->cursor, x, is_time, out, count, kind) : KEYANIM_INVALID_ARGUMENT;
}

}  // namespace

extern "C" {

keyanim_status keyanim_clip_sample(const keyanim_clip* clip, double frame_position, float* out, size_t count) {
  return clip_sample("keyanim_clip_sample", clip, frame_position, false, out, count, Kind::channels);
}
keyanim_status keyanim_clip_sample_local(const keyanim_clip* clip, double frame_position, keyanim_transform* out,
                                         size_t count) {
  return clip_sample("keyanim_clip_sample_local", clip, frame_position, false, out, count, Kind::local);
}
keyanim_status keyanim_clip_sample_model(const keyanim_clip* clip, double frame_position, keyanim_transform* out,
                                         size_t count) {
  return clip_sample("keyanim_clip_sample_model", clip, frame_position, false, out, count, Kind::model);
}
keyanim_status keyanim_clip_sample_time(const keyanim_clip* clip, double seconds, float* out, size_t count) {
  return clip_sample("keyanim_clip_sample_time", clip, seconds, true, out, count, Kind::channels);
}
keyanim_status keyanim_clip_sample_local_time(const keyanim_clip* clip, double seconds, keyanim_transform* out,
                                              size_t count) {
  return clip_sample("keyanim_clip_sample_local_time", clip, seconds, true, out, count, Kind::local);
}
keyanim_status keyanim_clip_sample_model_time(const keyanim_clip* clip, double seconds, keyanim_transform* out,
                                              size_t count) {
  return clip_sample("keyanim_clip_sample_model_time", clip, seconds, true, out, count, Kind::model);
}

keyanim_status keyanim_cursor_create(const keyanim_clip* h, keyanim_cursor** out) {
  const char* fn = "keyanim_cursor_create";
  if (out == nullptr) return fail(Status::invalid_argument, fn, "out is NULL");
  *out = nullptr;
  const Clip* clip = clip_of(h, fn);
  if (clip == nullptr) return KEYANIM_INVALID_ARGUMENT;
  keyanim_cursor* c = new (std::nothrow) keyanim_cursor{*clip, Cursor{}};
  if (c == nullptr) return fail(Status::limit_exceeded, fn, "out of memory");
  if (c->cursor.prepare(c->clip) != Status::ok) {
    delete c;
    return fail(Status::limit_exceeded, fn, "out of memory");
  }
  forget_freed(c);  // the allocator may reuse the address of the last freed handle
  *out = c;
  return KEYANIM_OK;
}

void keyanim_cursor_free(keyanim_cursor* cursor) {
  if (cursor == nullptr) return;
  if (was_freed_cursor(cursor))
    return (void)fail(Status::invalid_argument, "keyanim_cursor_free", "cursor was already freed");
  note_freed_cursor(cursor);
  delete cursor;
}

keyanim_status keyanim_cursor_sample(keyanim_cursor* cursor, double frame_position, float* out, size_t count) {
  return cursor_sample("keyanim_cursor_sample", cursor, frame_position, false, out, count, Kind::channels);
}
keyanim_status keyanim_cursor_sample_local(keyanim_cursor* cursor, double frame_position, keyanim_transform* out,
                                           size_t count) {
  return cursor_sample("keyanim_cursor_sample_local", cursor, frame_position, false, out, count, Kind::local);
}
keyanim_status keyanim_cursor_sample_model(keyanim_cursor* cursor, double frame_position, keyanim_transform* out,
                                           size_t count) {
  return cursor_sample("keyanim_cursor_sample_model", cursor, frame_position, false, out, count, Kind::model);
}
keyanim_status keyanim_cursor_sample_time(keyanim_cursor* cursor, double seconds, float* out, size_t count) {
  return cursor_sample("keyanim_cursor_sample_time", cursor, seconds, true, out, count, Kind::channels);
}
keyanim_status keyanim_cursor_sample_local_time(keyanim_cursor* cursor, double seconds, keyanim_transform* out,
                                                size_t count) {
  return cursor_sample("keyanim_cursor_sample_local_time", cursor, seconds, true, out, count, Kind::local);
}
keyanim_status keyanim_cursor_sample_model_time(keyanim_cursor* cursor, double seconds, keyanim_transform* out,
                                                size_t count) {
  return cursor_sample("keyanim_cursor_sample_model_time", cursor, seconds, true, out, count, Kind::model);
}

}  // extern "C"
