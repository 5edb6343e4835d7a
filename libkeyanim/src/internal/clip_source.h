// A clip's keys as integers, the way a file stores them: what the loader decodes from any
// format version and what the encoder produces, before the runtime image is built from it
// (runtime/image.h). Internal: nothing here is validated by its type; whoever fills it (the
// loader, or offline::to_clip for an encoder's valid output) has checked every rule.
#pragma once
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/rotation.h"
#include "keyanim/skeleton.h"

namespace keyanim::internal {

struct SourceChannel {
  Interpolation interp = Interpolation::cardinal;
  float tension = 0.0f;
  double step = 1.0;        // key value = dequantize(q, step)
  uint64_t first_key = 0;   // into ClipSource::frames / q
  uint32_t key_count = 0;   // 0: zero everywhere; 1: constant
};

// An allocator whose resize() leaves new elements of a trivial type as they are instead of
// zeroing them: the loader sizes the key arrays, then writes every element (the channels'
// key ranges tile them: sections.cpp checks it) or fails and drops them. Zeroing first was a
// tenth of an archive file's load (callgrind, CMU 01_01).
template <class T>
struct NoZeroAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = NoZeroAllocator<U>;
  };
  NoZeroAllocator() = default;
  template <class U>
  NoZeroAllocator(const NoZeroAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

struct ClipSource {
  uint16_t version_major = 0, version_minor = 0;
  uint32_t frame_count = 0;  // <= 2^24 (kMaxFrames): every frame position is exact in binary32
  double frame_time = 0.0;
  TangentRule rule = TangentRule::step_adjusted;
  Skeleton skeleton;         // channel columns assigned
  std::vector<SourceChannel> channels;
  // Every channel's key frames, channel after channel, increasing, and the matching quantized
  // values, |q| <= 2^53, finite once dequantized.
  std::vector<uint32_t, NoZeroAllocator<uint32_t>> frames;
  std::vector<int64_t, NoZeroAllocator<int64_t>> q;
  // Nodes stored as quaternions (version 5, QUAT), increasing: each one's rotation channels
  // c, c + 1, c + 2 hold x, y, z with equal interpolation, tension and key frames.
  std::vector<QuatNode> quat_nodes;
  std::string notes;
};

// Frame positions stay exact in binary32 below 2^24; no clip may be longer (spec section 8).
inline constexpr uint32_t kMaxFrames = 1u << 24;

}  // namespace keyanim::internal
