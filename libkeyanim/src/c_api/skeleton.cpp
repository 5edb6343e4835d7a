// The C API's view of a clip's skeleton: nodes, parents, End Sites, OFFSETs, channel layout.
// A keyanim_skeleton pointer is the clip's own keyanim::Skeleton, borrowed (handles.h).
#include "c_api/handles.h"

using keyanim::Joint;
using keyanim::Status;
using namespace keyanim::c_api;

namespace {

// Node `node` of the skeleton, or null with the last error recorded.
const Joint* node_of(const keyanim_skeleton* s, uint32_t node, const char* function) {
  if (s == nullptr) return fail(Status::invalid_argument, function, "skeleton is NULL"), nullptr;
  const auto& joints = of_handle(s).joints;
  if (node >= joints.size())
    return fail(Status::invalid_argument, function, "node %u is out of range (%zu nodes)", node, joints.size()), nullptr;
  return &joints[node];
}

}  // namespace

extern "C" {

uint32_t keyanim_skeleton_node_count(const keyanim_skeleton* s) {
  if (s == nullptr) return fail(Status::invalid_argument, "keyanim_skeleton_node_count", "skeleton is NULL"), 0;
  return static_cast<uint32_t>(of_handle(s).joints.size());  // DecodeLimits keep it far below 2^32
}
uint32_t keyanim_skeleton_channel_count(const keyanim_skeleton* s) {
  if (s == nullptr) return fail(Status::invalid_argument, "keyanim_skeleton_channel_count", "skeleton is NULL"), 0;
  return of_handle(s).channel_count();
}
const char* keyanim_skeleton_node_name(const keyanim_skeleton* s, uint32_t node) {
  const Joint* j = node_of(s, node, "keyanim_skeleton_node_name");
  return j ? j->name.c_str() : nullptr;
}
uint32_t keyanim_skeleton_node_name_length(const keyanim_skeleton* s, uint32_t node) {
  const Joint* j = node_of(s, node, "keyanim_skeleton_node_name_length");
  return j ? static_cast<uint32_t>(j->name.size()) : 0;  // SKEL's Name_Length is a u32
}
int32_t keyanim_skeleton_node_parent(const keyanim_skeleton* s, uint32_t node) {
  const Joint* j = node_of(s, node, "keyanim_skeleton_node_parent");
  return j ? j->parent : KEYANIM_NO_NODE;
}
int32_t keyanim_skeleton_node_is_end_site(const keyanim_skeleton* s, uint32_t node) {
  const Joint* j = node_of(s, node, "keyanim_skeleton_node_is_end_site");
  return j && j->end_site ? 1 : 0;
}
keyanim_status keyanim_skeleton_node_offset(const keyanim_skeleton* s, uint32_t node, double out[3]) {
  const char* fn = "keyanim_skeleton_node_offset";
  const Joint* j = node_of(s, node, fn);
  if (j == nullptr) return KEYANIM_INVALID_ARGUMENT;
  if (out == nullptr) return fail(Status::invalid_argument, fn, "out is NULL");
  for (int k = 0; k < 3; ++k) out[k] = j->offset[size_t(k)];
  return KEYANIM_OK;
}
uint32_t keyanim_skeleton_node_channel_count(const keyanim_skeleton* s, uint32_t node) {
  const Joint* j = node_of(s, node, "keyanim_skeleton_node_channel_count");
  return j ? static_cast<uint32_t>(j->channels.size()) : 0;
}
uint32_t keyanim_skeleton_node_first_channel(const keyanim_skeleton* s, uint32_t node) {
  const Joint* j = node_of(s, node, "keyanim_skeleton_node_first_channel");
  return j ? j->first_channel : 0;
}
keyanim_status keyanim_skeleton_node_channel_types(const keyanim_skeleton* s, uint32_t node, uint8_t* out,
                                                   size_t count) {
  const char* fn = "keyanim_skeleton_node_channel_types";
  const Joint* j = node_of(s, node, fn);
  if (j == nullptr) return KEYANIM_INVALID_ARGUMENT;
  if (out == nullptr && !j->channels.empty()) return fail(Status::invalid_argument, fn, "out is NULL");
  if (count < j->channels.size())
    return fail(Status::output_too_small, fn, "out holds %zu, node %u has %zu channels", count, node, j->channels.size());
  for (size_t k = 0; k < j->channels.size(); ++k) out[k] = static_cast<uint8_t>(j->channels[k]);
  return KEYANIM_OK;
}
keyanim_status keyanim_skeleton_node_rotation_order(const keyanim_skeleton* s, uint32_t node, char* out,
                                                    size_t size) {
  const char* fn = "keyanim_skeleton_node_rotation_order";
  const Joint* j = node_of(s, node, fn);
  if (j == nullptr) return KEYANIM_INVALID_ARGUMENT;
  if (out == nullptr) return fail(Status::invalid_argument, fn, "out is NULL");
  size_t n = 0;
  for (auto t : j->channels) n += keyanim::is_rotation(t) ? 1 : 0;
  // At least 4 always, so that a caller's buffer that fits one node's order fits every node's
  // of the usual kind; a node with more rotation channels needs n + 1.
  if (size < 4 || size < n + 1)
    return fail(Status::output_too_small, fn, "out holds %zu chars, node %u needs %zu", size, node, n < 3 ? 4 : n + 1);
  size_t k = 0;
  for (auto t : j->channels)
    if (keyanim::is_rotation(t)) out[k++] = static_cast<char>('X' + keyanim::channel_axis(t));
  out[k] = '\0';
  return KEYANIM_OK;
}

}  // extern "C"
