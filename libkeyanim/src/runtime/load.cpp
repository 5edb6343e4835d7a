// Loading a .kanim file: every rule of spec/FORMAT.md is checked once, here, in the order of
// its section 7, before anything a file declares is allocated; the sampler then trusts the
// arrays.
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "internal/byte_reader.h"
#include "internal/format.h"
#include "internal/value_coding.h"
#include "internal/zstd_bound.h"
#include "internal/varint.h"
#include "internal/clip_source.h"
#include "keyanim/clip.h"
#include "keyanim/version.h"
#include "runtime/clip_access.h"
#include "runtime/image.h"

namespace keyanim {
namespace {

using internal::ByteReader;
using internal::ClipSource;

std::string tag_name(uint32_t tag) {
  std::string s(4, '?');
  for (int i = 0; i < 4; ++i) {
    const char ch = static_cast<char>((tag >> (8 * i)) & 0xFF);
    s[static_cast<size_t>(i)] = (ch >= 0x20 && ch < 0x7F) ? ch : '?';
  }
  return s;
}

struct TableEntry {
  uint32_t tag = 0;
  uint32_t flags = 0;
  uint64_t stored = 0;
  uint64_t raw = 0;
  uint64_t file_offset = 0;   // where the stored bytes start
  uint64_t entry_offset = 0;  // where the table entry starts
};

// A section's raw content and how to turn an offset in it into an offset in the file.
struct Content {
  const uint8_t* data = nullptr;
  size_t size = 0;
  uint64_t file_offset = 0;
  bool compressed = false;
  const char* name = "";
};

struct DctxDeleter {
  void operator()(ZSTD_DCtx* d) const noexcept { ZSTD_freeDCtx(d); }
};

class Loader {
 public:
  Loader(std::span<const uint8_t> bytes, const DecodeLimits& limits, ErrorInfo* err)
      : bytes_(bytes), limits_(limits), err_(err) {}

  Status run(ClipSource& parts);

 private:
  Status fail(Status s, const char* section, uint64_t offset, std::string detail) {
    if (err_ != nullptr) {
      err_->status = s;
      err_->section = section;
      err_->byte_offset = offset;
      err_->detail = std::move(detail);
    }
    return s;
  }
  // Failure at offset `at` of a section's content.
  Status fail_in(Status s, const Content& c, size_t at, std::string detail) {
    if (c.compressed)
      return fail(s, c.name, c.file_offset,
                  detail + " (at byte " + std::to_string(at) + " of the decompressed section)");
    return fail(s, c.name, c.file_offset + at, std::move(detail));
  }

  Status read_header_and_table();
  Status get_content(const TableEntry& e, const char* name, Content& out);
  Status parse_clip(const Content& c, ClipSource& parts);
  Status parse_skel(const Content& c, ClipSource& parts);
  Status parse_chan(const Content& c, ClipSource& parts);
  Status parse_ktim(const Content& c, ClipSource& parts);
  Status parse_kval(const Content& c, ClipSource& parts);        // 1.x and 2.x: varint planes
  Status parse_kval_fixed(const Content& c, ClipSource& parts);  // 3.x: fixed-width byte planes
  // Turns channel ch's residual r (of key i, found at section offset at) into q, checking the
  // bounds of section 4.5; q and q_prev carry the previous two.
  Status residual_to_q(const Content& c, size_t at, size_t ch, uint32_t i, uint64_t zigzag, int64_t& q,
                       int64_t& q_prev, ClipSource& parts);

  std::span<const uint8_t> bytes_;
  const DecodeLimits& limits_;
  ErrorInfo* err_;

  uint16_t major_ = 0;
  uint16_t minor_ = 0;
  std::vector<TableEntry> table_;
  int critical_index_[5] = {-1, -1, -1, -1, -1};  // table index of CLIP..KVAL
  int note_index_ = -1;
  std::unique_ptr<ZSTD_DCtx, DctxDeleter> dctx_;
  // Decompressed sections, alive until parsed. Not zero-filled: a small file declaring a large
  // section must not make the loader touch (commit) that memory before zstd has produced it.
  std::vector<std::unique_ptr<uint8_t[]>> buffers_;

  // From CLIP.
  uint64_t key_count_ = 0;
  uint32_t node_count_ = 0;
  uint32_t channel_count_ = 0;
  // From CHAN, needed by KVAL.
  std::vector<internal::ValueCoding> codings_;  // all delta in 1.x
  std::vector<uint8_t> residual_bytes_;         // 3.x
};

Status Loader::read_header_and_table() {
  const uint8_t* p = bytes_.data();
  const size_t size = bytes_.size();
  for (size_t i = 0; i < internal::kSignatureSize; ++i) {
    if (i >= size) return fail(Status::truncated, "signature", size, "the file ends inside the signature");
    if (p[i] != internal::kSignature[i])
      return fail(Status::bad_signature, "signature", i, "not a .kanim file (signature mismatch)");
  }
  if (size < internal::kHeaderEnd) return fail(Status::truncated, "header", size, "the file ends inside the header");
  ByteReader r(p, size);
  r.skip(internal::kSignatureSize);
  uint16_t major = 0;
  uint32_t header_flags = 0, section_count = 0, reserved = 0;
  r.read(major);
  r.read(minor_);
  r.read(header_flags);
  r.read(section_count);
  r.read(reserved);
  if (major < kOldestFormatVersionMajor || major > kFormatVersionMajor)
    return fail(Status::unsupported_version, "header", 8,
                "major version " + std::to_string(major) + " (this decoder reads versions " +
                    std::to_string(kOldestFormatVersionMajor) + " to " + std::to_string(kFormatVersionMajor) + ")");
  major_ = major;
  if (header_flags & internal::kHeaderReservedMask)
    return fail(Status::reserved_bits_set, "header", 12, "reserved Header_Flags bits are set");
  if (reserved != 0) return fail(Status::reserved_bits_set, "header", 20, "Header_Reserved is not 0");

  // The table and the checksum must fit: 24 * count + 4 <= size - 24, in subtraction form.
  const size_t avail = size - internal::kHeaderEnd;
  if (avail < internal::kChecksumSize ||
      section_count > (avail - internal::kChecksumSize) / internal::kTableEntrySize)
    return fail(Status::truncated, "table", size,
                "the file ends inside the section table of " + std::to_string(section_count) + " entries");
  table_.resize(section_count);  // bounded by the file size just checked
  uint64_t pos = internal::kHeaderEnd + uint64_t(section_count) * internal::kTableEntrySize;
  size_t next_critical = 0;
  for (uint32_t i = 0; i < section_count; ++i) {
    TableEntry& e = table_[i];
    e.entry_offset = internal::kHeaderEnd + uint64_t(i) * internal::kTableEntrySize;
    r.read(e.tag);
    r.read(e.flags);
    r.read(e.stored);
    r.read(e.raw);
    e.file_offset = pos;
    const std::string name = "section " + std::to_string(i) + " (" + tag_name(e.tag) + ")";
    if (e.flags & internal::kSectionReservedMask)
      return fail(Status::reserved_bits_set, "table", e.entry_offset + 4, name + ": reserved Section_Flags bits are set");
    const bool ancillary = (e.flags & internal::kSectionAncillary) != 0;
    size_t crit = 5;
    for (size_t k = 0; k < 5; ++k)
      if (internal::kCriticalTags[k] == e.tag) crit = k;
    if (crit < 5) {
      if (ancillary) return fail(Status::corrupt, "table", e.entry_offset + 4, name + ": a critical section marked ancillary");
      if (crit != next_critical)
        return fail(Status::corrupt, "table", e.entry_offset,
                    name + ": critical sections must be CLIP, SKEL, CHAN, KTIM, KVAL, once each, in this order");
      critical_index_[crit] = static_cast<int>(i);
      ++next_critical;
    } else if (e.tag == internal::kTagNote) {
      if (!ancillary) return fail(Status::corrupt, "table", e.entry_offset + 4, name + ": NOTE must be ancillary");
      if (note_index_ >= 0) return fail(Status::corrupt, "table", e.entry_offset, name + ": a second NOTE section");
      note_index_ = static_cast<int>(i);
    } else if (!ancillary) {
      return fail(Status::reserved_bits_set, "table", e.entry_offset,
                  name + ": unknown critical section (this decoder does not know the tag)");
    }
    if (!(e.flags & internal::kSectionCompressed) && e.stored != e.raw)
      return fail(Status::corrupt, "table", e.entry_offset + 8, name + ": uncompressed, but Stored_Size != Raw_Size");
    if (e.stored > size - pos)
      return fail(Status::truncated, "table", size, name + ": the file ends before the section's declared end");
    pos += e.stored;
  }
  if (next_critical != 5)
    return fail(Status::corrupt, "table", internal::kHeaderEnd,
                std::string("missing critical section ") + tag_name(internal::kCriticalTags[next_critical]));
  if (size - pos < internal::kChecksumSize) return fail(Status::truncated, "checksum", size, "the file ends inside the checksum");
  if (size - pos > internal::kChecksumSize)
    return fail(Status::trailing_bytes, "checksum", pos + internal::kChecksumSize,
                std::to_string(size - pos - internal::kChecksumSize) + " bytes after the checksum");

  // Everything this decoder will decompress or copy, before anything is.
  uint64_t raw_total = 0;
  for (uint32_t i = 0; i < section_count; ++i) {
    const TableEntry& e = table_[i];
    const bool known = e.tag == internal::kTagNote || !(e.flags & internal::kSectionAncillary);
    if (!known) continue;
    if (e.raw > limits_.max_decompressed_bytes - raw_total || e.raw > limits_.max_decompressed_bytes)
      return fail(Status::limit_exceeded, "table", e.entry_offset + 16,
                  "decompressed sections exceed the limit of " + std::to_string(limits_.max_decompressed_bytes) + " bytes");
    raw_total += e.raw;
  }

  uLong crc = crc32(0L, Z_NULL, 0);
  for (uint64_t done = 0; done < pos;) {
    const uInt chunk = static_cast<uInt>(std::min<uint64_t>(pos - done, 1u << 30));
    crc = crc32(crc, p + done, chunk);
    done += chunk;
  }
  const uint32_t stored_crc = internal::load_le<uint32_t>(p + pos);
  if (static_cast<uint32_t>(crc) != stored_crc)
    return fail(Status::checksum_mismatch, "checksum", pos, "CRC-32 of the file does not match its checksum");
  return Status::ok;
}

Status Loader::get_content(const TableEntry& e, const char* name, Content& out) {
  out.name = name;
  out.file_offset = e.file_offset;
  const uint8_t* src = bytes_.data() + e.file_offset;
  const size_t stored = static_cast<size_t>(e.stored);  // <= file size
  if (!(e.flags & internal::kSectionCompressed)) {
    out.data = src;
    out.size = stored;
    return Status::ok;
  }
  out.compressed = true;
  if (stored < 4 || internal::load_le<uint32_t>(src) != internal::kZstdMagic)
    return fail(Status::zstd_error, name, e.file_offset, "not a zstd frame");
  const unsigned long long declared = ZSTD_getFrameContentSize(src, stored);
  if (declared == ZSTD_CONTENTSIZE_ERROR) return fail(Status::zstd_error, name, e.file_offset, "bad zstd frame header");
  if (declared == ZSTD_CONTENTSIZE_UNKNOWN)
    return fail(Status::zstd_error, name, e.file_offset, "the zstd frame does not declare its content size");
  if (declared != e.raw)
    return fail(Status::zstd_error, name, e.file_offset,
                "the zstd frame declares " + std::to_string(declared) + " bytes, Raw_Size is " + std::to_string(e.raw));
  const size_t frame = ZSTD_findFrameCompressedSize(src, stored);
  if (ZSTD_isError(frame) || frame != stored)
    return fail(Status::zstd_error, name, e.file_offset, "Stored_Size is not exactly one zstd frame");
  if (e.raw > std::numeric_limits<size_t>::max())
    return fail(Status::limit_exceeded, name, e.file_offset, "section too large for this platform");
  // Allocate Raw_Size only when the frame's blocks can produce it (zip-bomb headers).
  const std::optional<uint64_t> bound = internal::zstd_frame_output_bound(src, stored);
  if (!bound) return fail(Status::zstd_error, name, e.file_offset, "bad zstd block headers");
  if (*bound < e.raw)
    return fail(Status::zstd_error, name, e.file_offset,
                "the zstd frame's blocks can produce at most " + std::to_string(*bound) + " bytes, Raw_Size is " +
                    std::to_string(e.raw));
  if (!dctx_) {
    dctx_.reset(ZSTD_createDCtx());
    if (!dctx_) return fail(Status::zstd_error, name, e.file_offset, "cannot create a zstd context");
  }
  buffers_.emplace_back(new uint8_t[static_cast<size_t>(e.raw) + 1]);  // +1: valid when raw is 0
  uint8_t* buf = buffers_.back().get();
  const size_t got = ZSTD_decompressDCtx(dctx_.get(), buf, static_cast<size_t>(e.raw), src, stored);
  if (ZSTD_isError(got))
    return fail(Status::zstd_error, name, e.file_offset, std::string("zstd: ") + ZSTD_getErrorName(got));
  if (got != e.raw) return fail(Status::zstd_error, name, e.file_offset, "the zstd frame decompressed to the wrong size");
  out.data = buf;
  out.size = got;
  return Status::ok;
}

Status Loader::parse_clip(const Content& c, ClipSource& parts) {
  if (c.size != internal::kClipSize)
    return fail_in(Status::corrupt, c, 0, "CLIP must be 32 bytes, not " + std::to_string(c.size));
  ByteReader r(c.data, c.size);
  uint32_t frames = 0;
  uint8_t rule = 0, flags = 0;
  uint16_t reserved = 0;
  double frame_time = 0;
  r.read(frames);
  r.read(node_count_);
  r.read(channel_count_);
  r.read(rule);
  r.read(flags);
  r.read(reserved);
  r.read(frame_time);
  r.read(key_count_);
  if (major_ >= 3 && frames > internal::kMaxFrames)
    return fail_in(Status::corrupt, c, 0, "Frame_Count " + std::to_string(frames) + " is above 2^24");
  if (frames > std::min(limits_.max_frames, internal::kMaxFrames))
    return fail_in(Status::limit_exceeded, c, 0, "Frame_Count " + std::to_string(frames) + " exceeds the limit");
  if (node_count_ > limits_.max_joints)
    return fail_in(Status::limit_exceeded, c, 4, "Node_Count " + std::to_string(node_count_) + " exceeds the limit");
  if (channel_count_ > limits_.max_channels)
    return fail_in(Status::limit_exceeded, c, 8, "Channel_Count " + std::to_string(channel_count_) + " exceeds the limit");
  if (rule > internal::kMaxTangentRule)
    return fail_in(Status::reserved_bits_set, c, 12, "reserved Tangent_Rule " + std::to_string(rule));
  if (flags != 0) return fail_in(Status::reserved_bits_set, c, 13, "reserved Clip_Flags bits are set");
  if (reserved != 0) return fail_in(Status::reserved_bits_set, c, 14, "Clip_Reserved is not 0");
  if (!std::isfinite(frame_time) || frame_time < 0.0 || (frames > 1 && !(frame_time > 0.0)))
    return fail_in(Status::corrupt, c, 16, "Frame_Time must be finite, >= 0, and > 0 when Frame_Count > 1");
  if (key_count_ > limits_.max_keys)
    return fail_in(Status::limit_exceeded, c, 24, "Key_Count " + std::to_string(key_count_) + " exceeds the limit");
  if (key_count_ > UINT32_MAX)
    return fail_in(Status::limit_exceeded, c, 24, "this decoder holds fewer than 2^32 keys");
  if (key_count_ > uint64_t(channel_count_) * frames)
    return fail_in(Status::corrupt, c, 24, "Key_Count exceeds Channel_Count x Frame_Count");
  parts.frame_count = frames;
  parts.frame_time = frame_time;
  parts.rule = static_cast<TangentRule>(rule);
  return Status::ok;
}

Status Loader::parse_skel(const Content& c, ClipSource& parts) {
  if (node_count_ > c.size / internal::kNodeFixedBytes)
    return fail_in(Status::corrupt, c, 0,
                   "SKEL is too short for " + std::to_string(node_count_) + " nodes");
  auto& joints = parts.skeleton.joints;
  joints.resize(node_count_);
  ByteReader r(c.data, c.size);
  uint64_t channel_sum = 0;
  for (uint32_t i = 0; i < node_count_; ++i) {
    Joint& j = joints[i];
    const std::string node = "node " + std::to_string(i) + ": ";
    const size_t start = r.pos();
    uint32_t name_len = 0;
    const uint8_t* name = nullptr;
    if (!r.read(name_len) || !r.bytes(name_len, name))
      return fail_in(Status::corrupt, c, start, node + "the name runs past the end of SKEL");
    j.name.assign(reinterpret_cast<const char*>(name), name_len);
    const size_t fixed = r.pos();
    if (r.remaining() < internal::kNodeFixedBytes - 4)
      return fail_in(Status::corrupt, c, fixed, node + "the record runs past the end of SKEL");
    uint8_t flags = 0, count = 0;
    r.read(j.parent);
    for (double& o : j.offset) r.read(o);
    r.read(flags);
    r.read(count);
    if (j.parent < -1 || (j.parent >= 0 && static_cast<uint32_t>(j.parent) >= i))
      return fail_in(Status::corrupt, c, fixed, node + "Parent must be -1 or an earlier node");
    if (j.parent >= 0 && joints[static_cast<size_t>(j.parent)].end_site)
      return fail_in(Status::corrupt, c, fixed, node + "the parent is an End Site");
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(j.offset[static_cast<size_t>(k)]))
        return fail_in(Status::corrupt, c, fixed + 4 + 8 * static_cast<size_t>(k), node + "Offset is not finite");
    if (flags & internal::kNodeReservedMask)
      return fail_in(Status::reserved_bits_set, c, fixed + 28, node + "reserved Node_Flags bits are set");
    j.end_site = (flags & internal::kNodeEndSite) != 0;
    if (j.end_site && j.parent < 0) return fail_in(Status::corrupt, c, fixed, node + "an End Site must have a parent");
    if (count > internal::kMaxNodeChannels)
      return fail_in(Status::corrupt, c, fixed + 29, node + "more than 6 channels");
    if (j.end_site && count != 0) return fail_in(Status::corrupt, c, fixed + 29, node + "an End Site has channels");
    const uint8_t* types = nullptr;
    if (!r.bytes(count, types))
      return fail_in(Status::corrupt, c, fixed + 30, node + "the channel list runs past the end of SKEL");
    j.channels.resize(count);
    for (uint32_t k = 0; k < count; ++k) {
      if (types[k] > internal::kMaxChannelType)
        return fail_in(Status::reserved_bits_set, c, fixed + 30 + k,
                       node + "reserved channel type " + std::to_string(types[k]));
      j.channels[k] = static_cast<ChannelType>(types[k]);
    }
    channel_sum += count;
  }
  if (!r.at_end()) return fail_in(Status::corrupt, c, r.pos(), "bytes after the last node record");
  if (channel_sum != channel_count_)
    return fail_in(Status::corrupt, c, 0,
                   "the nodes have " + std::to_string(channel_sum) + " channels, CLIP says " + std::to_string(channel_count_));
  parts.skeleton.assign_channel_columns();
  return Status::ok;
}

Status Loader::parse_chan(const Content& c, ClipSource& parts) {
  const uint64_t channels = channel_count_;
  const size_t per_channel = major_ >= 3   ? internal::kChanBytesPerChannel
                             : major_ == 2 ? internal::kChanBytesPerChannelV2
                                           : internal::kChanBytesPerChannelV1;
  if (c.size != channels * per_channel)
    return fail_in(Status::corrupt, c, 0, "CHAN must be " + std::to_string(per_channel) + " x Channel_Count bytes");
  const uint8_t* p = c.data;
  parts.channels.resize(channels);
  codings_.assign(channels, internal::ValueCoding::delta);
  residual_bytes_.assign(channels, 0);
  uint64_t key_sum = 0;
  for (uint64_t i = 0; i < channels; ++i) {
    const std::string ch = "channel " + std::to_string(i) + ": ";
    const size_t at_interp = i, at_tension = channels + 4 * i, at_step = 5 * channels + 8 * i,
                 at_count = 13 * channels + 4 * i;
    const uint8_t interp = p[at_interp];
    const float tension = internal::load_le<float>(p + at_tension);
    const double step = internal::load_le<double>(p + at_step);
    const uint32_t count = internal::load_le<uint32_t>(p + at_count);
    if (interp > internal::kMaxInterpolation)
      return fail_in(Status::reserved_bits_set, c, at_interp, ch + "reserved Interpolation " + std::to_string(interp));
    if (!std::isfinite(tension) || tension < -1.0f || tension > 1.0f)
      return fail_in(Status::corrupt, c, at_tension, ch + "Tension must be finite and in [-1, 1]");
    if (!std::isfinite(step) || !(step > 0.0))
      return fail_in(Status::corrupt, c, at_step, ch + "Step must be finite and > 0");
    if (count > parts.frame_count)
      return fail_in(Status::corrupt, c, at_count, ch + "more keys than frames");
    if (major_ >= 2) {
      const size_t at_coding = 17 * channels + i;
      if (p[at_coding] > internal::kMaxValueCoding)
        return fail_in(Status::reserved_bits_set, c, at_coding, ch + "reserved Value_Coding " + std::to_string(p[at_coding]));
      codings_[i] = static_cast<internal::ValueCoding>(p[at_coding]);
    }
    if (major_ >= 3) {
      const size_t at_bytes = 18 * channels + i;
      residual_bytes_[i] = p[at_bytes];
      if (residual_bytes_[i] > internal::kMaxResidualBytes || (count == 0 && residual_bytes_[i] != 0))
        return fail_in(Status::corrupt, c, at_bytes, ch + "Residual_Bytes must be at most 8, and 0 without keys");
    }
    internal::SourceChannel& t = parts.channels[i];
    t.first_key = key_sum;
    t.key_count = count;
    t.interp = static_cast<Interpolation>(interp);
    t.tension = tension;
    t.step = step;
    key_sum += count;
    if (key_sum > key_count_)
      return fail_in(Status::corrupt, c, at_count, ch + "the channels' Key_Count add up to more than CLIP's");
  }
  if (key_sum != key_count_)
    return fail_in(Status::corrupt, c, 13 * channels, "the channels' Key_Count add up to less than CLIP's");
  return Status::ok;
}

const char* varint_problem(internal::VarintError e) {
  switch (e) {
    case internal::VarintError::cut: return "a varint runs past the end of the section";
    case internal::VarintError::overlong: return "an over-long varint";
    case internal::VarintError::too_big: return "a varint too large for its field";
    case internal::VarintError::none: break;
  }
  return "";
}

Status Loader::parse_ktim(const Content& c, ClipSource& parts) {
  if (key_count_ > c.size) return fail_in(Status::corrupt, c, 0, "KTIM is too short for Key_Count varints");
  parts.frames.resize(static_cast<size_t>(key_count_));
  uint32_t* out = parts.frames.data();
  const uint64_t frames = parts.frame_count;
  size_t pos = 0;
  for (size_t ch = 0; ch < parts.channels.size(); ++ch) {
    const internal::SourceChannel& t = parts.channels[ch];
    uint64_t frame = 0;
    for (uint32_t i = 0; i < t.key_count; ++i) {
      const size_t at = pos;
      uint64_t v = 0;
      if (pos < c.size && c.data[pos] < 0x80) {
        v = c.data[pos++];  // the usual one-byte gap
      } else {
        const auto e = internal::get_varint(c.data, c.size, pos, internal::kMaxVarint32Bytes, v);
        if (e != internal::VarintError::none) return fail_in(Status::corrupt, c, at, varint_problem(e));
      }
      frame = i == 0 ? v : frame + v + 1;  // < 2^33: no overflow
      if (frame >= frames)
        return fail_in(Status::corrupt, c, at,
                       "channel " + std::to_string(ch) + ": key frame " + std::to_string(frame) + " >= Frame_Count");
      out[t.first_key + i] = static_cast<uint32_t>(frame);
    }
  }
  if (pos != c.size) return fail_in(Status::corrupt, c, pos, "bytes after the last key frame");
  return Status::ok;
}

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

Status Loader::run(ClipSource& parts) {
  Status s = read_header_and_table();
  if (s != Status::ok) return s;
  parts.version_major = major_;
  parts.version_minor = minor_;
  // Sections in table order (the critical ones are in order by now); unknown ancillary
  // sections are skipped without being decompressed.
  for (size_t i = 0; i < table_.size(); ++i) {
    const TableEntry& e = table_[i];
    Content c;
    if (static_cast<int>(i) == note_index_) {
      if ((s = get_content(e, "NOTE", c)) != Status::ok) return s;
      parts.notes.assign(reinterpret_cast<const char*>(c.data), c.size);
    } else {
      for (int k = 0; k < 5; ++k) {
        if (critical_index_[k] != static_cast<int>(i)) continue;
        switch (k) {
          case 0: s = get_content(e, "CLIP", c); if (s == Status::ok) s = parse_clip(c, parts); break;
          case 1: s = get_content(e, "SKEL", c); if (s == Status::ok) s = parse_skel(c, parts); break;
          case 2: s = get_content(e, "CHAN", c); if (s == Status::ok) s = parse_chan(c, parts); break;
          case 3: s = get_content(e, "KTIM", c); if (s == Status::ok) s = parse_ktim(c, parts); break;
          default:
            s = get_content(e, "KVAL", c);
            if (s == Status::ok) s = major_ >= 3 ? parse_kval_fixed(c, parts) : parse_kval(c, parts);
            break;
        }
        if (s != Status::ok) return s;
      }
    }
    buffers_.clear();  // a decompressed section is not needed once parsed
  }
  return Status::ok;
}

}  // namespace

Status Clip::load(std::span<const uint8_t> bytes, Clip& out, ErrorInfo* err, const DecodeLimits& limits) {
  out = Clip{};
  if (err != nullptr) *err = ErrorInfo{};
  try {
    ClipSource parts;
    Loader loader(bytes, limits, err);
    const Status s = loader.run(parts);
    if (s != Status::ok) return s;
    out = ClipAccess::make(internal::build_image(std::move(parts)));
  } catch (const std::bad_alloc&) {
    out = Clip{};
    if (err != nullptr) {
      err->status = Status::limit_exceeded;
      err->section = "file";
      err->byte_offset = 0;
      err->detail = "out of memory";
    }
    return Status::limit_exceeded;
  }
  return Status::ok;
}

Status Clip::load_file(const std::string& path, Clip& out, ErrorInfo* err, const DecodeLimits& limits) {
  out = Clip{};
  auto io_fail = [&](Status s, std::string detail) {
    if (err != nullptr) *err = ErrorInfo{s, 0, "file", path + ": " + detail};
    return s;
  };
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) return io_fail(Status::io_error, "cannot open");
  if (std::fseek(f.get(), 0, SEEK_END) != 0) return io_fail(Status::io_error, "cannot seek");
  const long end = std::ftell(f.get());
  if (end < 0 || std::fseek(f.get(), 0, SEEK_SET) != 0) return io_fail(Status::io_error, "cannot tell its size");
  if (static_cast<unsigned long>(end) > limits.max_decompressed_bytes)
    return io_fail(Status::limit_exceeded, "larger than max_decompressed_bytes");
  std::vector<uint8_t> bytes;
  try {
    bytes.resize(static_cast<size_t>(end));
  } catch (const std::bad_alloc&) {
    return io_fail(Status::limit_exceeded, "out of memory");
  }
  if (!bytes.empty() && std::fread(bytes.data(), 1, bytes.size(), f.get()) != bytes.size())
    return io_fail(Status::io_error, "read error");
  return load(bytes, out, err, limits);
}

}  // namespace keyanim
