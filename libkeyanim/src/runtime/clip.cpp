// Sampling a loaded clip. The value of a channel is exactly eval_channel's (cardinal.h); what
// this file adds is a faster way to find the segment: a per-bucket index built at load, and a
// per-channel cursor for playback.
#include <algorithm>
#include <atomic>
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
  c.p_ = std::move(parts);
  c.build_index();
  static std::atomic<uint64_t> next_id{1};
  c.id_ = next_id.fetch_add(1, std::memory_order_relaxed);
  return c;
}

// Bucket length: the smallest power of two whose table (buckets x channels x 4 bytes) is no
// larger than half the key arrays (keys x 8 bytes). With keys every g frames on average that
// is about g frames, so the search from the bucket's entry takes at most a step or two (which
// the sampler takes without branches). A larger table samples no faster but loads slower.
void Clip::build_index() {
  index_.clear();
  index_shift_ = 0;
  index_buckets_ = 0;
  const uint64_t channels = p_.tracks.size();
  const uint64_t keys = p_.key_frames.size();
  if (channels == 0 || p_.frame_count < 2 || keys == 0) return;
  // Interior positions f satisfy K_0 < f < K_{n-1} <= F - 1, so buckets of frames 0 .. F-2.
  const uint64_t last = p_.frame_count - 2;
  uint32_t shift = 0;
  for (; shift < 32; ++shift) {
    const uint64_t buckets = (last >> shift) + 1;
    if (buckets * channels <= keys) break;
  }
  const uint64_t buckets = (last >> std::min(shift, 31u)) + 1;
  if (shift >= 32 || buckets < 2) return;  // one bucket would only say "segment 0"
  index_.resize(buckets * channels);
  index_shift_ = shift;
  index_buckets_ = static_cast<uint32_t>(buckets);
  // Row by row (the table's order), each channel's segment carried from one row to the next:
  // the largest j < n-1 with frames[j] <= the bucket's first frame (or 0). That frame is
  // <= floor(f) for every f in the bucket, so float(frames[j]) <= f: j never passes the answer.
  struct Walk {
    const uint32_t* next;  // frames[j + 1]
    const uint32_t* stop;  // frames[n - 1]: j stays < n - 1
    uint32_t key;          // absolute index of key j
  };
  std::vector<Walk> walk(channels);
  for (uint64_t c = 0; c < channels; ++c) {
    const ChannelTrack& t = p_.tracks[c];
    const uint32_t* fr = p_.key_frames.data() + t.first_key;
    static const uint32_t kNever = UINT32_MAX;  // channels without segments never advance
    walk[c] = t.key_count < 2 ? Walk{&kNever, &kNever, t.first_key}
                              : Walk{fr + 1, fr + t.key_count - 1, t.first_key};
  }
  uint32_t* out = index_.data();
  for (uint64_t b = 0; b < buckets; ++b) {
    const uint64_t start = b << shift;
    for (Walk& w : walk) {
      // One step without a branch (the usual case: buckets are about half a key gap long),
      // then a loop that rarely runs. *next is always readable: next <= stop.
      const uint32_t step = static_cast<uint32_t>(w.next < w.stop) & static_cast<uint32_t>(*w.next <= start);
      w.next += step;
      w.key += step;
      while (w.next < w.stop && *w.next <= start) {
        ++w.next;
        ++w.key;
      }
      *out++ = w.key;
    }
  }
}

double Clip::duration() const noexcept {
  return p_.frame_count == 0 ? 0.0 : static_cast<double>(p_.frame_count - 1) * p_.frame_time;
}

std::span<const uint32_t> Clip::key_frames(uint32_t c) const noexcept {
  const ChannelTrack& t = p_.tracks[c];
  return {p_.key_frames.data() + t.first_key, t.key_count};
}

std::span<const float> Clip::key_values(uint32_t c) const noexcept {
  const ChannelTrack& t = p_.tracks[c];
  return {p_.key_values.data() + t.first_key, t.key_count};
}

ChannelInfo Clip::channel(uint32_t c) const noexcept {
  const ChannelTrack& t = p_.tracks[c];
  return {t.interp, s_to_tension(t.s), t.key_count};
}

Status Clip::channel_keys(uint32_t c, std::span<uint32_t> frames, std::span<float> values) const noexcept {
  if (c >= p_.tracks.size()) return Status::invalid_argument;
  const ChannelTrack& t = p_.tracks[c];
  if (frames.size() < t.key_count || values.size() < t.key_count) return Status::output_too_small;
  std::copy_n(p_.key_frames.data() + t.first_key, t.key_count, frames.data());
  std::copy_n(p_.key_values.data() + t.first_key, t.key_count, values.data());
  return Status::ok;
}

size_t Clip::memory_bytes() const noexcept {
  size_t n = sizeof(Clip);
  n += p_.tracks.capacity() * sizeof(ChannelTrack);
  n += p_.key_frames.capacity() * sizeof(uint32_t);
  n += p_.key_values.capacity() * sizeof(float);
  n += index_.capacity() * sizeof(uint32_t);
  n += p_.notes.capacity();
  n += p_.skeleton.joints.capacity() * sizeof(Joint);
  for (const Joint& j : p_.skeleton.joints) {
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
  return index_.data() + b * p_.tracks.size();
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

// From a segment j <= n-2 whose first key is <= f (or j = 0), the largest j <= n-2 with
// K_j <= f: eval_channel's segment when f is inside the keys, else the first or last one. Up to
// two steps at once, from loads that do not wait for each other (the index's buckets are short
// enough that more are rare); frames increase, so K_{j+2} <= f implies K_{j+1} <= f.
template <class LE>
inline uint32_t locate(const uint32_t* fr, uint32_t n, uint32_t j, float f, LE le) noexcept {
  const uint32_t last = n - 2;
  const uint32_t one = static_cast<uint32_t>(j < last) & static_cast<uint32_t>(le(fr[j + 1]));
  const uint32_t two = static_cast<uint32_t>(j + 1 < last) & static_cast<uint32_t>(le(fr[std::min(j + 2, n - 1)]));
  j += one + (one & two);
  for (uint32_t step = 0; j < last && le(fr[j + 1]); ++j) {
    if (++step == kMaxScan) return j + find_segment(fr + j, n - j, f);
  }
  return j;
}

// Pass one for one channel: the case of eval_channel, and the segment's operands. Branch-free
// on the common path: a mispredicted branch per channel would cost more than the arithmetic.
template <class LE>
inline void gather(Batch& b, uint32_t i, const ChannelTrack& t, const uint32_t* key_frames,
                   const float* key_values, float f, LE le, const uint32_t* start,
                   bool step_adjusted) noexcept {
  const uint32_t n = t.key_count;
  const uint32_t* fr = key_frames + t.first_key;
  const float* va = key_values + t.first_key;
  if (n < 2) {
    b.set_direct(i, n == 0 ? 0.0f : va[0]);
    return;
  }
  // Start from the index's segment, or bisect (exact, and clamped outside the keys).
  const uint32_t j = locate(fr, n, start != nullptr ? *start - t.first_key : find_segment(fr, n, f), f, le);
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

inline float select_bits(uint32_t mask, float if_set, float if_clear) noexcept {
  return std::bit_cast<float>((std::bit_cast<uint32_t>(if_set) & mask) | (std::bit_cast<uint32_t>(if_clear) & ~mask));
}

// Pass two: eval_segment (and segment_u) for a whole chunk, no branches. The selects are bit
// masks: compilers vectorize them where they would keep a branch.
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
    res[i] = select_bits(b.direct_mask[i], b.direct[i], select_bits(b.linear_mask[i], lin, card));
  }
}

// The cursor's per-channel state, structure of arrays in SampleCursor::cache (kCacheArrays x C
// floats) and ::flags (2 x C). A channel's state holds while lo <= f < hi; then the value is
// the segment polynomial below, or `p0` itself for a direct one (clamped, constant, zero).
enum CacheArray : uint32_t { kLo, kHi, kK0, kK1, kP0, kD, kM0, kM1, kCacheArrays };
enum FlagArray : uint32_t { kLinearMask, kDirectMask, kFlagArrays };
constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

void Clip::sample_batch(float f, const uint32_t* channels, uint32_t count, float* out) const noexcept {
  const uint32_t* row = index_row(f);
  const bool step_adjusted = p_.rule == TangentRule::step_adjusted;
  Batch b;
  float res[kChunk];
  auto run = [&](auto le) {
    for (uint32_t base = 0; base < count; base += kChunk) {
      const uint32_t m = std::min(kChunk, count - base);
      for (uint32_t i = 0; i < m; ++i) {
        const uint32_t c = channels != nullptr ? channels[base + i] : base + i;
        gather(b, i, p_.tracks[c], p_.key_frames.data(), p_.key_values.data(), f, le, row != nullptr ? row + c : nullptr,
               step_adjusted);
      }
      for (uint32_t i = m; i < kChunk; ++i) b.set_direct(i, 0.0f);
      evaluate(b, f, res);
      std::memcpy(out + base, res, m * sizeof(float));
    }
  };
  // Key frames are < frame_count: all below 2^24 when frame_count <= 2^24.
  if (p_.frame_count <= (1u << 24))
    run(IntLE(f));
  else
    run(FloatLE{f});
}

// Prepares channel c's cursor state for position f: its segment and the operands that stay the
// same along it (computed with eval_segment's operations, so the results are unchanged).
void Clip::refresh_cursor(uint32_t c, float f, SampleCursor& cursor) const noexcept {
  const uint32_t C = channel_count();
  float* st = cursor.cache.data();
  uint32_t* fl = cursor.flags.data();
  auto set_direct = [&](float value, float lo, float hi) {
    st[kLo * C + c] = lo;
    st[kHi * C + c] = hi;
    st[kK0 * C + c] = 0.0f;
    st[kK1 * C + c] = 1.0f;
    st[kP0 * C + c] = value;
    st[kD * C + c] = st[kM0 * C + c] = st[kM1 * C + c] = 0.0f;
    fl[kLinearMask * C + c] = 0;
    fl[kDirectMask * C + c] = ~0u;
  };
  const ChannelTrack& t = p_.tracks[c];
  const uint32_t n = t.key_count;
  const uint32_t* fr = p_.key_frames.data() + t.first_key;
  const float* va = p_.key_values.data() + t.first_key;
  if (n < 2) {
    set_direct(n == 0 ? 0.0f : va[0], -kInf, kInf);
    return;
  }
  uint32_t& seg = cursor.segment[c];
  const FloatLE le{f};
  uint32_t start;
  if (seg + 1 < n && le(fr[seg]))
    start = seg;  // playback: the same segment or a later one
  else if (const uint32_t* row = index_row(f))
    start = row[c] - t.first_key;
  else
    start = find_segment(fr, n, f);
  const uint32_t j = locate(fr, n, start, f, le);
  seg = j;
  const float k0 = static_cast<float>(fr[j]);
  const float k1 = static_cast<float>(fr[j + 1]);
  if (!(f > k0) && j == 0 && f < k0) {
    set_direct(va[0], -kInf, k0);  // before the first key (f == K_0 is the segment's start)
    return;
  }
  if (f >= k1) {
    set_direct(va[j + 1], k1, kInf);  // at or after the last key
    return;
  }
  const float p0 = va[j], p1 = va[j + 1];
  const float pm = va[j > 0 ? j - 1 : 0];
  const float p2 = va[j + 2 < n ? j + 2 : n - 1];
  float a0 = 1.0f, a1 = 1.0f;
  if (p_.rule == TangentRule::step_adjusted) {
    const float len = static_cast<float>(fr[j + 1] - fr[j]);
    if (j > 0) a0 = 2.0f * len / (static_cast<float>(fr[j] - fr[j - 1]) + len);
    if (j + 2 < n) a1 = 2.0f * len / (len + static_cast<float>(fr[j + 2] - fr[j + 1]));
  }
  const float d = p1 - p0;
  const float m0 = t.s * a0 * (p1 - pm);
  const float m1 = t.s * a1 * (p2 - p0);
  // At f == K_j the polynomial gives p0 + (+-0) ... = p0 exactly, as eval_channel's v_j, as
  // long as the operands are finite and p0 is not -0 (-0 + +0 is +0); else K_j itself is left
  // to a direct state.
  const bool finite = std::isfinite(d) && std::isfinite(m0) && std::isfinite(m1);
  const bool exact_at_key = finite && p0 != 0.0f;
  if (!exact_at_key && f == k0) {
    set_direct(p0, k0, std::nextafter(k0, kInf));
    return;
  }
  st[kLo * C + c] = exact_at_key ? k0 : std::nextafter(k0, kInf);
  st[kHi * C + c] = k1;
  st[kK0 * C + c] = k0;
  st[kK1 * C + c] = k1;
  st[kP0 * C + c] = p0;
  st[kD * C + c] = d;
  st[kM0 * C + c] = m0;
  st[kM1 * C + c] = m1;
  fl[kLinearMask * C + c] = t.interp == Interpolation::linear ? ~0u : 0u;
  fl[kDirectMask * C + c] = 0;
}

void Clip::sample_cursor(float f, float* out, SampleCursor& cursor) const noexcept {
  const uint32_t C = channel_count();
  const float* st = cursor.cache.data();
  const uint32_t* fl = cursor.flags.data();
  const float* lo = st + kLo * C;
  const float* hi = st + kHi * C;
  for (uint32_t c = 0; c < C; ++c)
    if (!(lo[c] <= f && f < hi[c])) refresh_cursor(c, f, cursor);
  const float* k0 = st + kK0 * C;
  const float* k1 = st + kK1 * C;
  const float* p0 = st + kP0 * C;
  const float* dd = st + kD * C;
  const float* m0 = st + kM0 * C;
  const float* m1 = st + kM1 * C;
  const uint32_t* lin_mask = fl + kLinearMask * C;
  const uint32_t* dir_mask = fl + kDirectMask * C;
  for (uint32_t c = 0; c < C; ++c) {
    const float u = (f - k0[c]) / (k1[c] - k0[c]);
    const float d = dd[c];
    const float lin = p0[c] + u * d;
    const float u2 = u * u;
    const float u3 = u2 * u;
    const float h01 = -2.0f * u3 + 3.0f * u2;
    const float h10 = u3 - 2.0f * u2 + u;
    const float h11 = u3 - u2;
    const float card = p0[c] + h01 * d + h10 * m0[c] + h11 * m1[c];
    out[c] = select_bits(dir_mask[c], p0[c], select_bits(lin_mask[c], lin, card));
  }
}

float Clip::sample_channel(uint32_t c, float frame_position) const noexcept {
  if (c >= p_.tracks.size()) return 0.0f;
  const ChannelTrack& t = p_.tracks[c];
  return eval_channel(p_.key_frames.data() + t.first_key, p_.key_values.data() + t.first_key, t.key_count,
                      frame_position, t.interp, t.s, p_.rule);
}

Status Clip::sample(double frame_position, std::span<float> out, SampleCursor* cursor) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  const uint32_t channels = channel_count();
  if (out.size() < channels) return Status::output_too_small;
  const float f = static_cast<float>(frame_position);
  if (cursor != nullptr && id_ != 0) {
    if (cursor->clip_id != id_ || cursor->clip != this || cursor->segment.size() != channels ||
        cursor->cache.size() != size_t(kCacheArrays) * channels ||
        cursor->flags.size() != size_t(kFlagArrays) * channels) {
      try {
        cursor->segment.assign(channels, 0);
        // An empty range (lo = +inf) makes every channel refresh on first use.
        cursor->cache.assign(size_t(kCacheArrays) * channels, kInf);
        cursor->flags.assign(size_t(kFlagArrays) * channels, 0);
        cursor->clip = this;
        cursor->clip_id = id_;
      } catch (const std::bad_alloc&) {
        cursor->clip = nullptr;
        cursor->clip_id = 0;
      }
    }
    if (cursor->clip_id == id_) {
      sample_cursor(f, out.data(), *cursor);
      return Status::ok;
    }
  }
  sample_batch(f, nullptr, channels, out.data());
  return Status::ok;
}

Status Clip::sample_time(double seconds, std::span<float> out, SampleCursor* cursor) const noexcept {
  if (std::isnan(seconds)) return Status::invalid_argument;
  const double position = p_.frame_time > 0.0 ? seconds / p_.frame_time : 0.0;
  return sample(position, out, cursor);
}

Status Clip::sample_channels(double frame_position, std::span<const uint32_t> channels,
                             std::span<float> out) const noexcept {
  if (std::isnan(frame_position)) return Status::invalid_argument;
  if (out.size() < channels.size()) return Status::output_too_small;
  for (uint32_t c : channels)
    if (c >= p_.tracks.size()) return Status::invalid_argument;
  if (channels.size() > UINT32_MAX) return Status::invalid_argument;
  sample_batch(static_cast<float>(frame_position), channels.data(), static_cast<uint32_t>(channels.size()),
               out.data());
  return Status::ok;
}

}  // namespace keyanim
