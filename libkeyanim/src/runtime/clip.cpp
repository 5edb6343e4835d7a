// Sampling a loaded clip. The value of a channel is exactly eval_channel's (cardinal.h); what
// this file adds is a faster way to find the segment: a per-bucket index built at load, and a
// per-channel cursor for playback.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <utility>

#include "keyanim/clip.h"

namespace keyanim {

Clip Clip::from_parts(Parts parts) {
  Clip c;
  c.version_major_ = parts.version_major;
  c.version_minor_ = parts.version_minor;
  c.frame_count_ = parts.frame_count;
  c.frame_time_ = parts.frame_time;
  c.rule_ = parts.rule;
  c.skeleton_ = std::move(parts.skeleton);
  c.tracks_ = std::move(parts.tracks);
  c.key_frames_ = std::move(parts.key_frames);
  c.key_values_ = std::move(parts.key_values);
  c.notes_ = std::move(parts.notes);
  c.build_index();
  return c;
}

// Bucket length: the smallest power of two whose table (buckets x channels x 4 bytes) is no
// larger than the key arrays (keys x 8 bytes). With keys every g frames on average that is
// about g/2 frames, so the forward scan from the bucket's entry takes one or two steps.
void Clip::build_index() {
  index_.clear();
  index_shift_ = 0;
  index_buckets_ = 0;
  const uint64_t channels = tracks_.size();
  const uint64_t keys = key_frames_.size();
  if (channels == 0 || frame_count_ < 2 || keys == 0) return;
  // Interior positions f satisfy K_0 < f < K_{n-1} <= F - 1, so buckets of frames 0 .. F-2.
  const uint64_t last = frame_count_ - 2;
  uint32_t shift = 0;
  for (; shift < 32; ++shift) {
    const uint64_t buckets = (last >> shift) + 1;
    if (buckets * channels <= 2 * keys) break;
  }
  const uint64_t buckets = (last >> std::min(shift, 31u)) + 1;
  if (shift >= 32 || buckets < 2) return;  // one bucket would only say "segment 0"
  index_.assign(buckets * channels, 0);
  index_shift_ = shift;
  index_buckets_ = static_cast<uint32_t>(buckets);
  for (uint64_t c = 0; c < channels; ++c) {
    const ChannelTrack& t = tracks_[c];
    if (t.key_count < 2) continue;
    const uint32_t* fr = key_frames_.data() + t.first_key;
    uint32_t j = 0;
    for (uint64_t b = 0; b < buckets; ++b) {
      const uint64_t start = b << shift;
      // Largest j < n-1 with frames[j] <= start (or 0): since start <= floor(f) for every f
      // in the bucket, float(frames[j]) <= f, so j never passes the answer.
      while (j + 2 < t.key_count && fr[j + 1] <= start) ++j;
      index_[b * channels + c] = t.first_key + j;
    }
  }
}

double Clip::duration() const noexcept {
  return frame_count_ == 0 ? 0.0 : static_cast<double>(frame_count_ - 1) * frame_time_;
}

std::span<const uint32_t> Clip::key_frames(uint32_t c) const noexcept {
  const ChannelTrack& t = tracks_[c];
  return {key_frames_.data() + t.first_key, t.key_count};
}

std::span<const float> Clip::key_values(uint32_t c) const noexcept {
  const ChannelTrack& t = tracks_[c];
  return {key_values_.data() + t.first_key, t.key_count};
}

size_t Clip::memory_bytes() const noexcept {
  size_t n = sizeof(Clip);
  n += tracks_.capacity() * sizeof(ChannelTrack);
  n += key_frames_.capacity() * sizeof(uint32_t);
  n += key_values_.capacity() * sizeof(float);
  n += index_.capacity() * sizeof(uint32_t);
  n += notes_.capacity();
  n += skeleton_.joints.capacity() * sizeof(Joint);
  for (const Joint& j : skeleton_.joints) {
    n += j.name.capacity() > 15 ? j.name.capacity() : 0;  // beyond the small-string buffer
    n += j.channels.capacity() * sizeof(ChannelType);
  }
  return n;
}

const uint32_t* Clip::index_row(float f) const noexcept {
  if (index_.empty()) return nullptr;
  // Any bucket whose first frame is <= f gives a lower bound; f < 0 takes bucket 0 (whose
  // entry is segment 0), f past the table the last bucket.
  const double fd = f > 0.0f ? std::min(static_cast<double>(f), 4294967295.0) : 0.0;
  const uint64_t b = std::min<uint64_t>(static_cast<uint64_t>(fd) >> index_shift_, index_buckets_ - 1);
  return index_.data() + b * tracks_.size();
}

namespace {

// Sampling runs in two passes over chunks of channels: a scalar pass finds each channel's
// segment and gathers its operands, then a branch-free pass evaluates eval_segment's
// arithmetic for the whole chunk, which compilers vectorize. The arithmetic is eval_segment's,
// operation for operation (cardinal.h; the tests compare every sample with eval_channel bit for
// bit): with the step-adjusted rule off, or at a channel's first or last key, the gathered
// lengths are equal, so that 2 len / (len + len) is exactly 1, as eval_segment's a0 = a1 = 1.
constexpr uint32_t kChunk = 32;

struct Batch {
  float pm[kChunk], p0[kChunk], p1[kChunk], p2[kChunk], s[kChunk];
  float k0[kChunk], k1[kChunk], len_in[kChunk], len[kChunk], len_out[kChunk];
  float direct[kChunk];
  uint32_t linear_mask[kChunk];  // all ones: linear interpolation
  uint32_t direct_mask[kChunk];  // all ones: the value is `direct` (no segment to evaluate)

  void set_direct(uint32_t i, float v) noexcept {
    pm[i] = p0[i] = p1[i] = p2[i] = s[i] = k0[i] = 0.0f;
    k1[i] = len_in[i] = len[i] = len_out[i] = 1.0f;
    direct[i] = v;
    linear_mask[i] = 0;
    direct_mask[i] = ~0u;
  }
};

// Linear steps before the search falls back to bisection: bounds the worst case to O(log n)
// when one channel has many keys after its starting segment.
constexpr uint32_t kMaxScan = 8;

// "K_k <= f" for a key frame k, i.e. float(k) <= f. While every frame is below 2^24 (the
// default frame limit) floats hold them exactly, and the test is the integer k <= floor(f):
// no conversion on the search's dependency chain.
struct FloatLE {
  float f;
  bool operator()(uint32_t k) const noexcept { return static_cast<float>(k) <= f; }
};
struct IntLE {
  int64_t floor_f;  // -1 below frame 0, 2^32 from frame 2^24 on
  explicit IntLE(float f) noexcept
      : floor_f(f < 0.0f ? -1 : f >= 16777216.0f ? (int64_t(1) << 32) : static_cast<int64_t>(f)) {}
  bool operator()(uint32_t k) const noexcept { return static_cast<int64_t>(k) <= floor_f; }
};

// Advances j (a segment whose first key is <= f) to the largest j < n-1 with K_j <= f.
template <class LE>
inline uint32_t scan_forward(const uint32_t* fr, uint32_t n, uint32_t j, float f, LE le) noexcept {
  for (uint32_t step = 0; j + 2 < n && le(fr[j + 1]); ++j) {
    if (++step == kMaxScan) return j + find_segment(fr + j, n - j, f);
  }
  return j;
}

// Pass one for one channel: the case of eval_channel, and the segment's operands. Branch-free
// on the common path: a mispredicted branch per channel would cost more than the arithmetic.
template <class LE>
inline void gather(Batch& b, uint32_t i, const ChannelTrack& t, const uint32_t* key_frames,
                   const float* key_values, float f, LE le, uint32_t index_entry, bool has_index,
                   uint32_t* cursor, bool step_adjusted) noexcept {
  const uint32_t n = t.key_count;
  const uint32_t* fr = key_frames + t.first_key;
  const float* va = key_values + t.first_key;
  if (n < 2) {
    b.set_direct(i, n == 0 ? 0.0f : va[0]);
    return;
  }
  // A segment j <= n-2 whose first key is <= f (or j = 0): the cursor's, the index's, or
  // bisection's (which is exact, and clamps to the first or last segment outside the keys).
  uint32_t j;
  if (cursor != nullptr && *cursor + 1 < n && le(fr[*cursor]))
    j = *cursor;
  else if (has_index)
    j = index_entry - t.first_key;
  else
    j = find_segment(fr, n, f);
  // Forward to the largest j <= n-2 with K_j <= f. Up to two steps at once, from loads that do
  // not wait for each other (the index's buckets are short enough that more are rare);
  // frames increase, so K_{j+2} <= f implies K_{j+1} <= f.
  const uint32_t last = n - 2;
  const uint32_t one = static_cast<uint32_t>(j < last) & static_cast<uint32_t>(le(fr[j + 1]));
  const uint32_t two = static_cast<uint32_t>(j + 1 < last) & static_cast<uint32_t>(le(fr[std::min(j + 2, n - 1)]));
  j += one + (one & two);
  if (j < last && le(fr[j + 1])) j = scan_forward(fr, n, j, f, le);
  if (cursor != nullptr) *cursor = j;

  const float k0 = static_cast<float>(fr[j]);
  const float k1 = static_cast<float>(fr[j + 1]);
  // eval_channel's other cases, reached only through j: f <= K_0 (j = 0) or f == K_j gives
  // v_j; f >= K_{n-1} (j = n-2) gives v_{n-1}.
  const bool at_or_before = !(f > k0);
  const bool after = f >= k1;
  b.k0[i] = k0;
  b.k1[i] = k1;
  b.p0[i] = va[j];
  b.p1[i] = va[j + 1];
  b.pm[i] = va[j > 0 ? j - 1 : 0];
  b.p2[i] = va[j + 2 < n ? j + 2 : n - 1];
  b.s[i] = t.s;
  const float len = static_cast<float>(fr[j + 1] - fr[j]);
  b.len[i] = len;
  b.len_in[i] = step_adjusted && j > 0 ? static_cast<float>(fr[j] - fr[j - 1]) : len;
  b.len_out[i] = step_adjusted && j + 2 < n ? static_cast<float>(fr[j + 2] - fr[j + 1]) : len;
  b.direct[i] = after ? va[j + 1] : va[j];
  b.linear_mask[i] = t.interp == Interpolation::linear ? ~0u : 0u;
  b.direct_mask[i] = (at_or_before || after) ? ~0u : 0u;
}

// Pass two: eval_segment (and segment_u) for a whole chunk, no branches.
inline void evaluate(const Batch& b, float f, float* res) noexcept {
  for (uint32_t i = 0; i < kChunk; ++i) {
    const float u = (f - b.k0[i]) / (b.k1[i] - b.k0[i]);
    const float d = b.p1[i] - b.p0[i];
    const float lin = b.p0[i] + u * d;
    const float a0 = 2.0f * b.len[i] / (b.len_in[i] + b.len[i]);
    const float a1 = 2.0f * b.len[i] / (b.len[i] + b.len_out[i]);
    const float m0 = b.s[i] * a0 * (b.p1[i] - b.pm[i]);
    const float m1 = b.s[i] * a1 * (b.p2[i] - b.p0[i]);
    const float u2 = u * u;
    const float u3 = u2 * u;
    const float h01 = -2.0f * u3 + 3.0f * u2;
    const float h10 = u3 - 2.0f * u2 + u;
    const float h11 = u3 - u2;
    const float card = b.p0[i] + h01 * d + h10 * m0 + h11 * m1;
    // Selects as bit masks: compilers vectorize them where they would keep a branch.
    const uint32_t ml = b.linear_mask[i], md = b.direct_mask[i];
    const uint32_t curve = (std::bit_cast<uint32_t>(lin) & ml) | (std::bit_cast<uint32_t>(card) & ~ml);
    res[i] = std::bit_cast<float>((std::bit_cast<uint32_t>(b.direct[i]) & md) | (curve & ~md));
  }
}

}  // namespace

void Clip::sample_batch(float f, const uint32_t* channels, uint32_t count, float* out,
                        uint32_t* cursor_segments) const noexcept {
  const uint32_t* row = index_row(f);
  const bool step_adjusted = rule_ == TangentRule::step_adjusted;
  Batch b;
  float res[kChunk];
  auto run = [&](auto le) {
    for (uint32_t base = 0; base < count; base += kChunk) {
      const uint32_t m = std::min(kChunk, count - base);
      for (uint32_t i = 0; i < m; ++i) {
        const uint32_t c = channels != nullptr ? channels[base + i] : base + i;
        gather(b, i, tracks_[c], key_frames_.data(), key_values_.data(), f, le, row != nullptr ? row[c] : 0,
               row != nullptr, cursor_segments != nullptr ? cursor_segments + c : nullptr, step_adjusted);
      }
      for (uint32_t i = m; i < kChunk; ++i) b.set_direct(i, 0.0f);
      evaluate(b, f, res);
      std::memcpy(out + base, res, m * sizeof(float));
    }
  };
  // Key frames are < frame_count: all below 2^24 when frame_count <= 2^24.
  if (frame_count_ <= (1u << 24))
    run(IntLE(f));
  else
    run(FloatLE{f});
}

float Clip::sample_channel(uint32_t c, float frame_position) const noexcept {
  if (c >= tracks_.size()) return 0.0f;
  const ChannelTrack& t = tracks_[c];
  return eval_channel(key_frames_.data() + t.first_key, key_values_.data() + t.first_key, t.key_count,
                      frame_position, t.interp, t.s, rule_);
}

Status Clip::sample(double frame_position, std::span<float> out, SampleCursor* cursor) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  const uint32_t channels = channel_count();
  if (out.size() < channels) return Status::output_too_small;
  uint32_t* seg = nullptr;
  if (cursor != nullptr) {
    if (cursor->clip != this || cursor->segment.size() != channels) {
      try {
        cursor->segment.assign(channels, 0);
        cursor->clip = this;
      } catch (const std::bad_alloc&) {
        cursor->clip = nullptr;  // sample without it
      }
    }
    if (cursor->clip == this) seg = cursor->segment.data();
  }
  sample_batch(static_cast<float>(frame_position), nullptr, channels, out.data(), seg);
  return Status::ok;
}

Status Clip::sample_time(double seconds, std::span<float> out, SampleCursor* cursor) const noexcept {
  if (std::isnan(seconds)) return Status::invalid_argument;
  const double position = frame_time_ > 0.0 ? seconds / frame_time_ : 0.0;
  return sample(position, out, cursor);
}

Status Clip::sample_channels(double frame_position, std::span<const uint32_t> channels,
                             std::span<float> out) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  if (out.size() < channels.size()) return Status::output_too_small;
  for (uint32_t c : channels)
    if (c >= tracks_.size()) return Status::invalid_argument;
  if (channels.size() > UINT32_MAX) return Status::invalid_argument;
  sample_batch(static_cast<float>(frame_position), channels.data(), static_cast<uint32_t>(channels.size()),
               out.data(), nullptr);
  return Status::ok;
}

}  // namespace keyanim
