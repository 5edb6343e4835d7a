// Opening a bank: the header, where every part lies (section 10.1), the bank's checksum, then
// the names and the name order (10.3) and the dictionary's magic (10.4).
#include "runtime/bank/bank_index.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include <zstd.h>

#include "internal/format.h"
#include "internal/xxh64.h"
#include "internal/zstd_bound.h"
#include "keyanim/version.h"

namespace keyanim::internal {
namespace {

Status fail(ErrorInfo* err, Status s, const char* section, uint64_t offset, std::string detail) {
  if (err != nullptr) *err = ErrorInfo{s, offset, section, std::move(detail)};
  return s;
}

Status check_header(std::span<const uint8_t> bytes, BankIndex& out, ErrorInfo* err) {
  const uint8_t* p = bytes.data();
  const size_t size = bytes.size();
  for (size_t i = 0; i < kSignatureSize; ++i) {
    if (i >= size) return fail(err, Status::truncated, "signature", size, "the file ends inside the signature");
    if (p[i] != kSignature[i]) return fail(err, Status::bad_signature, "signature", i, "not a keyanim bank (signature mismatch)");
  }
  if (size < kBankHeaderSize) return fail(err, Status::truncated, "bank header", size, "the file ends inside the bank header");
  const uint16_t major = load_le<uint16_t>(p + 8);
  const uint32_t flags = load_le<uint32_t>(p + 12);
  // A file of one clip (any version) is named as such rather than as a bank of a bad version.
  if (!(flags & kHeaderBank))
    return fail(err, Status::invalid_argument, "bank header", 12, "a file of one clip, not a bank (Header_Flags bit 2 is clear)");
  if (major != kRuntimeVersionMajor && major != kQuatFormatVersionMajor)
    return fail(err, Status::unsupported_version, "bank header", 8,
                "major version " + std::to_string(major) + " (banks are versions 4 and 5, section 10)");
  out.major = major;
  if (flags & kHeaderReservedMask & ~(kHeaderRuntime | kHeaderMember | kHeaderBank))
    return fail(err, Status::reserved_bits_set, "bank header", 12, "reserved Header_Flags bits are set");
  if (flags & kHeaderMember) return fail(err, Status::corrupt, "bank header", 12, "a bank's header has Header_Flags bit 1 (Member) set");
  out.runtime = (flags & kHeaderRuntime) != 0;
  out.clips = load_le<uint32_t>(p + 16);
  out.skeletons = load_le<uint32_t>(p + 20);
  const uint64_t names = load_le<uint64_t>(p + 24);
  const uint64_t dictionary = load_le<uint64_t>(p + 32);
  if (out.runtime && dictionary != 0)
    return fail(err, Status::corrupt, "bank header", 32, "a runtime-profile bank has no dictionary (Dictionary_Size must be 0)");
  const auto layout = bank_index_layout(out.clips, out.skeletons, names, dictionary, size);
  if (!layout)
    return fail(err, Status::truncated, "bank header", size,
                "the file ends inside the index of " + std::to_string(out.clips) + " clips, " +
                    std::to_string(out.skeletons) + " skeletons, " + std::to_string(names) + " bytes of names and " +
                    std::to_string(dictionary) + " of dictionary");
  out.layout = *layout;
  out.bytes = bytes;
  return Status::ok;
}

// The bytes [from, to) between two parts: at most 7, all zero.
bool zero_padding(std::span<const uint8_t> bytes, uint64_t from, uint64_t to) noexcept {
  return std::all_of(bytes.begin() + std::ptrdiff_t(from), bytes.begin() + std::ptrdiff_t(to), [](uint8_t b) { return b == 0; });
}

// One part placed at the next multiple of 8 after `end` (updated to the part's end): its table
// entry at `entry` holds Offset and (stored) Size. The padding before a member is checked when
// the member is read (check_member_padding), so that opening a bank reads no member's page.
Status place(std::span<const uint8_t> bytes, const uint8_t* entry, uint64_t& end, const char* table, uint32_t i,
             bool padding, ErrorInfo* err) {
  const uint64_t at = static_cast<uint64_t>(entry - bytes.data());
  const uint64_t offset = load_le<uint64_t>(entry), size = load_le<uint64_t>(entry + 8);
  const std::string what = std::string(table) + " entry " + std::to_string(i);
  if (offset != next_part(end))
    return fail(err, Status::corrupt, table, at,
                what + ": Offset " + std::to_string(offset) + ", not " + std::to_string(next_part(end)) +
                    " (each part starts at the next multiple of 8 after the one before)");
  if (offset > bytes.size() || size > bytes.size() - offset)
    return fail(err, Status::truncated, table, at + 8, what + ": the file ends before its " + std::to_string(size) + " bytes");
  if (padding && !zero_padding(bytes, end, offset))
    return fail(err, Status::corrupt, "padding", end, what + ": padding before it is not zero");
  end = offset + size;
  return Status::ok;
}

// Skeleton s's flags and sizes (10.3): a compressed one's Raw_Size within what its stored bytes
// can make (section 8), an uncompressed one's equal to them.
Status check_skeleton_entry(const BankIndex& idx, uint32_t s, ErrorInfo* err) {
  const uint8_t* e = idx.bytes.data() + idx.layout.skeleton_table + uint64_t(s) * kBankSkeletonEntrySize;
  const uint64_t at = static_cast<uint64_t>(e - idx.bytes.data());
  const BankIndex::Skeleton k = idx.skeleton(s);
  const std::string what = "skeleton " + std::to_string(s);
  if ((load_le<uint32_t>(e + 24) & kSkeletonReservedMask) != 0 || load_le<uint32_t>(e + 28) != 0)
    return fail(err, Status::reserved_bits_set, "skeleton table", at + 24, what + ": reserved Skeleton_Flags bits or Skeleton_Reserved set");
  if (k.stored == 0 || k.raw == 0)
    return fail(err, Status::corrupt, "skeleton table", at + 8, what + ": size 0 (a skeleton is a SKEL section's content)");
  if (!k.compressed && k.raw != k.stored)
    return fail(err, Status::corrupt, "skeleton table", at + 16, what + ": uncompressed, but Raw_Size != Stored_Size");
  if (k.compressed && k.raw > kMaxZstdExpansion * k.stored)  // stored < 2^48: exact
    return fail(err, Status::zstd_error, "skeleton table", at + 16,
                what + ": Raw_Size " + std::to_string(k.raw) + " is more than its " + std::to_string(k.stored) + " stored bytes can make");
  return Status::ok;
}

// Skeletons, the checksum and the members, each where section 10.1 puts it; the checksum.
Status check_placement(const BankIndex& idx, ErrorInfo* err) {
  const std::span<const uint8_t> bytes = idx.bytes;
  if (!zero_padding(bytes, idx.layout.names_end, idx.layout.dictionary))
    return fail(err, Status::corrupt, "padding", idx.layout.names_end, "the padding after the names is not zero");
  uint64_t end = idx.layout.dictionary_end;
  for (uint32_t s = 0; s < idx.skeletons; ++s) {
    const uint8_t* e = bytes.data() + idx.layout.skeleton_table + uint64_t(s) * kBankSkeletonEntrySize;
    if (Status st = place(bytes, e, end, "skeleton table", s, true, err); st != Status::ok) return st;
    if (Status st = check_skeleton_entry(idx, s, err); st != Status::ok) return st;
  }
  const uint64_t checksum_at = next_part(end);
  if (checksum_at > bytes.size() || bytes.size() - checksum_at < kBankChecksumSize)
    return fail(err, Status::truncated, "bank checksum", bytes.size(), "the file ends before the bank's checksum");
  if (!zero_padding(bytes, end, checksum_at)) return fail(err, Status::corrupt, "padding", end, "the padding before the checksum is not zero");
  end = checksum_at + kBankChecksumSize;
  for (uint32_t i = 0; i < idx.clips; ++i)
    if (Status st = place(bytes, idx.clip_at(i), end, "clip table", i, false, err); st != Status::ok) return st;
  if (end != bytes.size())
    return fail(err, Status::trailing_bytes, "bank", end, std::to_string(bytes.size() - end) + " bytes after the last clip");
  if (xxh64_of(bytes.data(), checksum_at) != load_le<uint64_t>(bytes.data() + checksum_at))
    return fail(err, Status::checksum_mismatch, "bank checksum", checksum_at,
                "XXH64 of the bank's header, index, dictionary and skeletons does not match its checksum");
  return Status::ok;
}

}  // namespace

std::string bank_name_problem(std::string_view name) {
  if (name.empty() || name.size() > kMaxBankNameBytes) return "Name_Size must be 1 to 1024";
  if (name.find('\0') != std::string_view::npos) return "a name holds no byte 0";
  for (size_t from = 0;;) {
    const size_t to = std::min(name.find('/', from), name.size());
    const std::string_view part = name.substr(from, to - from);
    if (part.empty() || part == "." || part == "..") return "no part of a name between '/' is empty, '.' or '..'";
    if (to == name.size()) return "";
    from = to + 1;
  }
}

namespace {

Status check_names(const BankIndex& idx, ErrorInfo* err) {
  const uint64_t names_size = idx.layout.names_end - idx.layout.names;
  for (uint32_t i = 0; i < idx.clips; ++i) {
    const uint8_t* e = idx.clip_at(i);
    const uint64_t at = static_cast<uint64_t>(e - idx.bytes.data());
    const uint64_t name_offset = load_le<uint32_t>(e + 32), name_size = load_le<uint32_t>(e + 36);
    if (load_le<uint32_t>(e + 28) >= idx.skeletons)
      return fail(err, Status::corrupt, "clip table", at + 28,
                  "clip " + std::to_string(i) + ": skeleton " + std::to_string(load_le<uint32_t>(e + 28)) + " of " +
                      std::to_string(idx.skeletons));
    if (name_offset > names_size || name_size > names_size - name_offset)
      return fail(err, Status::corrupt, "clip table", at + 32, "clip " + std::to_string(i) + ": its name lies outside the name pool");
    if (std::string p = bank_name_problem(idx.name(e)); !p.empty())
      return fail(err, Status::corrupt, "clip table", at + 32, "clip " + std::to_string(i) + ": " + p);
  }
  std::vector<bool> listed(idx.clips);  // bounded: the clip table fits in the file
  for (uint32_t k = 0; k < idx.clips; ++k) {
    const uint64_t at = idx.layout.name_order + uint64_t(k) * kBankOrderEntrySize;
    const uint32_t i = idx.order(k);
    if (i >= idx.clips || listed[i])
      return fail(err, Status::corrupt, "name order", at, "the name order must list every clip once");
    listed[i] = true;
    if (k > 0 && !(idx.name(idx.clip_at(idx.order(k - 1))) < idx.name(idx.clip_at(i))))
      return fail(err, Status::corrupt, "name order", at,
                  "names must be in strictly increasing order (clip " + std::to_string(i) +
                      (idx.name(idx.clip_at(idx.order(k - 1))) == idx.name(idx.clip_at(i)) ? ": a second clip of its name)" : ")"));
  }
  return Status::ok;
}

}  // namespace

Status check_member_padding(const BankIndex& idx, uint32_t i, ErrorInfo* err) {
  const BankEntry e = idx.entry(i);
  // The part before member 0 is the checksum: it ends at a multiple of 8, so member 0 has none.
  const uint64_t end = i == 0 ? e.offset : idx.entry(i - 1).offset + idx.entry(i - 1).size;
  if (!zero_padding(idx.bytes, end, e.offset))
    return fail(err, Status::corrupt, "padding", end, "clip table entry " + std::to_string(i) + ": padding before it is not zero");
  return Status::ok;
}

Status skeleton_content(const BankIndex& idx, uint32_t s, uint64_t& limit, std::vector<uint8_t>& out, ErrorInfo* err) {
  const BankIndex::Skeleton k = idx.skeleton(s);
  const uint8_t* src = idx.bytes.data() + k.offset;
  const std::string what = "skeleton " + std::to_string(s);
  if (k.raw > limit)
    return fail(err, Status::limit_exceeded, "skeleton table", idx.layout.skeleton_table + uint64_t(s) * kBankSkeletonEntrySize + 16,
                "the bank's skeletons exceed the limit of decompressed bytes");
  limit -= k.raw;
  if (!k.compressed) {
    out.assign(src, src + k.stored);
    return Status::ok;
  }
  // As a compressed section (3.2.5): one frame declaring Raw_Size, whose blocks can make it.
  const size_t stored = static_cast<size_t>(k.stored);
  const std::optional<uint64_t> bound = zstd_frame_output_bound(src, stored);
  if (stored < 4 || load_le<uint32_t>(src) != kZstdMagic || ZSTD_getFrameContentSize(src, stored) != k.raw ||
      ZSTD_findFrameCompressedSize(src, stored) != stored || !bound || *bound < k.raw)
    return fail(err, Status::zstd_error, "skeleton", k.offset, what + ": not one zstd frame of Raw_Size bytes");
  out.resize(static_cast<size_t>(k.raw));
  const size_t got = ZSTD_decompress(out.data(), out.size(), src, stored);
  if (ZSTD_isError(got) || got != k.raw)
    return fail(err, Status::zstd_error, "skeleton", k.offset, what + ": zstd: " + (ZSTD_isError(got) ? ZSTD_getErrorName(got) : "wrong size"));
  return Status::ok;
}

Status check_bank_index(std::span<const uint8_t> bytes, BankIndex& out, ErrorInfo* err) {
  if (err != nullptr) *err = ErrorInfo{};
  Status s = check_header(bytes, out, err);
  if (s == Status::ok) s = check_placement(out, err);
  if (s == Status::ok) s = check_names(out, err);
  const std::span<const uint8_t> dict = s == Status::ok ? out.dictionary() : std::span<const uint8_t>{};
  if (s == Status::ok && !dict.empty() && (dict.size() < 8 || load_le<uint32_t>(dict.data()) != kZstdDictionaryMagic))
    s = fail(err, Status::corrupt, "dictionary", out.layout.dictionary, "not a zstd dictionary (RFC 8878 section 5)");
  if (s != Status::ok) out = BankIndex{};
  return s;
}

}  // namespace keyanim::internal
