// KVAL: the quantized key values. Format 3.x stores fixed-width residual byte planes
// (parse_kval_fixed); 1.x and 2.x stored varint planes (parse_kval), read here and turned into the
// same quantized integers, so that the image is the same whatever the version.
#include <algorithm>
#include <cmath>
#include <string>

#include "internal/byte_reader.h"
#include "internal/quat_layout.h"
#include "internal/format.h"
#include "internal/value_coding.h"
#include "internal/varint.h"
#include "keyanim/cardinal.h"
#include "runtime/load/loader.h"

namespace keyanim::internal {

Status Loader::parse_kval(const Content& c, ClipSource& parts) {
  // Plane_Count, Plane_Size[Plane_Count], then the planes (spec/FORMAT.md 4.5).
  ByteReader r(c.data, c.size);
  uint8_t count = 0;
  if (!r.read(count) || count > internal::kMaxVarint64Bytes)
    return fail_in(Status::corrupt, c, 0, "Plane_Count must be 0 to 10");
  if ((count == 0) != (key_count_ == 0))
    return fail_in(Status::corrupt, c, 0, "Plane_Count must be 0 exactly when there are no keys");
  const uint8_t* plane[internal::kMaxVarint64Bytes] = {};
  uint64_t size[internal::kMaxVarint64Bytes] = {};
  size_t base[internal::kMaxVarint64Bytes] = {};  // section offsets, for errors
  uint64_t total = 1 + 4 * uint64_t(count);
  if (c.size < total) return fail_in(Status::corrupt, c, 0, "KVAL ends inside its plane sizes");
  for (uint8_t k = 0; k < count; ++k) {
    uint32_t n = 0;
    r.read(n);
    size[k] = n;
    total += n;
    if (n == 0) return fail_in(Status::corrupt, c, 1 + 4 * size_t(k), "an empty plane");
  }
  if (total != c.size) return fail_in(Status::corrupt, c, 1, "the plane sizes do not add up to Raw_Size");
  if (count > 0 && size[0] != key_count_)
    return fail_in(Status::corrupt, c, 1, "plane 0 must hold one byte per key");
  size_t at = 1 + 4 * size_t(count);
  for (uint8_t k = 0; k < count; ++k) {
    base[k] = at;
    plane[k] = c.data + at;
    at += static_cast<size_t>(size[k]);
  }
  parts.q.resize(static_cast<size_t>(key_count_));  // key_count_ == size[0] <= c.size
  size_t pos[internal::kMaxVarint64Bytes] = {};
  for (size_t ch = 0; ch < parts.channels.size(); ++ch) {
    const internal::SourceChannel& t = parts.channels[ch];
    int64_t q = 0, q_prev = 0;
    for (uint32_t i = 0; i < t.key_count; ++i) {
      const size_t first_at = base[0] + pos[0];
      // The varint's k-th byte is the next unread byte of plane k (section 6.1 rules). Plane 0
      // holds exactly one byte per key, so its first byte is always there.
      uint64_t v = plane[0][pos[0]++];
      if (v & 0x80u) {
        v &= 0x7Fu;
        for (uint32_t k = 1;; ++k) {
          if (k >= count || pos[k] == size[k])
            return fail_in(Status::corrupt, c, k < count ? base[k] + pos[k] : first_at,
                           "a varint continues past the bytes of its planes");
          const uint8_t b = plane[k][pos[k]++];
          const uint64_t bits = b & 0x7Fu;
          if (k == internal::kMaxVarint64Bytes - 1 && ((b & 0x80u) || bits > 1))
            return fail_in(Status::corrupt, c, first_at, "a varint too large for its field");
          v |= bits << (7 * k);
          if (!(b & 0x80u)) {
            if (b == 0) return fail_in(Status::corrupt, c, first_at, "an over-long varint");
            break;
          }
        }
      }
      if (Status st = residual_to_q(c, first_at, ch, i, v, q, q_prev, parts); st != Status::ok) return st;
    }
  }
  for (uint8_t k = 0; k < count; ++k)
    if (pos[k] != size[k]) return fail_in(Status::corrupt, c, base[k] + pos[k], "plane bytes left over");
  return Status::ok;
}

Status Loader::residual_to_q(const Content& c, size_t at, size_t ch, uint32_t i, uint64_t v, int64_t& q,
                             int64_t& q_prev, ClipSource& parts) {
  const internal::SourceChannel& t = parts.channels[ch];
  // 1.x stores deltas up to 2^54; 2.x and 3.x residuals up to 2^57, so |prediction + residual|
  // < 2^58. zigzag: |r| = (v + 1) / 2 without overflow.
  const uint64_t max_residual = major_ >= 2 ? internal::kMaxAbsResidual : internal::kMaxAbsDelta;
  if ((v >> 1) + (v & 1) > max_residual)
    return fail_in(Status::corrupt, c, at,
                   "channel " + std::to_string(ch) + (major_ >= 2 ? ": a residual beyond 2^57" : ": a delta beyond 2^54"));
  const uint32_t* kf = parts.frames.data() + t.first_key;  // KTIM is parsed before KVAL
  const int64_t predicted = internal::predict_q(codings_[ch], kf, i, q, q_prev);
  q_prev = q;
  q = predicted + internal::zigzag_decode(v);
  if (q > internal::kMaxAbsQ || q < -internal::kMaxAbsQ)
    return fail_in(Status::corrupt, c, at, "channel " + std::to_string(ch) + ": |q| > 2^53");
  if (!std::isfinite(dequantize(q, t.step)))
    return fail_in(Status::corrupt, c, at, "channel " + std::to_string(ch) + ": a key value is not finite");
  parts.q[t.first_key + i] = q;
  return Status::ok;
}

namespace {

// Where decoding one channel's keys stopped: n when every key was in bounds, else the key and
// the bound it broke.
struct KeysDecoded {
  uint32_t at;
  bool residual_too_big;  // else |q| > 2^53
  int64_t lo, hi;         // the smallest and largest q decoded
};

// Residual i of a channel with B residual bytes, byte k in plane[k].
template <uint32_t B>
[[gnu::always_inline]] inline uint64_t residual(const uint8_t* const* plane, uint32_t i) noexcept {
  uint64_t v = 0;
  for (uint32_t k = 0; k < B; ++k) v |= uint64_t(plane[k][i]) << (8 * k);
  return v;
}

// q_i = prediction + residual for one channel of n keys (section 4.5), into out. One loop per
// width and coding, so that the loop body has no branch but the bounds: below 8 bytes a residual
// is below 2^56 and cannot break the 2^57 bound, and delta coding predicts q_{i-1} (0 for the
// first key, which q = 0 gives).
template <uint32_t B>
KeysDecoded decode_keys(const uint8_t* const* plane, ValueCoding coding, const uint32_t* kf, uint32_t n,
                        int64_t* out) noexcept {
  KeysDecoded r{n, false, INT64_MAX, INT64_MIN};
  int64_t q = 0, q_prev = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const uint64_t v = residual<B>(plane, i);
    if constexpr (B == kMaxResidualBytes) {
      if ((v >> 1) + (v & 1) > kMaxAbsResidual) [[unlikely]] {  // |r| = (v + 1) / 2 without overflow
        r.at = i, r.residual_too_big = true;
        return r;
      }
    }
    const int64_t predicted = coding == ValueCoding::delta ? q : predict_q(coding, kf, i, q, q_prev);
    q_prev = q;
    q = predicted + zigzag_decode(v);  // |prediction + r| < 2^58 after the bound above
    if (q > kMaxAbsQ || q < -kMaxAbsQ) [[unlikely]] {
      r.at = i;
      return r;
    }
    out[i] = q;
    r.lo = std::min(r.lo, q), r.hi = std::max(r.hi, q);
  }
  return r;
}

using DecodeKeys = KeysDecoded (*)(const uint8_t* const*, ValueCoding, const uint32_t*, uint32_t, int64_t*) noexcept;
constexpr DecodeKeys kDecodeKeys[kMaxResidualBytes + 1] = {decode_keys<0>, decode_keys<1>, decode_keys<2>,
                                                           decode_keys<3>, decode_keys<4>, decode_keys<5>,
                                                           decode_keys<6>, decode_keys<7>, decode_keys<8>};

}  // namespace

uint64_t Loader::kval_fixed_bytes(const ClipSource& parts) const noexcept {
  uint64_t total = 0;  // < 2^28 keys x 8 bytes
  for (size_t ch = 0; ch < parts.channels.size(); ++ch) total += uint64_t(parts.channels[ch].key_count) * residual_bytes_[ch];
  return total;
}

Status Loader::parse_kval_fixed(const Content& c, ClipSource& parts) {
  // Plane k: byte k of every residual of the channels with Residual_Bytes > k (section 4.5).
  const size_t channels = parts.channels.size();
  uint64_t size[internal::kMaxResidualBytes] = {};
  for (size_t ch = 0; ch < channels; ++ch)
    for (uint32_t k = 0; k < residual_bytes_[ch]; ++k) size[k] += parts.channels[ch].key_count;
  size_t at[internal::kMaxResidualBytes];  // where each plane's next byte is
  uint64_t total = 0;
  for (uint32_t k = 0; k < internal::kMaxResidualBytes; ++k) at[k] = static_cast<size_t>(total), total += size[k];
  if (total != c.size)
    return fail_in(Status::corrupt, c, 0,
                   "KVAL must hold " + std::to_string(kval_fixed_bytes(parts)) + " bytes (the channels' keys times their Residual_Bytes)");
  parts.q.resize(static_cast<size_t>(key_count_));
  for (size_t ch = 0; ch < channels; ++ch) {
    const internal::SourceChannel& t = parts.channels[ch];
    const uint32_t bytes = residual_bytes_[ch];
    const uint8_t* plane[internal::kMaxResidualBytes] = {};
    for (uint32_t k = 0; k < bytes; ++k) plane[k] = c.data + at[k], at[k] += t.key_count;
    const uint32_t* kf = parts.frames.data() + t.first_key;  // KTIM is parsed before KVAL
    const KeysDecoded r = kDecodeKeys[bytes](plane, codings_[ch], kf, t.key_count, parts.q.data() + t.first_key);
    if (r.at < t.key_count) [[unlikely]]
      return fail_in(Status::corrupt, c, plane[0] + r.at - c.data,
                     "channel " + std::to_string(ch) + (r.residual_too_big ? ": a residual beyond 2^57" : ": |q| > 2^53"));
    // q x step is monotone in q, so the extremes tell whether every value is finite.
    if (t.key_count && (!std::isfinite(dequantize(r.lo, t.step)) || !std::isfinite(dequantize(r.hi, t.step))))
      return fail_in(Status::corrupt, c, bytes ? plane[0] - c.data : 0,
                     "channel " + std::to_string(ch) + ": a key value is not finite");
  }
  if (const uint32_t ch = internal::stored_quat_out_of_range(parts); ch != UINT32_MAX)
    return fail_in(Status::corrupt, c, 0,
                   "channel " + std::to_string(ch) + ": a quaternion node's stored x, y or z has a key beyond +-16 (section 4.7)");
  return Status::ok;
}

}  // namespace keyanim::internal
