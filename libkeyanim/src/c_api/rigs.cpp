// The C API's rig caches: clips of one skeleton sharing it (keyanim::RigCache), and a clip's
// rig hash.
#include <new>

#include "c_api/handles.h"

using keyanim::Status;
using namespace keyanim::c_api;

extern "C" {

keyanim_status keyanim_rig_cache_create(keyanim_rig_cache** out) {
  const char* fn = "keyanim_rig_cache_create";
  if (out == nullptr) return fail(Status::invalid_argument, fn, "out is NULL");
  *out = nullptr;
  try {
    *out = new keyanim_rig_cache;
  } catch (const std::bad_alloc&) {
    return fail(Status::limit_exceeded, fn, "out of memory");
  }
  forget_freed(*out);  // the allocator may reuse the address of the last freed handle
  return KEYANIM_OK;
}

void keyanim_rig_cache_free(keyanim_rig_cache* rigs) {
  if (rigs == nullptr) return;
  if (was_freed_rigs(rigs)) return (void)fail(Status::invalid_argument, "keyanim_rig_cache_free", "rigs was already freed");
  note_freed_rigs(rigs);
  delete rigs;
}

uint64_t keyanim_rig_cache_rig_count(const keyanim_rig_cache* rigs) {
  const char* fn = "keyanim_rig_cache_rig_count";
  if (rigs == nullptr) return fail(Status::invalid_argument, fn, "rigs is NULL"), 0;
  if (was_freed_rigs(rigs)) return fail(Status::invalid_argument, fn, "rigs was freed"), 0;
  return rigs->rigs.rig_count();
}

uint64_t keyanim_clip_rig_hash(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_rig_hash");
  return c ? c->rig_hash() : 0;
}

int32_t keyanim_clip_shares_rig(const keyanim_clip* a, const keyanim_clip* b) {
  const keyanim::Clip* x = clip_of(a, "keyanim_clip_shares_rig");
  const keyanim::Clip* y = x ? clip_of(b, "keyanim_clip_shares_rig") : nullptr;
  return x && y && x->shares_rig(*y) ? 1 : 0;
}

}  // extern "C"
