// The header, the section table, the checksum, and a section's content (zstd-decompressed when
// it is stored so, with every declared size checked before anything is allocated).
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <limits>
#include <optional>

#include "internal/byte_reader.h"
#include "internal/format.h"
#include "internal/varint.h"
#include "internal/xxh64.h"
#include "internal/zstd_bound.h"
#include "keyanim/version.h"
#include "runtime/load/loader.h"

namespace keyanim::internal {

std::string tag_name(uint32_t tag) {
  std::string s(4, '?');
  for (int i = 0; i < 4; ++i) {
    const char ch = static_cast<char>((tag >> (8 * i)) & 0xFF);
    s[static_cast<size_t>(i)] = (ch >= 0x20 && ch < 0x7F) ? ch : '?';
  }
  return s;
}

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
  if (major < kOldestFormatVersionMajor || major > kNewestFormatVersionMajor)
    return fail(Status::unsupported_version, "header", 8,
                "major version " + std::to_string(major) + " (this decoder reads versions " +
                    std::to_string(kOldestFormatVersionMajor) + " to " + std::to_string(kNewestFormatVersionMajor) + ")");
  major_ = major;
  runtime_ = major >= internal::kRuntimeVersionMajor && (header_flags & internal::kHeaderRuntime) != 0;
  if (Status s = check_header_flags(major, header_flags); s != Status::ok) return s;
  if (reserved != 0) return fail(Status::reserved_bits_set, "header", 20, "Header_Reserved is not 0");

  // The table and the checksum must fit: 24 * count + 4 (8) <= size - 24, in subtraction form.
  const size_t avail = size - internal::kHeaderEnd;
  const size_t checksum_size = runtime_ ? internal::kRuntimeChecksumSize : internal::kChecksumSize;
  // A bank's member has no SKEL (section 10.5).
  const bool member = member_ != nullptr;
  const bool v5 = major >= kQuatFormatVersionMajor && !runtime_;  // QUAT after SKEL (section 4.7)
  const uint32_t* critical_tags = runtime_ ? internal::kRuntimeTags
                                  : v5     ? (member ? internal::kMemberTagsV5 : internal::kCriticalTagsV5)
                                           : (member ? internal::kMemberTags : internal::kCriticalTags);
  const int* critical_slots = v5 ? (member ? internal::kMemberSlotsV5 : internal::kCriticalSlotsV5)
                                 : member && !runtime_ ? internal::kMemberSlots : nullptr;
  const size_t critical_count = runtime_ ? (member ? 2 : 3) : (member ? 4 : 5) + (v5 ? 1 : 0);
  const char* const archive_rule =
      v5 ? (member ? ": a member's critical sections must be CLIP, QUAT, CHAN, KTIM, KVAL, once each, in this order"
                   : ": critical sections must be CLIP, SKEL, QUAT, CHAN, KTIM, KVAL, once each, in this order")
         : (member ? ": a member's critical sections must be CLIP, CHAN, KTIM, KVAL, once each, in this order"
                   : ": critical sections must be CLIP, SKEL, CHAN, KTIM, KVAL, once each, in this order");
  const std::string runtime_rule = member ? ": a runtime-profile member's sections must be CLIP and IMAG, entries 0 and 1"
                                          : ": the runtime profile's sections must be CLIP, IMAG and SKEL, entries 0, 1 and 2";
  if (avail < checksum_size ||
      section_count > (avail - checksum_size) / internal::kTableEntrySize)
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
    size_t crit = critical_count;
    for (size_t k = 0; k < critical_count; ++k)
      if (critical_tags[k] == e.tag) crit = k;
    if (member && e.tag == internal::kTagSkel)
      return fail(Status::corrupt, "table", e.entry_offset, name + ": a bank's member holds no SKEL (its skeleton is the bank's)");
    if (runtime_ && (e.flags & internal::kSectionCompressed))
      return fail(Status::corrupt, "table", e.entry_offset + 4, name + ": no section of the runtime profile is compressed");
    // The archive's critical sections, whatever their flags; QUAT only from version 5 on (before,
    // an unknown tag: skipped if ancillary, else reserved_bits_set below).
    const bool known = e.tag != internal::kTagQuat || major >= kQuatFormatVersionMajor;
    if (runtime_ && crit == critical_count && e.tag != internal::kTagNote && known)
      for (uint32_t tag : internal::kCriticalTagsV5)
        if (tag == e.tag) return fail(Status::corrupt, "table", e.entry_offset, name + ": the runtime profile holds no " + tag_name(tag));
    if (runtime_ && i < critical_count && e.tag != critical_tags[i])
      return fail(Status::corrupt, "table", e.entry_offset, name + runtime_rule);
    if (crit < critical_count) {
      if (ancillary) return fail(Status::corrupt, "table", e.entry_offset + 4, name + ": a critical section marked ancillary");
      if (crit != next_critical || (runtime_ && i != crit))
        return fail(Status::corrupt, "table", e.entry_offset, name + (runtime_ ? runtime_rule : archive_rule));
      critical_index_[critical_slots ? critical_slots[crit] : static_cast<int>(crit)] = static_cast<int>(i);
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
  if (next_critical != critical_count)
    return fail(Status::corrupt, "table", internal::kHeaderEnd,
                std::string("missing critical section ") + tag_name(critical_tags[next_critical]));
  if (size - pos < checksum_size) return fail(Status::truncated, "checksum", size, "the file ends inside the checksum");
  if (size - pos > checksum_size)
    return fail(Status::trailing_bytes, "checksum", pos + checksum_size,
                std::to_string(size - pos - checksum_size) + " bytes after the checksum");

  // Everything this decoder will decompress or copy, before anything is (a member's skeleton
  // counts as its SKEL: rule 10.5.3).
  uint64_t raw_total = member ? member_->skel.size() : 0;
  if (raw_total > limits_.max_decompressed_bytes)
    return fail(Status::limit_exceeded, "SKEL", member_->skel_offset - member_->member_offset,
                "the bank's skeleton exceeds the limit of " + std::to_string(limits_.max_decompressed_bytes) + " bytes");
  for (uint32_t i = 0; i < section_count; ++i) {
    const TableEntry& e = table_[i];
    const bool known = e.tag == internal::kTagNote || !(e.flags & internal::kSectionAncillary);
    if (!known) continue;
    if (e.raw > limits_.max_decompressed_bytes - raw_total || e.raw > limits_.max_decompressed_bytes)
      return fail(Status::limit_exceeded, "table", e.entry_offset + 16,
                  "decompressed sections exceed the limit of " + std::to_string(limits_.max_decompressed_bytes) + " bytes");
    if (e.tag == internal::kTagNote && e.raw > limits_.max_note_bytes)
      return fail(Status::limit_exceeded, "table", e.entry_offset + 16,
                  "NOTE declares " + std::to_string(e.raw) + " bytes, above the limit of " +
                      std::to_string(limits_.max_note_bytes) + " (notes are informative text)");
    raw_total += e.raw;
  }
  if (Status s = check_expansion(); s != Status::ok) return s;

  if (runtime_) {
    if (internal::xxh64_of(p, pos) != internal::load_le<uint64_t>(p + pos))
      return fail(Status::checksum_mismatch, "checksum", pos, "XXH64 of the file does not match its checksum");
    return Status::ok;
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

Status Loader::check_header_flags(uint16_t major, uint32_t flags) {
  const uint32_t known =
      major >= internal::kRuntimeVersionMajor ? internal::kHeaderRuntime | internal::kHeaderMember | internal::kHeaderBank : 0u;
  if (flags & internal::kHeaderReservedMask & ~known)
    return fail(Status::reserved_bits_set, "header", 12, "reserved Header_Flags bits are set");
  const bool member = (flags & internal::kHeaderMember) != 0;
  if (member_ == nullptr && (flags & internal::kHeaderBank))
    return fail(Status::invalid_argument, "header", 12,
                "a bank of many clips (spec section 10), not a clip: open it with keyanim::Bank");
  if (member_ == nullptr && member)
    return fail(Status::corrupt, "header", 12, "a bank's member (Header_Flags bit 1), which only its bank reads");
  if (member_ != nullptr && (!member || (flags & internal::kHeaderBank)))
    return fail(Status::corrupt, "header", 12, "a bank's clip must have Header_Flags bit 1 (Member) set and bit 2 (Bank) clear");
  if (member_ != nullptr && runtime_ != member_->runtime)
    return fail(Status::corrupt, "header", 12, "a bank's clips are of the bank's profile (Header_Flags bit 0)");
  if (member_ != nullptr && major > member_->bank_major)
    return fail(Status::corrupt, "header", 8, "a member of version " + std::to_string(major) + " in a bank of version " +
                                                  std::to_string(member_->bank_major));
  return Status::ok;
}

Status Loader::check_expansion() {
  for (size_t i = 0; i < table_.size(); ++i) {
    const TableEntry& e = table_[i];
    const bool known = e.tag == internal::kTagNote || !(e.flags & internal::kSectionAncillary);
    // stored <= file size < 2^48: the product is exact.
    if (known && (e.flags & internal::kSectionCompressed) && e.raw > internal::kMaxZstdExpansion * e.stored)
      return fail(Status::zstd_error, "table", e.entry_offset + 16,
                  "section " + std::to_string(i) + " (" + tag_name(e.tag) + "): Raw_Size " + std::to_string(e.raw) +
                      " is more than its " + std::to_string(e.stored) + " stored bytes can make (a zstd frame makes at most " +
                      std::to_string(internal::kMaxZstdExpansion) + " bytes of each)");
  }
  return Status::ok;
}

Status Loader::get_content(const TableEntry& e, const char* name, Content& out, int critical, const ClipSource* parts) {
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
  if (critical >= 0 && parts != nullptr)
    if (Status s = check_declared_size(e, critical, *parts); s != Status::ok) return s;
  if (!dctx_) {
    dctx_.reset(ZSTD_createDCtx());
    if (!dctx_) return fail(Status::zstd_error, name, e.file_offset, "cannot create a zstd context");
  }
  buffers_.emplace_back(new uint8_t[static_cast<size_t>(e.raw) + 1]);  // +1: valid when raw is 0
  uint8_t* buf = buffers_.back().get();
  const ZSTD_DDict* dict = member_ != nullptr ? member_->dictionary : nullptr;  // section 10.4
  const size_t got = dict != nullptr ? ZSTD_decompress_usingDDict(dctx_.get(), buf, static_cast<size_t>(e.raw), src, stored, dict)
                                     : ZSTD_decompressDCtx(dctx_.get(), buf, static_cast<size_t>(e.raw), src, stored);
  if (ZSTD_isError(got))
    return fail(Status::zstd_error, name, e.file_offset, std::string("zstd: ") + ZSTD_getErrorName(got));
  if (got != e.raw) return fail(Status::zstd_error, name, e.file_offset, "the zstd frame decompressed to the wrong size");
  out.data = buf;
  out.size = got;
  return Status::ok;
}

Status Loader::get_skel(int index, Content& out) {
  if (member_ == nullptr) return get_content(table_[static_cast<size_t>(index)], "SKEL", out);
  out.name = "SKEL";
  out.data = member_->skel.data();
  out.size = member_->skel.size();
  out.file_offset = member_->skel_offset - member_->member_offset;  // wraps: fail() adds it back
  out.compressed = member_->skel_compressed;
  return Status::ok;
}

Status Loader::check_declared_size(const TableEntry& e, int critical, const ClipSource& parts) {
  if (!(e.flags & kSectionCompressed)) return Status::ok;  // nothing to inflate: the parse checks
  static const char* const kNames[6] = {"CLIP", "SKEL", "CHAN", "KTIM", "KVAL", "QUAT"};
  Content c;  // where a failure is reported: the section's stored bytes, as after inflating
  c.name = kNames[critical];
  c.file_offset = e.file_offset;
  c.compressed = true;
  const uint64_t raw = e.raw;
  switch (critical) {
    case 0:
      if (raw != kClipSize) return fail_in(Status::corrupt, c, 0, "CLIP must be 32 bytes, not " + std::to_string(raw));
      break;
    case 1:
      if (node_count_ > raw / kNodeFixedBytes)
        return fail_in(Status::corrupt, c, 0, "SKEL is too short for " + std::to_string(node_count_) + " nodes");
      break;
    case 2: {
      const uint64_t per = major_ >= 3 ? kChanBytesPerChannel : major_ == 2 ? kChanBytesPerChannelV2 : kChanBytesPerChannelV1;
      if (raw != uint64_t(channel_count_) * per)
        return fail_in(Status::corrupt, c, 0, "CHAN must be " + std::to_string(per) + " x Channel_Count bytes");
      break;
    }
    case 3:
      if (time_count_ > raw) return fail_in(Status::corrupt, c, 0, "KTIM is too short for its key frames' varints");
      if (raw > time_count_ * kMaxVarint32Bytes)
        return fail_in(Status::corrupt, c, 0, "KTIM is longer than its key frames' varints of at most 5 bytes can be");
      break;
    case kQuatSlot:
      if (raw < kQuatHeaderBytes || (raw - kQuatHeaderBytes) % kQuatEntryBytes != 0 ||
          (raw - kQuatHeaderBytes) / kQuatEntryBytes > node_count_)
        return fail_in(Status::corrupt, c, 0, "QUAT must be 4 + 10 x Quat_Count bytes, Quat_Count at most Node_Count");
      break;
    default:
      if (major_ >= 3 && raw != kval_fixed_bytes(parts))
        return fail_in(Status::corrupt, c, 0, "KVAL must hold " + std::to_string(kval_fixed_bytes(parts)) +
                                                   " bytes (the channels' keys times their Residual_Bytes)");
      if (major_ < 3 && raw > 1 + 4 * uint64_t(kMaxVarint64Bytes) + key_count_ * kMaxVarint64Bytes)
        return fail_in(Status::corrupt, c, 0, "KVAL is longer than Key_Count varints of at most 10 bytes can be");
      break;
  }
  return Status::ok;
}

}  // namespace keyanim::internal
