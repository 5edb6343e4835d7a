// The C API's loading and freeing: keyanim_clip_load*, keyanim_clip_free. No C++ exception
// leaves these functions: the loader reports lack of memory as limit_exceeded, and so does this
// layer for its own allocations.
#include <new>
#include <string>

#include "c_api/handles.h"

namespace keyanim::c_api {
namespace {

DecodeLimits to_limits(const keyanim_decode_limits* l) {
  DecodeLimits out;
  if (l != nullptr) {
    out.max_joints = l->max_joints;
    out.max_channels = l->max_channels;
    out.max_frames = l->max_frames;
    out.max_keys = l->max_keys;
    out.max_decompressed_bytes = l->max_decompressed_bytes;
  }
  return out;
}

// Runs `load` (a Clip::load or load_file call) into a new handle stored at *out.
template <class Load>
keyanim_status load_into(const char* function, keyanim_clip** out, const keyanim_decode_limits* limits, Load load) {
  if (out == nullptr) return fail(Status::invalid_argument, function, "out is NULL");
  *out = nullptr;
  if (limits != nullptr && limits->reserved != 0)
    return fail(Status::invalid_argument, function, "limits->reserved is not 0");
  try {
    auto handle = std::make_unique<keyanim_clip>();
    ErrorInfo info;
    if (load(handle->clip, info, to_limits(limits)) != Status::ok) return fail_load(info);
    forget_freed(handle.get());  // the allocator may reuse the address of the last freed handle
    *out = handle.release();
    return KEYANIM_OK;
  } catch (const std::bad_alloc&) {
    return fail(Status::limit_exceeded, function, "out of memory");
  }
}

// Clip::load of `size` bytes (NULL with 0: an empty input) into a new handle, through `rigs`
// when given: keyanim_clip_load_limited and keyanim_clip_load_shared.
keyanim_status load_bytes(const char* function, const uint8_t* bytes, size_t size, const keyanim_decode_limits* limits,
                          RigCache* rigs, keyanim_clip** out) {
  if (bytes == nullptr && size != 0) {
    if (out != nullptr) *out = nullptr;
    return fail(Status::invalid_argument, function, "bytes is NULL and size is %zu", size);
  }
  static const uint8_t kNone = 0;  // a span of 0 bytes still needs an address
  const uint8_t* data = bytes != nullptr ? bytes : &kNone;
  return load_into(function, out, limits, [&](Clip& clip, ErrorInfo& info, const DecodeLimits& l) {
    return Clip::load({data, size}, clip, &info, l, rigs);
  });
}

}  // namespace
}  // namespace keyanim::c_api

using keyanim::Clip;
using keyanim::DecodeLimits;
using keyanim::ErrorInfo;
using keyanim::Status;
using namespace keyanim::c_api;

extern "C" {

void keyanim_decode_limits_default(keyanim_decode_limits* out) {
  if (out == nullptr) return (void)fail(Status::invalid_argument, "keyanim_decode_limits_default", "out is NULL");
  const DecodeLimits d;
  *out = keyanim_decode_limits{d.max_joints, d.max_channels, d.max_frames, 0, d.max_keys, d.max_decompressed_bytes};
}

keyanim_status keyanim_clip_load_limited(const uint8_t* bytes, size_t size, const keyanim_decode_limits* limits,
                                         keyanim_clip** out) {
  return load_bytes("keyanim_clip_load", bytes, size, limits, nullptr, out);
}

keyanim_status keyanim_clip_load(const uint8_t* bytes, size_t size, keyanim_clip** out) {
  return keyanim_clip_load_limited(bytes, size, nullptr, out);
}

keyanim_status keyanim_clip_load_shared(const uint8_t* bytes, size_t size, const keyanim_decode_limits* limits,
                                        keyanim_rig_cache* rigs, keyanim_clip** out) {
  const char* fn = "keyanim_clip_load_shared";
  if (rigs == nullptr || was_freed_rigs(rigs)) {
    if (out != nullptr) *out = nullptr;
    return fail(Status::invalid_argument, fn, rigs == nullptr ? "rigs is NULL" : "rigs was freed");
  }
  return load_bytes(fn, bytes, size, limits, &rigs->rigs, out);
}

keyanim_status keyanim_clip_load_file_limited(const char* path, const keyanim_decode_limits* limits,
                                              keyanim_clip** out) {
  const char* fn = "keyanim_clip_load_file";
  if (path == nullptr) {
    if (out != nullptr) *out = nullptr;
    return fail(Status::invalid_argument, fn, "path is NULL");
  }
  return load_into(fn, out, limits, [&](Clip& clip, ErrorInfo& info, const DecodeLimits& l) {
    return Clip::load_file(std::string(path), clip, &info, l);
  });
}

keyanim_status keyanim_clip_load_file(const char* path, keyanim_clip** out) {
  return keyanim_clip_load_file_limited(path, nullptr, out);
}

keyanim_status keyanim_clip_view(const uint8_t* bytes, size_t size, const keyanim_decode_limits* limits,
                                 keyanim_rig_cache* rigs, keyanim_clip** out) {
  const char* fn = "keyanim_clip_view";
  if ((bytes == nullptr && size != 0) || (rigs != nullptr && was_freed_rigs(rigs))) {
    if (out != nullptr) *out = nullptr;
    return fail(Status::invalid_argument, fn, bytes == nullptr ? "bytes is NULL and size is %zu" : "rigs was freed", size);
  }
  static const uint64_t kNone = 0;  // a span of 0 bytes still needs an (aligned) address
  const uint8_t* data = bytes != nullptr ? bytes : reinterpret_cast<const uint8_t*>(&kNone);
  return load_into(fn, out, limits, [&](Clip& clip, ErrorInfo& info, const DecodeLimits& l) {
    return Clip::view({data, size}, clip, &info, l, rigs != nullptr ? &rigs->rigs : nullptr);
  });
}

int32_t keyanim_clip_runtime_profile(const keyanim_clip* h) {
  const Clip* c = clip_of(h, "keyanim_clip_runtime_profile");
  return c != nullptr && c->runtime_profile() ? 1 : 0;
}

keyanim_status keyanim_clip_check_content(const keyanim_clip* h) {
  const Clip* c = clip_of(h, "keyanim_clip_check_content");
  if (c == nullptr) return KEYANIM_INVALID_ARGUMENT;
  ErrorInfo info;
  return c->check_content(&info) == Status::ok ? KEYANIM_OK : fail_load(info);
}

void keyanim_clip_free(keyanim_clip* clip) {
  if (clip == nullptr) return;
  if (was_freed_clip(clip)) return (void)fail(Status::invalid_argument, "keyanim_clip_free", "clip was already freed");
  note_freed_clip(clip);
  delete clip;
}

}  // extern "C"
