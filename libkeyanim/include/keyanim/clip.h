// The runtime side: a .kanim file loaded, validated once, and sampled at any frame or time.
// Nothing here parses BVH, encodes or allocates while sampling.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/skeleton.h"
#include "keyanim/status.h"

namespace keyanim {

// Upper bounds a loader checks before it allocates anything a file declares.
struct DecodeLimits {
  uint32_t max_joints = 1u << 16;             // Defaults to 65536 nodes (joints + End Sites).
  uint32_t max_channels = 1u << 18;           // Defaults to 262144 channels.
  uint32_t max_frames = 1u << 24;             // Defaults to 16777216 frames (float frame positions stay exact).
  uint64_t max_keys = 1ull << 28;             // Defaults to 268435456 keys in all.
  uint64_t max_decompressed_bytes = 1ull << 30;  // Defaults to 1 GiB of decompressed sections.
};

// What a channel is, independent of how a loaded clip stores it.
struct ChannelInfo {
  Interpolation interp = Interpolation::cardinal;
  float tension = 0.0f;    // T in [-1, 1] (s = (1 - T) / 2); ignored by linear channels
  uint32_t key_count = 0;  // 0: all zeros; 1: constant
};

// One channel's keys, as the sampler sees them.
struct ChannelTrack {
  uint32_t first_key = 0;  // index into Clip's key arrays
  uint32_t key_count = 0;  // 0: all zeros; 1: constant
  Interpolation interp = Interpolation::cardinal;
  float s = 0.5f;          // (1 - tension) / 2
};

// Speeds up sequential sampling: remembers each channel's last segment. Correctness never
// depends on it; a cursor used with another clip is detected and reset. Its vector is
// allocated once, the first time the cursor is used with a clip; after that sampling through
// it allocates nothing.
struct SampleCursor {
  const void* clip = nullptr;
  std::vector<uint32_t> segment;  // per channel
  // Private to Clip: the identity of the clip the state below belongs to, and each channel's
  // current segment, prepared (its range of validity and Hermite operands) so that a frame
  // within the same segments costs only the polynomial.
  uint64_t clip_id = 0;
  std::vector<float> cache;
  std::vector<uint32_t> flags;
};

class Clip {
 public:
  // Validates `bytes` completely (see spec/FORMAT.md, "Decoder obligations"). On failure `out`
  // is left empty and `err` (if given) says which section and byte offset: the absolute offset
  // of the offending field, or, inside a zstd-compressed section, the offset of the section's
  // stored bytes (`detail` then gives the offset within the decompressed content).
  // A clip holds fewer than 2^32 keys whatever `limits` says.
  static Status load(std::span<const uint8_t> bytes, Clip& out, ErrorInfo* err = nullptr,
                     const DecodeLimits& limits = {});
  // Reads the whole file, then load(). A file larger than limits.max_decompressed_bytes is
  // refused with limit_exceeded before it is read.
  static Status load_file(const std::string& path, Clip& out, ErrorInfo* err = nullptr,
                          const DecodeLimits& limits = {});

  uint16_t version_major() const noexcept { return p_.version_major; }
  uint16_t version_minor() const noexcept { return p_.version_minor; }
  uint32_t frame_count() const noexcept { return p_.frame_count; }
  double frame_time() const noexcept { return p_.frame_time; }
  // (frame_count - 1) * frame_time, or 0 for an empty clip.
  double duration() const noexcept;
  uint32_t channel_count() const noexcept { return static_cast<uint32_t>(p_.tracks.size()); }
  TangentRule tangent_rule() const noexcept { return p_.rule; }
  const Skeleton& skeleton() const noexcept { return p_.skeleton; }
  const ChannelTrack& track(uint32_t c) const noexcept { return p_.tracks[c]; }
  // Channel c (< channel_count()): interpolation, tension and number of keys.
  ChannelInfo channel(uint32_t c) const noexcept;
  // Channel c's keys: frames (strictly increasing) and values, exactly as the sampler uses them.
  // Both spans must hold channel(c).key_count entries (output_too_small); c >= channel_count()
  // is invalid_argument.
  Status channel_keys(uint32_t c, std::span<uint32_t> frames, std::span<float> values) const noexcept;
  std::span<const uint32_t> key_frames(uint32_t c) const noexcept;
  std::span<const float> key_values(uint32_t c) const noexcept;
  uint64_t total_keys() const noexcept { return p_.key_frames.size(); }
  // Informative encoder notes stored in the file (settings, measured error), as key=value text.
  const std::string& encoder_notes() const noexcept { return p_.notes; }
  // Bytes held by this object (key arrays, tracks, skeleton, notes, the segment index), for
  // memory budgets. The segment index is never larger than half the key arrays.
  size_t memory_bytes() const noexcept;

  // Every channel at frame position f (fractional frames are in-betweens; clamped to the clip),
  // computed exactly as eval_channel (spec/FORMAT.md appendix A) with f rounded to float.
  // `out` must hold channel_count() values (output_too_small); a NaN position is
  // invalid_argument. Never allocates, except a cursor's first use with this clip.
  Status sample(double frame_position, std::span<float> out, SampleCursor* cursor = nullptr) const noexcept;
  // Same at a time in seconds: frame position = seconds / frame_time (0 if frame_time is 0).
  Status sample_time(double seconds, std::span<float> out, SampleCursor* cursor = nullptr) const noexcept;
  // Only the listed channels (e.g. one joint's), out[i] for channels[i]. A channel number
  // >= channel_count() is invalid_argument.
  Status sample_channels(double frame_position, std::span<const uint32_t> channels,
                         std::span<float> out) const noexcept;
  // One channel, no checks beyond c < channel_count().
  float sample_channel(uint32_t c, float frame_position) const noexcept;

  // Used by the loader and by the encoder (which verifies with the very arrays a decoder builds).
  struct Parts {
    uint16_t version_major = 0, version_minor = 0;
    uint32_t frame_count = 0;
    double frame_time = 0.0;
    TangentRule rule = TangentRule::step_adjusted;
    Skeleton skeleton;
    std::vector<ChannelTrack> tracks;
    std::vector<uint32_t> key_frames;
    std::vector<float> key_values;
    std::string notes;
  };
  // Takes the arrays as they are (they must be valid: the loader has checked them) and builds
  // the segment index.
  static Clip from_parts(Parts parts);

 private:
  void build_index();
  // The index row for position f, or null when there is no index.
  const uint32_t* index_row(float f) const noexcept;
  // Channels channels[0..count) (or 0..count when `channels` is null) at f into out.
  void sample_batch(float f, const uint32_t* channels, uint32_t count, float* out) const noexcept;
  // All channels through a prepared cursor (sequential playback).
  void sample_cursor(float f, float* out, SampleCursor& cursor) const noexcept;
  void refresh_cursor(uint32_t c, float f, SampleCursor& cursor) const noexcept;

  Parts p_;  // what the file holds; the members below are built from it
  // Segment index: for bucket b (frames [b << index_shift_, (b + 1) << index_shift_)) and
  // channel c, index_[b * channel_count + c] is the absolute key index of the segment holding
  // the bucket's first frame: a lower bound for any f in the bucket. Empty when not worth it.
  std::vector<uint32_t> index_;
  uint32_t index_shift_ = 0;
  uint32_t index_buckets_ = 0;
  // Distinguishes clips for cursors (an address can be reused by another clip); copies share it,
  // as they share the content.
  uint64_t id_ = 0;
};

}  // namespace keyanim
