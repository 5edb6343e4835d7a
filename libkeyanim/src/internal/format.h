// Constants of the .kanim container (spec/FORMAT.md), shared by the writer and the loader so
// that the two can never disagree on a tag, a size or a flag bit.
#pragma once
#include <cstddef>
#include <cstdint>

namespace keyanim::internal {

inline constexpr uint8_t kSignature[8] = {0x89, 'K', 'A', 'N', 0x0D, 0x0A, 0x1A, 0x0A};
inline constexpr size_t kSignatureSize = 8;
inline constexpr size_t kHeaderEnd = 24;       // signature + 16-byte header
inline constexpr size_t kTableEntrySize = 24;  // tag, flags, stored size, raw size
inline constexpr size_t kChecksumSize = 4;         // CRC-32 (the archive profile)
inline constexpr size_t kRuntimeChecksumSize = 8;  // XXH64 (the runtime profile, section 9.1)

// Header_Flags: bits 0-15 reserved (reject), bits 16-31 unused (ignore); from version 4, bit 0
// is Runtime (the runtime profile, section 9).
inline constexpr uint32_t kHeaderReservedMask = 0x0000FFFFu;
inline constexpr uint32_t kHeaderRuntime = 1u << 0;
// From version 4.1 (section 10): bit 1 Member (a bank's clip), bit 2 Bank (a bank's header).
inline constexpr uint32_t kHeaderMember = 1u << 1;
inline constexpr uint32_t kHeaderBank = 1u << 2;
inline constexpr uint16_t kRuntimeVersionMajor = 4;  // the first version with the runtime profile
// Section_Flags.
inline constexpr uint32_t kSectionCompressed = 1u << 0;
inline constexpr uint32_t kSectionAncillary = 1u << 1;
inline constexpr uint32_t kSectionReservedMask = 0x0000FFFCu;  // bits 2-15; 16-31 unused

// A tag is four bytes in file order, read as a little-endian u32.
constexpr uint32_t make_tag(char a, char b, char c, char d) noexcept {
  return uint32_t(uint8_t(a)) | uint32_t(uint8_t(b)) << 8 | uint32_t(uint8_t(c)) << 16 |
         uint32_t(uint8_t(d)) << 24;
}
inline constexpr uint32_t kTagClip = make_tag('C', 'L', 'I', 'P');
inline constexpr uint32_t kTagSkel = make_tag('S', 'K', 'E', 'L');
inline constexpr uint32_t kTagChan = make_tag('C', 'H', 'A', 'N');
inline constexpr uint32_t kTagKtim = make_tag('K', 'T', 'I', 'M');
inline constexpr uint32_t kTagKval = make_tag('K', 'V', 'A', 'L');
inline constexpr uint32_t kTagNote = make_tag('N', 'O', 'T', 'E');
inline constexpr uint32_t kTagImag = make_tag('I', 'M', 'A', 'G');
inline constexpr uint32_t kTagQuat = make_tag('Q', 'U', 'A', 'T');  // version 5 (section 4.7)
// The critical sections, in the order a file must list them: the archive profile's, and the
// runtime profile's (entries 0 and 1 exactly, so that IMAG starts 8-aligned: section 9.1).
inline constexpr uint32_t kCriticalTags[5] = {kTagClip, kTagSkel, kTagChan, kTagKtim, kTagKval};
inline constexpr uint32_t kRuntimeTags[3] = {kTagClip, kTagImag, kTagSkel};
// A bank's member has no SKEL (section 10.5): the archive profile's critical sections without
// it (kMemberSlots: their places in kCriticalTags), and the runtime profile's first two.
inline constexpr uint32_t kMemberTags[4] = {kTagClip, kTagChan, kTagKtim, kTagKval};
inline constexpr int kMemberSlots[4] = {0, 2, 3, 4};
// Version 5's archive profile adds QUAT after SKEL (kQuatSlot: its index among the loader's
// critical sections, after kCriticalTags' five); a member's has no SKEL.
inline constexpr int kQuatSlot = 5;
inline constexpr uint32_t kCriticalTagsV5[6] = {kTagClip, kTagSkel, kTagQuat, kTagChan, kTagKtim, kTagKval};
inline constexpr int kCriticalSlotsV5[6] = {0, 1, kQuatSlot, 2, 3, 4};
inline constexpr uint32_t kMemberTagsV5[5] = {kTagClip, kTagQuat, kTagChan, kTagKtim, kTagKval};
inline constexpr int kMemberSlotsV5[5] = {0, kQuatSlot, 2, 3, 4};
inline constexpr size_t kQuatHeaderBytes = 4;  // Quat_Count
inline constexpr size_t kQuatEntryBytes = 10;  // Node u32, Reference i16[3]

inline constexpr size_t kClipSize = 32;
inline constexpr size_t kNodeFixedBytes = 34;     // name length, parent, offset, flags, count
inline constexpr size_t kChanBytesPerChannel = 19;    // u8 + f32 + f64 + u32 + u8 + u8 (3.0)
inline constexpr size_t kChanBytesPerChannelV2 = 18;  // 2.x: no Residual_Bytes
inline constexpr size_t kChanBytesPerChannelV1 = 17;  // 1.x: no Value_Coding either
inline constexpr uint32_t kMaxResidualBytes = 8;      // zigzag residuals are below 2^58
inline constexpr uint8_t kNodeEndSite = 1u << 0;
inline constexpr uint8_t kNodeReservedMask = 0xFEu;
inline constexpr uint32_t kMaxNodeChannels = 6;
inline constexpr uint8_t kMaxChannelType = 5;
inline constexpr uint8_t kMaxTangentRule = 1;
inline constexpr uint8_t kMaxInterpolation = 1;

inline constexpr int64_t kMaxAbsQ = int64_t(1) << 53;      // |q| bound
inline constexpr uint64_t kMaxAbsDelta = uint64_t(1) << 54;  // 1.x: |q_i - q_{i-1}| bound
inline constexpr uint32_t kMaxVarint32Bytes = 5;
inline constexpr uint32_t kMaxVarint64Bytes = 10;

inline constexpr uint32_t kZstdMagic = 0xFD2FB528u;

// Spec section 8, limits that follow from the file's size. No zstd frame makes more than 32768
// bytes of each of its bytes: a block produces at most 128 KiB, and the cheapest, an RLE block,
// takes 4 bytes (3 of header, 1 repeated); a Compressed block producing as much takes more, the
// frame header more still. An uncompressed section is its own size. So a valid file of N bytes
// has at most 32768 N bytes of sections, and (a key taking at least one byte of KTIM's content,
// its varint) at most 32768 N keys. Checked on the counts before anything they size, with the
// status the file would fail with later (zstd_error, corrupt): the refusal is only earlier.
inline constexpr uint64_t kMaxZstdExpansion = 32768;
inline constexpr uint64_t kMaxKeysPerFileByte = kMaxZstdExpansion;
// From version 5 a key frame of KTIM is shared by a quaternion node's three curves.
inline constexpr uint64_t kMaxKeysPerFileByteV5 = 3 * kMaxZstdExpansion;

}  // namespace keyanim::internal
