// Cold samples: a loaded clip's memory flushed from every cache level (clflush) before a pose
// is timed. It reads the runtime's internal layout (runtime/clip_access.h, image.h), which no
// public header shows: the one place the benchmarks reach past the public API.
#pragma once
#include <cstddef>
#if defined(__x86_64__)
#include <emmintrin.h>
#endif

#include "keyanim/clip.h"
#include "runtime/clip_access.h"

namespace bench {

inline void flush(const void* p, size_t n) {
#if defined(__x86_64__)
  const auto* c = static_cast<const char*>(p);
  for (size_t i = 0; i < n; i += 64) _mm_clflush(c + i);
  if (n) _mm_clflush(c + n - 1);
#else
  (void)p, (void)n;
#endif
}

inline void fence() {
#if defined(__x86_64__)
  _mm_mfence();
#endif
}

template <class V>
void flush_vec(const V& v) {
  flush(v.data(), v.size() * sizeof(v[0]));
}

// Every array a loaded clip's image owns, its notes and its node names and channel lists.
inline void flush_image(const keyanim::Clip& clip) {
  const keyanim::internal::Image& img = keyanim::ClipAccess::image(clip);
  flush(&img, sizeof img);
  flush_vec(img.payload), flush_vec(img.record_offset), flush_vec(img.curves);
  flush_vec(img.curve_of), flush_vec(img.fixed_value), flush_vec(img.fixed_channels);
  flush(img.rig.get(), sizeof *img.rig), flush_vec(img.rig->node_offset), flush_vec(img.curve_s);
  flush_vec(img.first_frame);
  flush_vec(img.last_frame), flush_vec(img.first_value), flush_vec(img.last_value);
  flush_vec(img.curve_linear), flush_vec(img.curve_channel), flush_vec(img.list_frames);
  flush_vec(img.lists), flush_vec(img.list_values), flush_vec(img.interp), flush_vec(img.tension);
  flush_vec(img.key_count), flush_vec(img.fixed_frame), flush_vec(img.euler->groups);
  flush_vec(img.euler->node), flush_vec(img.euler->column), flush_vec(img.rig->moves);
  flush_vec(img.quat_node), flush_vec(img.quat_column), flush_vec(img.quat_reference);
  flush_vec(img.notes), flush_vec(img.rig->skeleton.joints);
  for (const auto& j : img.rig->skeleton.joints) flush_vec(j.channels), flush_vec(j.name);
}

}  // namespace bench
