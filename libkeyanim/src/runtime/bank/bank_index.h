// A bank's index (spec/FORMAT.md sections 10.1 to 10.4), checked once when the bank opens and
// then read in place: entries are decoded from the bytes on demand, so that opening a bank of
// many clips allocates nothing per clip.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "internal/bank_layout.h"
#include "internal/byte_reader.h"
#include "keyanim/bank.h"
#include "keyanim/status.h"

namespace keyanim::internal {

struct BankIndex {
  std::span<const uint8_t> bytes;
  uint32_t clips = 0;
  uint32_t skeletons = 0;
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
  std::span<const uint8_t> skeleton(uint32_t s, uint64_t& offset) const noexcept {
    const uint8_t* p = bytes.data() + layout.skeleton_table + uint64_t(s) * kBankSkeletonEntrySize;
    offset = load_le<uint64_t>(p);
    return bytes.subspan(offset, load_le<uint64_t>(p + 8));
  }
  std::span<const uint8_t> dictionary() const noexcept {
    return bytes.subspan(layout.dictionary, layout.dictionary_end - layout.dictionary);
  }
};

// Why `name` breaks section 10.3's rules for a clip's name, or "" if it keeps them.
std::string bank_name_problem(std::string_view name);

// Every rule of sections 10.1 to 10.4 that needs no member, in the spec's order: header, the
// tables' sizes and offsets, padding, the bank's checksum, then names, name order, skeleton
// indexes and the dictionary's magic. Time in proportion to the clips and the name pool.
Status check_bank_index(std::span<const uint8_t> bytes, BankIndex& out, ErrorInfo* err);

}  // namespace keyanim::internal
