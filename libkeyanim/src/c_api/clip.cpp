// The C API's questions to a clip: counts, times, memory, notes. Each answers 0 (or NULL) for a
// NULL handle, with the last error recorded.
#include "c_api/handles.h"

using namespace keyanim::c_api;

extern "C" {

uint32_t keyanim_clip_format_version(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_format_version");
  return c ? (uint32_t{c->version_major()} << 16) | c->version_minor() : 0;
}
uint32_t keyanim_clip_frame_count(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_frame_count");
  return c ? c->frame_count() : 0;
}
double keyanim_clip_frame_time(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_frame_time");
  return c ? c->frame_time() : 0.0;
}
double keyanim_clip_duration(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_duration");
  return c ? c->duration() : 0.0;
}
uint32_t keyanim_clip_channel_count(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_channel_count");
  return c ? c->channel_count() : 0;
}
uint64_t keyanim_clip_total_keys(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_total_keys");
  return c ? c->total_keys() : 0;
}
uint64_t keyanim_clip_memory_bytes(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_memory_bytes");
  return c ? c->memory_bytes() : 0;
}
uint64_t keyanim_clip_skeleton_bytes(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_skeleton_bytes");
  return c ? c->skeleton_bytes() : 0;
}
uint64_t keyanim_clip_animation_bytes(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_animation_bytes");
  return c ? c->animation_bytes() : 0;
}
const char* keyanim_clip_encoder_notes(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_encoder_notes");
  return c ? c->encoder_notes().c_str() : nullptr;
}

const keyanim_skeleton* keyanim_clip_skeleton(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_skeleton");
  return c ? to_handle(c->skeleton()) : nullptr;
}
uint32_t keyanim_clip_node_count(const keyanim_clip* h) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_node_count");
  return c ? keyanim_skeleton_node_count(to_handle(c->skeleton())) : 0;
}
const char* keyanim_clip_node_name(const keyanim_clip* h, uint32_t node) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_node_name");
  return c ? keyanim_skeleton_node_name(to_handle(c->skeleton()), node) : nullptr;
}
int32_t keyanim_clip_node_parent(const keyanim_clip* h, uint32_t node) {
  const keyanim::Clip* c = clip_of(h, "keyanim_clip_node_parent");
  return c ? keyanim_skeleton_node_parent(to_handle(c->skeleton()), node) : KEYANIM_NO_NODE;
}

}  // extern "C"
