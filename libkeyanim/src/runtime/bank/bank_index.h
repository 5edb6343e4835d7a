// A bank's index (spec/FORMAT.md sections 10.1 to 10.4), checked once when the bank opens and
// then read in place: entries are decoded from the bytes on demand, so that opening a bank of
// many clips allocates nothing per clip.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "internal/bank_layout.h"
#include "internal/byte_reader.h"
#include "keyanim/bank.h"
#include "keyanim/status.h"

namespace keyanim::internal {

struct BankIndex {
  std::span<const uint8_t> bytes;
  uint32_t clips = 0;
  uint32_t skeletons = 0;
  uint16_t major = 0;  // 4, or 5 when a member may be of version 5
  bool runtime = false;
  BankIndexLayout layout;

  const uint8_t* clip_at(uint32_t i) const noexcept { return bytes.data() + layout.clip_table + uint64_t(i) * kBankClipEntrySize; }
  BankEntry entry(uint32_t i) const noexcept {
    const uint8_t* p = clip_at(i);
    BankEntry e;
    e.offset = load_le<uint64_t>(p);
    e.size = load_le<uint64_t>(p + 8);
    e.frame_time = load_le<double>(p + 16);
    e.frame_count = load_le<uint32_t>(p + 24);
    e.skeleton = load_le<uint32_t>(p + 28);
    e.name = name(p);
    return e;
  }
  std::string_view name(const uint8_t* clip_entry) const noexcept {
    return {reinterpret_cast<const char*>(bytes.data() + layout.names + load_le<uint32_t>(clip_entry + 32)),
            load_le<uint32_t>(clip_entry + 36)};
  }
  uint32_t order(uint32_t k) const noexcept {
    return load_le<uint32_t>(bytes.data() + layout.name_order + uint64_t(k) * kBankOrderEntrySize);
  }
  // Skeleton s's entry: where its stored bytes lie, its raw size and whether it is compressed.
  struct Skeleton {
    uint64_t offset = 0, stored = 0, raw = 0;
    bool compressed = false;
  };
  Skeleton skeleton(uint32_t s) const noexcept {
    const uint8_t* p = bytes.data() + layout.skeleton_table + uint64_t(s) * kBankSkeletonEntrySize;
    return {load_le<uint64_t>(p), load_le<uint64_t>(p + 8), load_le<uint64_t>(p + 16),
            (load_le<uint32_t>(p + 24) & kSkeletonCompressed) != 0};
  }
  std::span<const uint8_t> dictionary() const noexcept {
    return bytes.subspan(layout.dictionary, layout.dictionary_end - layout.dictionary);
  }
};

// Why `name` breaks section 10.3's rules for a clip's name, or "" if it keeps them.
std::string bank_name_problem(std::string_view name);

// Every rule of sections 10.1 to 10.4 that needs no member, in the spec's order: header, the
// tables' sizes and offsets, the padding of the index and skeletons, the bank's checksum, then
// names, name order, skeleton indexes, the skeletons' flags and sizes and the dictionary's
// magic. Time in proportion to the clips and the name pool; no member's page is read.
Status check_bank_index(std::span<const uint8_t> bytes, BankIndex& out, ErrorInfo* err);

// Skeleton s's content (inflated when it is compressed: section 10.3), or a failure at its
// place. `limit`: the most bytes all skeletons may inflate to, lowered by this one's size.
Status skeleton_content(const BankIndex& idx, uint32_t s, uint64_t& limit, std::vector<uint8_t>& out, ErrorInfo* err);

// The padding before member i (the zero bytes between the part before it and its Offset).
Status check_member_padding(const BankIndex& idx, uint32_t i, ErrorInfo* err);

}  // namespace keyanim::internal
