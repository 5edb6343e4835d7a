// A bank's layout (spec/FORMAT.md section 10.1): the sizes of its parts and where each one
// starts, for the writer that places them and the reader that checks them, so that the two can
// never disagree on an offset.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>

namespace keyanim::internal {

inline constexpr size_t kBankHeaderSize = 40;
inline constexpr size_t kBankSkeletonEntrySize = 32;  // Offset, Stored_Size, Raw_Size, Skeleton_Flags, reserved
inline constexpr uint32_t kSkeletonCompressed = 1u << 0;     // Skeleton_Flags
inline constexpr uint32_t kSkeletonReservedMask = 0x0000FFFEu;
inline constexpr size_t kBankClipEntrySize = 40;      // Offset, Size, Frame_Time, Frame_Count, Skeleton, Name_Offset, Name_Size
inline constexpr size_t kBankOrderEntrySize = 4;
inline constexpr size_t kBankChecksumSize = 8;  // XXH64
inline constexpr uint32_t kMaxBankNameBytes = 1024;
inline constexpr uint16_t kBankVersionMinor = 1;        // banks are version 4.1
inline constexpr uint32_t kZstdDictionaryMagic = 0xEC30A437u;  // RFC 8878 section 5

// The next multiple of 8 at or after `end` (a part's start). `end` is at most a file's size.
constexpr uint64_t next_part(uint64_t end) noexcept { return (end + 7) & ~uint64_t(7); }

// Where the index's parts start, from the header's counts: the skeleton table at 40, then the
// clip table, the name order and the names, then the dictionary at the next multiple of 8.
struct BankIndexLayout {
  uint64_t skeleton_table = kBankHeaderSize;
  uint64_t clip_table = 0;
  uint64_t name_order = 0;
  uint64_t names = 0;
  uint64_t names_end = 0;
  uint64_t dictionary = 0;
  uint64_t dictionary_end = 0;
};

// Nothing if the parts do not fit in `file_size` bytes (computed without overflow: a count of
// 2^32 - 1 clips is refused here, before anything it sizes is allocated).
constexpr std::optional<BankIndexLayout> bank_index_layout(uint32_t clips, uint32_t skeletons, uint64_t names_size,
                                                           uint64_t dictionary_size, uint64_t file_size) noexcept {
  BankIndexLayout l;
  l.clip_table = l.skeleton_table + uint64_t(skeletons) * kBankSkeletonEntrySize;  // < 2^37
  l.name_order = l.clip_table + uint64_t(clips) * kBankClipEntrySize;              // < 2^39
  l.names = l.name_order + uint64_t(clips) * kBankOrderEntrySize;
  if (l.names > file_size || names_size > file_size - l.names) return std::nullopt;
  l.names_end = l.names + names_size;
  l.dictionary = next_part(l.names_end);
  if (l.dictionary > file_size || dictionary_size > file_size - l.dictionary) return std::nullopt;
  l.dictionary_end = l.dictionary + dictionary_size;
  return l;
}

}  // namespace keyanim::internal
