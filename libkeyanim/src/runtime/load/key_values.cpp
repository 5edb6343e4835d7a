// KVAL: the quantized key values. Format 3.x stores fixed-width residual byte planes
// (parse_kval_fixed); 1.x and 2.x stored varint planes (parse_kval), read here and turned into the
// same quantized integers, so that the image is the same whatever the version.
#include <algorithm>
#include <cmath>
#include <string>

#include "internal/byte_reader.h"
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

Status Loader::parse_kval_fixed(const Content& c, ClipSource& parts) {
  // Plane k: byte k of every residual of the channels with Residual_Bytes > k (section 4.5).
  const size_t channels = parts.channels.size();
  uint64_t size[internal::kMaxResidualBytes] = {};
  for (size_t ch = 0; ch < channels; ++ch)
    for (uint32_t k = 0; k < residual_bytes_[ch]; ++k) size[k] += parts.channels[ch].key_count;
  uint64_t total = 0;
  size_t at[internal::kMaxResidualBytes];  // where each plane's next byte is
  for (uint32_t k = 0; k < internal::kMaxResidualBytes; ++k) at[k] = static_cast<size_t>(total), total += size[k];
  if (total != c.size)
    return fail_in(Status::corrupt, c, 0,
                   "KVAL must hold " + std::to_string(total) + " bytes (the channels' keys times their Residual_Bytes)");
  parts.q.resize(static_cast<size_t>(key_count_));
  for (size_t ch = 0; ch < channels; ++ch) {
    const internal::SourceChannel& t = parts.channels[ch];
    const uint32_t bytes = residual_bytes_[ch];
    const uint8_t* plane[internal::kMaxResidualBytes];
    for (uint32_t k = 0; k < bytes; ++k) plane[k] = c.data + at[k], at[k] += t.key_count;
    const uint32_t* kf = parts.frames.data() + t.first_key;  // KTIM is parsed before KVAL
    int64_t* out = parts.q.data() + t.first_key;
    int64_t q = 0, q_prev = 0, lo = 0, hi = 0;
    for (uint32_t i = 0; i < t.key_count; ++i) {
      uint64_t v = 0;
      for (uint32_t k = 0; k < bytes; ++k) v |= uint64_t(plane[k][i]) << (8 * k);
      // |r| = (v + 1) / 2 without overflow; after this check |prediction + r| < 2^58.
      if ((v >> 1) + (v & 1) > internal::kMaxAbsResidual) [[unlikely]]
        return fail_in(Status::corrupt, c, plane[0] + i - c.data, "channel " + std::to_string(ch) + ": a residual beyond 2^57");
      const int64_t predicted = internal::predict_q(codings_[ch], kf, i, q, q_prev);
      q_prev = q;
      q = predicted + internal::zigzag_decode(v);
      if (q > internal::kMaxAbsQ || q < -internal::kMaxAbsQ) [[unlikely]]
        return fail_in(Status::corrupt, c, plane[0] + i - c.data, "channel " + std::to_string(ch) + ": |q| > 2^53");
      out[i] = q;
      lo = i ? std::min(lo, q) : q, hi = i ? std::max(hi, q) : q;
    }
    // q x step is monotone in q, so the extremes tell whether every value is finite.
    if (t.key_count && (!std::isfinite(dequantize(lo, t.step)) || !std::isfinite(dequantize(hi, t.step))))
      return fail_in(Status::corrupt, c, bytes ? plane[0] - c.data : 0,
                     "channel " + std::to_string(ch) + ": a key value is not finite");
  }
  return Status::ok;
}

}  // namespace keyanim::internal
