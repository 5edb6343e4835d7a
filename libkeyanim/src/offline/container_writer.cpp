// Writes the .kanim container (spec/FORMAT.md) and builds the runtime Clip a decoder would
// load from it.
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "internal/byte_writer.h"
#include "internal/format.h"
#include "internal/quat_layout.h"
#include "internal/value_coding.h"
#include "internal/varint.h"
#include "keyanim/offline/container.h"
#include "keyanim/version.h"
#include "runtime/clip_access.h"
#include "internal/clip_source.h"
#include "offline/container_parts.h"

namespace keyanim::offline {
namespace {

using internal::put_bytes;
using internal::put_le;
using internal::put_varint;
using internal::ValueCoding;

// Residuals of a channel's quantized values under a coding; false if one is out of range.
bool residuals(const EncodedChannel& c, ValueCoding coding, std::vector<int64_t>& out) {
  out.resize(c.q.size());
  for (uint32_t i = 0; i < c.q.size(); ++i) {
    const int64_t q1 = i > 0 ? c.q[i - 1] : 0, q2 = i > 1 ? c.q[i - 2] : 0;
    const int64_t r = c.q[i] - internal::predict_q(coding, c.frames.data(), i, q1, q2);
    if (r > int64_t(internal::kMaxAbsResidual) || r < -int64_t(internal::kMaxAbsResidual)) return false;
    out[i] = r;
  }
  return true;
}

size_t varint_bytes(const std::vector<int64_t>& r) {
  size_t n = 0;
  for (int64_t x : r) n += internal::varint_size(internal::zigzag_encode(x));
  return n;
}

// How KVAL stores each channel's values: the prediction, and the bytes per residual.
struct ValuePlan {
  std::vector<ValueCoding> coding;
  std::vector<uint8_t> bytes;  // Residual_Bytes: the fewest that hold every zigzag residual
};

// Per channel, the coding whose residuals are smaller (their varint bytes, a proxy for what
// zstd makes of them; delta on a tie): extrapolation pays on smooth channels with sparse keys
// and loses on noisy ones (spec Appendix D).
ValuePlan plan_values(const std::vector<EncodedChannel>& chans) {
  ValuePlan plan;
  plan.coding.assign(chans.size(), ValueCoding::delta);
  plan.bytes.assign(chans.size(), 0);
  std::vector<int64_t> d, e;
  for (size_t c = 0; c < chans.size(); ++c) {
    residuals(chans[c], ValueCoding::delta, d);  // |q| <= 2^53: always in range
    if (residuals(chans[c], ValueCoding::extrapolate, e) && varint_bytes(e) < varint_bytes(d)) {
      plan.coding[c] = ValueCoding::extrapolate;
      d.swap(e);
    }
    uint64_t widest = 0;
    for (int64_t r : d) widest |= internal::zigzag_encode(r);
    while (widest >> (8 * plan.bytes[c])) ++plan.bytes[c];
  }
  return plan;
}

std::string channel_problem(const EncodedChannel& ch, uint32_t frame_count) {
  if (static_cast<uint8_t>(ch.interp) > internal::kMaxInterpolation) return "unknown interpolation";
  if (!std::isfinite(ch.tension) || ch.tension < -1.0f || ch.tension > 1.0f)
    return "tension outside [-1, 1]";
  if (!std::isfinite(ch.step) || !(ch.step > 0.0)) return "step not finite and > 0";
  if (ch.frames.size() != ch.q.size()) return "frames and q differ in length";
  if (ch.frames.size() > frame_count) return "more keys than frames";
  for (size_t i = 0; i < ch.frames.size(); ++i) {
    if (ch.frames[i] >= frame_count) return "key frame " + std::to_string(ch.frames[i]) + " >= frame_count";
    if (i > 0 && ch.frames[i] <= ch.frames[i - 1]) return "key frames not strictly increasing";
    if (ch.q[i] > internal::kMaxAbsQ || ch.q[i] < -internal::kMaxAbsQ) return "|q| > 2^53";
    if (!std::isfinite(dequantize(ch.q[i], ch.step))) return "key value not finite in binary32";
  }
  return {};
}

// Column by column: values of one kind sit together and compress better.
std::vector<uint8_t> chan_section(const std::vector<EncodedChannel>& chans, const ValuePlan& plan) {
  std::vector<uint8_t> s;
  s.reserve(chans.size() * internal::kChanBytesPerChannel);
  for (const auto& c : chans) put_le<uint8_t>(s, static_cast<uint8_t>(c.interp));
  for (const auto& c : chans) put_le<float>(s, c.tension);
  for (const auto& c : chans) put_le<double>(s, c.step);
  for (const auto& c : chans) put_le<uint32_t>(s, static_cast<uint32_t>(c.frames.size()));
  for (ValueCoding v : plan.coding) put_le<uint8_t>(s, static_cast<uint8_t>(v));
  for (uint8_t b : plan.bytes) put_le<uint8_t>(s, b);
  return s;
}

// Every channel's key frames, but a quaternion node's y and z (section 4.4: they are its x's).
std::vector<uint8_t> ktim_section(const std::vector<EncodedChannel>& chans, const std::vector<internal::Stored>& kinds) {
  std::vector<uint8_t> s;
  for (size_t ch = 0; ch < chans.size(); ++ch) {
    const EncodedChannel& c = chans[ch];
    if (kinds[ch] == internal::Stored::quat_y || kinds[ch] == internal::Stored::quat_z) continue;
    for (size_t i = 0; i < c.frames.size(); ++i)
      put_varint(s, i == 0 ? c.frames[0] : uint64_t(c.frames[i] - c.frames[i - 1] - 1));
  }
  return s;
}

// The zigzag residuals in byte planes: plane k holds byte k of every residual of the channels
// whose residuals have more than k bytes. Low bytes (nearly uniform) and high bytes (mostly
// small) then form streams of like statistics; `breaks` gets the plane boundaries, where the
// writer ends a zstd block so that each plane gets its own entropy tables.
std::vector<uint8_t> kval_section(const std::vector<EncodedChannel>& chans, const ValuePlan& plan,
                                  std::vector<size_t>& breaks) {
  std::vector<uint8_t> s;
  std::vector<int64_t> r;
  for (uint32_t k = 0; k < internal::kMaxResidualBytes; ++k) {
    const size_t plane_start = s.size();
    for (size_t c = 0; c < chans.size(); ++c) {
      if (plan.bytes[c] <= k) continue;
      residuals(chans[c], plan.coding[c], r);  // in range: plan_values checked
      for (int64_t x : r) s.push_back(static_cast<uint8_t>(internal::zigzag_encode(x) >> (8 * k)));
    }
    if (s.size() > plane_start && plane_start > 0) breaks.push_back(plane_start);
  }
  return s;
}

// Without a level from the caller, each section at the cheapest parameters measured to keep
// its bytes: over the 42 corpus files (0.05% / 0.5% of the skeleton size), against -19 on
// every section (1,316,838 / 520,860 bytes) and counted by callgrind on CMU 01_01 and Bandai
// walk_sad_002. zstd -19 (btultra2) cost 555 M instructions there, 15% of the encode, KTIM
// 356 M and KVAL 181 M of them, for 0.5% fewer KTIM bytes than -15 and 0.75% fewer KVAL bytes
// than -1. A minimum match of 6 bytes is both smaller and cheaper on the key sections (the
// short matches of gaps and residual bytes cost more to code than they save). Per section:
// KVAL -12, min match 6: +482 / -240 bytes, 181 M -> 20 M instructions (-9, min match 6:
// +985 / -277, 13 M); KTIM -15, min match 6: +2,440 / -257, 356 M -> 114 M (-16: +1,091 /
// -397, 163 M; -13: +13,065 / +1,210); SKEL and CHAN -15: +128 and +171 bytes, 17 M -> 9 M;
// NOTE -15: -9 bytes. All five: +0.24% / -0.04% bytes for 139 M instructions instead of 555 M.
constexpr Zstd kSkelZstd{15, 0}, kChanZstd{15, 0}, kKtimZstd{15, 6}, kKvalZstd{12, 6}, kNoteZstd{15, 0};

// Compresses `raw` as one zstd frame, ending a zstd block at each of `breaks` (offsets) so
// that streams of different statistics (the KVAL planes) get their own entropy tables.
Section make_section(uint32_t tag, uint32_t flags, std::vector<uint8_t> raw, ZSTD_CCtx* cctx, Zstd z,
                     const std::vector<size_t>& breaks, std::span<const uint8_t> dictionary) {
  Section sec;
  sec.tag = tag;
  sec.flags = flags;
  sec.raw_size = raw.size();
  if (!raw.empty() && cctx != nullptr) {
    std::vector<uint8_t> out_bytes(ZSTD_compressBound(raw.size()) + 64 * (breaks.size() + 1));
    ZSTD_CCtx_reset(cctx, ZSTD_reset_session_and_parameters);
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, z.level);
    if (z.min_match > 0) ZSTD_CCtx_setParameter(cctx, ZSTD_c_minMatch, z.min_match);
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, 1);  // the spec requires it
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 0);     // the file has its own CRC
    if (!dictionary.empty()) ZSTD_CCtx_loadDictionary(cctx, dictionary.data(), dictionary.size());  // a bank's (section 10.4)
    ZSTD_CCtx_setPledgedSrcSize(cctx, raw.size());
    ZSTD_outBuffer out{out_bytes.data(), out_bytes.size(), 0};
    bool ok = true;
    size_t from = 0;
    for (size_t k = 0; k <= breaks.size() && ok; ++k) {
      const size_t to = k < breaks.size() ? std::min(breaks[k], raw.size()) : raw.size();
      if (to < from) continue;
      ZSTD_inBuffer in{raw.data() + from, to - from, 0};
      const ZSTD_EndDirective mode = k < breaks.size() ? ZSTD_e_flush : ZSTD_e_end;
      size_t left = 0;
      do {
        left = ZSTD_compressStream2(cctx, &out, &in, mode);
        if (ZSTD_isError(left) || (left != 0 && out.pos == out.size)) ok = false;
      } while (ok && left != 0);
      from = to;
    }
    if (ok && out.pos < raw.size()) {
      out_bytes.resize(out.pos);
      sec.stored = std::move(out_bytes);
      sec.flags |= internal::kSectionCompressed;
      return sec;
    }
  }
  sec.stored = std::move(raw);
  return sec;
}

}  // namespace

uint32_t crc32_of(const uint8_t* p, size_t n) {
  uLong crc = crc32(0L, Z_NULL, 0);
  while (n > 0) {  // zlib takes uInt lengths
    const uInt chunk = static_cast<uInt>(std::min<size_t>(n, 1u << 30));
    crc = crc32(crc, p, chunk);
    p += chunk;
    n -= chunk;
  }
  return static_cast<uint32_t>(crc);
}

namespace {

// The first rule of section 4.7 (QUAT) that `clip`'s quaternion nodes break, or "". The
// skeleton's rules hold (first_broken_rule checked them).
std::string quat_problem(const EncodedClip& clip) {
  const auto& joints = clip.skeleton.joints;
  Skeleton s = clip.skeleton;
  s.assign_channel_columns();
  for (size_t i = 0; i < clip.quat_nodes.size(); ++i) {
    const QuatNode& n = clip.quat_nodes[i];
    const std::string where = "quaternion node " + std::to_string(i) + ": ";
    if (n.node >= joints.size()) return where + "no such node";
    if (i > 0 && n.node <= clip.quat_nodes[i - 1].node) return where + "nodes not strictly increasing";
    if (!quaternion_capable(joints[n.node])) return where + "its node lacks three consecutive rotation channels about three axes";
    if (!internal::valid_reference(n.reference)) return where + "reference's x^2 + y^2 + z^2 above 1";
    const uint32_t c = internal::first_quat_channel(s, n.node);
    const EncodedChannel& x = clip.channels[c];
    for (uint32_t k = 1; k < 3; ++k) {
      const EncodedChannel& o = clip.channels[c + k];
      if (o.interp != x.interp || std::memcmp(&o.tension, &x.tension, sizeof(float)) != 0 || o.frames != x.frames)
        return where + "its x, y and z differ in interpolation, tension or key frames";
    }
    for (uint32_t k = 0; k < 3; ++k) {
      const EncodedChannel& ch = clip.channels[c + k];
      for (int64_t q : ch.q)
        if (!(std::fabs(dequantize(q, ch.step)) <= internal::kMaxStoredQuatValue))
          return where + "a key of its stored x, y or z beyond +-16";
    }
  }
  return {};
}

// The first rule of spec/FORMAT.md that `clip` breaks, or "".
std::string first_broken_rule(const EncodedClip& clip) {
  const auto& joints = clip.skeleton.joints;
  if (joints.size() > UINT32_MAX) return "too many nodes";
  uint64_t channel_sum = 0;
  for (size_t i = 0; i < joints.size(); ++i) {
    const Joint& j = joints[i];
    const std::string where = "node " + std::to_string(i) + ": ";
    if (j.name.size() > UINT32_MAX) return where + "name too long";
    if (j.parent < -1 || (j.parent >= 0 && static_cast<size_t>(j.parent) >= i))
      return where + "parent must be -1 or an earlier node";
    if (j.parent >= 0 && joints[static_cast<size_t>(j.parent)].end_site)
      return where + "parent is an End Site";
    if (j.end_site && j.parent < 0) return where + "End Site without a parent";
    if (j.end_site && !j.channels.empty()) return where + "End Site with channels";
    if (j.channels.size() > internal::kMaxNodeChannels) return where + "more than 6 channels";
    for (ChannelType t : j.channels)
      if (static_cast<uint8_t>(t) > internal::kMaxChannelType) return where + "unknown channel type";
    for (double o : j.offset)
      if (!std::isfinite(o)) return where + "offset not finite";
    channel_sum += j.channels.size();
  }
  if (channel_sum != clip.channels.size()) return "channel count differs from the skeleton's";
  if (static_cast<uint8_t>(clip.tangent_rule) > internal::kMaxTangentRule) return "unknown tangent rule";
  if (clip.frame_count > internal::kMaxFrames) return "more than 2^24 frames";
  if (!std::isfinite(clip.frame_time) || clip.frame_time < 0.0 ||
      (clip.frame_count > 1 && !(clip.frame_time > 0.0)))
    return "frame_time must be finite, >= 0, and > 0 when there are several frames";
  uint64_t keys = 0;
  for (size_t c = 0; c < clip.channels.size(); ++c) {
    const std::string p = channel_problem(clip.channels[c], clip.frame_count);
    if (!p.empty()) return "channel " + std::to_string(c) + ": " + p;
    keys += clip.channels[c].frames.size();
  }
  if (keys > UINT32_MAX) return "more than 2^32 - 1 keys";
  return quat_problem(clip);
}

}  // namespace


std::vector<uint8_t> clip_section(uint32_t frame_count, const Skeleton& skeleton, size_t channels, TangentRule rule,
                                  double frame_time, uint64_t keys) {
  // Section 4.1's fields at their offsets (little-endian hosts, as the loader assumes).
  std::vector<uint8_t> s(internal::kClipSize, 0);
  const uint32_t counts[3] = {frame_count, static_cast<uint32_t>(skeleton.joints.size()), static_cast<uint32_t>(channels)};
  std::memcpy(s.data(), counts, sizeof counts);
  s[12] = static_cast<uint8_t>(rule);  // then Clip_Flags and Clip_Reserved, 0
  std::memcpy(s.data() + 16, &frame_time, 8);
  std::memcpy(s.data() + 24, &keys, 8);
  return s;
}

std::vector<uint8_t> quat_section(const std::vector<QuatNode>& nodes) {
  // Quat_Count at its offset: put_le on an empty vector makes GCC 12 warn of an overflow that
  // cannot happen (as in assemble).
  std::vector<uint8_t> s(internal::kQuatHeaderBytes, 0);
  s.reserve(internal::kQuatHeaderBytes + internal::kQuatEntryBytes * nodes.size());
  const uint32_t count = static_cast<uint32_t>(nodes.size());
  std::memcpy(s.data(), &count, sizeof count);
  for (const QuatNode& n : nodes) {
    put_le<uint32_t>(s, n.node);
    for (int16_t r : n.reference) put_le<int16_t>(s, r);
  }
  return s;
}

uint16_t archive_version_major(const EncodedClip& clip) {
  return clip.quat_nodes.empty() ? kFormatVersionMajor : kQuatFormatVersionMajor;
}

std::vector<uint8_t> skel_section(const Skeleton& skel) {
  std::vector<uint8_t> s;
  for (const Joint& j : skel.joints) {
    put_le<uint32_t>(s, static_cast<uint32_t>(j.name.size()));
    put_bytes(s, j.name.data(), j.name.size());
    put_le<int32_t>(s, j.parent);
    for (double o : j.offset) put_le<double>(s, o);
    put_le<uint8_t>(s, j.end_site ? internal::kNodeEndSite : 0);
    put_le<uint8_t>(s, static_cast<uint8_t>(j.channels.size()));
    for (ChannelType t : j.channels) put_le<uint8_t>(s, static_cast<uint8_t>(t));
  }
  return s;
}

std::vector<uint8_t> assemble(const std::vector<Section>& sections, uint16_t major, uint16_t minor, uint32_t flags,
                              size_t checksum_size) {
  size_t total = internal::kHeaderEnd + internal::kTableEntrySize * sections.size() + checksum_size;
  for (const auto& s : sections) total += s.stored.size();
  // Signature and header (section 2) at their offsets: put_le on an empty vector here made
  // GCC 12 warn of an overflow that cannot happen.
  std::vector<uint8_t> out(internal::kHeaderEnd, 0);
  out.reserve(total);
  std::memcpy(out.data(), internal::kSignature, internal::kSignatureSize);
  const uint16_t version[2] = {major, minor};
  const uint32_t header[2] = {flags, static_cast<uint32_t>(sections.size())};  // then Header_Reserved, 0
  std::memcpy(out.data() + 8, version, sizeof version);
  std::memcpy(out.data() + 12, header, sizeof header);
  for (const auto& s : sections) {
    put_le<uint32_t>(out, s.tag);
    put_le<uint32_t>(out, s.flags);
    put_le<uint64_t>(out, s.stored.size());
    put_le<uint64_t>(out, s.raw_size);
  }
  for (const auto& s : sections) put_bytes(out, s.stored.data(), s.stored.size());
  return out;
}

void validate_encoded_clip(const EncodedClip& clip) {
  if (std::string rule = first_broken_rule(clip); !rule.empty()) throw Error(ErrorKind::invalid_argument, rule);
}

std::vector<RawSection> archive_raw_sections(const EncodedClip& clip, std::optional<int> zstd_level) {
  validate_encoded_clip(clip);
  uint64_t keys = 0;
  for (const auto& c : clip.channels) keys += c.frames.size();

  // A level from the caller: that level on every section, with zstd's own parameters for it.
  auto zstd = [&](Zstd measured) {
    return zstd_level ? Zstd{std::min(*zstd_level, ZSTD_maxCLevel()), 0} : measured;
  };
  std::vector<RawSection> raw;
  auto add = [&](uint32_t tag, uint32_t flags, std::vector<uint8_t> bytes, Zstd z) {
    raw.push_back({tag, flags, std::move(bytes), z, {}});
  };
  add(internal::kTagClip, 0, clip_section(clip.frame_count, clip.skeleton, clip.channels.size(), clip.tangent_rule, clip.frame_time, keys), Zstd{});  // 32 bytes: stored raw
  add(internal::kTagSkel, 0, skel_section(clip.skeleton), zstd(kSkelZstd));
  if (!clip.quat_nodes.empty()) add(internal::kTagQuat, 0, quat_section(clip.quat_nodes), zstd(kSkelZstd));
  const ValuePlan plan = plan_values(clip.channels);
  add(internal::kTagChan, 0, chan_section(clip.channels, plan), zstd(kChanZstd));
  Skeleton skeleton = clip.skeleton;
  skeleton.assign_channel_columns();
  add(internal::kTagKtim, 0, ktim_section(clip.channels, internal::stored_kinds(skeleton, clip.quat_nodes)),
      zstd(kKtimZstd));
  // A block per plane: each gets its own entropy tables. (Also compressing without the
  // breaks and keeping the smaller won 0.005% on the CMU clips for a fifth of the encode.)
  std::vector<size_t> breaks;
  add(internal::kTagKval, 0, kval_section(clip.channels, plan, breaks), zstd(kKvalZstd));
  raw.back().breaks = std::move(breaks);
  if (!clip.notes.empty())
    add(internal::kTagNote, internal::kSectionAncillary, {clip.notes.begin(), clip.notes.end()}, zstd(kNoteZstd));
  return raw;
}

namespace {

// The zstd context of the last compress_sections on this thread, kept for the next where its
// tables take at most kKeptContextBytes: made anew for every file, its tables came back as
// page faults each time (glibc returns them to the system when they are freed), half of
// writing a short clip: Bandai run_normal_001 (24 frames) 1.7 -> 0.8 ms, raise-up-both-
// hands_normal_001 (51 frames) 1.2 -> 0.75 ms (write_kanim, median of 15 in one process).
// A context is reset before each section (ZSTD_reset_session_and_parameters, which also
// drops a dictionary), so the bytes do not depend on what it compressed before. A long clip's
// context is freed as before: at most 8 MiB stays (CMU 01_01's is 5.1 MB, 01_03's 7.5 MB;
// 11,008 frames take 14 MB, 44,032 frames 54 MB).
constexpr size_t kKeptContextBytes = size_t(8) << 20;
struct FreeContext {
  void operator()(ZSTD_CCtx* c) const noexcept { ZSTD_freeCCtx(c); }
};
using Context = std::unique_ptr<ZSTD_CCtx, FreeContext>;
Context& kept_context() {
  thread_local Context kept;
  return kept;
}

}  // namespace

std::vector<Section> compress_sections(std::vector<RawSection> raw, std::span<const uint8_t> dictionary) {
  // One section after another, in one zstd context: a context's tables at the higher levels
  // are tens of MB, and two at once made the peak of `keyanim encode -j 2` on a 44,032-frame
  // clip (120 MB against 99 MB with one; the encoder's own peak is 98 MB). KTIM is most of
  // the compression's time, so threads gained little here.
  std::vector<Section> sections(raw.size());
  Context cctx = std::move(kept_context());  // null (no level, or out of memory): stored raw, still a valid file
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i].z.level > 0 && !cctx) cctx.reset(ZSTD_createCCtx());
    sections[i] = make_section(raw[i].tag, raw[i].flags, std::move(raw[i].bytes),
                               raw[i].z.level > 0 ? cctx.get() : nullptr, raw[i].z, raw[i].breaks, dictionary);
  }
  if (cctx && ZSTD_sizeof_CCtx(cctx.get()) <= kKeptContextBytes) kept_context() = std::move(cctx);
  return sections;
}

Section stored_skel(std::vector<uint8_t> skel) {
  std::vector<RawSection> raw(1);
  raw[0] = {internal::kTagSkel, 0, std::move(skel), kSkelZstd, {}};
  return std::move(compress_sections(std::move(raw), {})[0]);
}

std::vector<uint8_t> write_kanim(const EncodedClip& clip, std::optional<int> zstd_level) {
  const std::vector<Section> sections = compress_sections(archive_raw_sections(clip, zstd_level), {});
  std::vector<uint8_t> out = assemble(sections, archive_version_major(clip), 0, 0, internal::kChecksumSize);
  put_le<uint32_t>(out, crc32_of(out.data(), out.size()));
  return out;
}

Clip to_clip(const EncodedClip& clip) {
  internal::ClipSource src;
  src.version_major = archive_version_major(clip);
  src.version_minor = 0;
  src.frame_count = clip.frame_count;
  src.frame_time = clip.frame_time;
  src.rule = clip.tangent_rule;
  src.skeleton = clip.skeleton;
  src.skeleton.assign_channel_columns();
  src.channels.reserve(clip.channels.size());
  size_t keys = 0;  // the key arrays at their size at once: growing them would hold up to 3x
  for (const auto& c : clip.channels) keys += c.frames.size();
  src.frames.reserve(keys);
  src.q.reserve(keys);
  for (const auto& c : clip.channels) {
    internal::SourceChannel sc;
    sc.interp = c.interp;
    sc.tension = c.tension;
    sc.step = c.step;
    sc.first_key = src.frames.size();
    sc.key_count = static_cast<uint32_t>(c.frames.size());
    src.channels.push_back(sc);
    src.frames.insert(src.frames.end(), c.frames.begin(), c.frames.end());
    src.q.insert(src.q.end(), c.q.begin(), c.q.end());
  }
  src.quat_nodes = clip.quat_nodes;
  src.notes = clip.notes;
  return ClipAccess::make(internal::build_image(std::move(src)));
}

}  // namespace keyanim::offline
