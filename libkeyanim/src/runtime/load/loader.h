// The loader's parts (internal to load/): the section table, each section's parsing, and the
// key values of every format version. Every rule of spec/FORMAT.md is checked once, in the
// order of its section 7, before anything a file declares is allocated; the sampler then
// trusts the arrays. load.cpp drives them (Loader::run) and is the public door (Clip::load).
#pragma once
#include <zstd.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "internal/clip_source.h"
#include "internal/quat_layout.h"
#include "internal/value_coding.h"
#include "keyanim/clip.h"
#include "runtime/image_layout.h"
#include "runtime/rig.h"

namespace keyanim::internal {

// "CLIP", or '?' for bytes that are not printable.
std::string tag_name(uint32_t tag);

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

// A bank's member (spec/FORMAT.md section 10.5): its skeleton is the bank's (`skel`, at
// `skel_offset` in the bank), its compressed sections are made with `dictionary` (or none), and
// failures are reported at offsets from the bank's first byte (the member starts at
// `member_offset`).
struct MemberContext {
  std::span<const uint8_t> skel;
  uint64_t skel_offset = 0;
  bool skel_compressed = false;  // stored as a zstd frame: offsets in it are of its content
  uint64_t member_offset = 0;
  const ZSTD_DDict* dictionary = nullptr;
  bool runtime = false;  // the bank's profile, which its members must have
  uint16_t bank_major = 4;  // a member's major version is at most the bank's (section 10.5)
};

class Loader {
 public:
  Loader(std::span<const uint8_t> bytes, const DecodeLimits& limits, ErrorInfo* err)
      : bytes_(bytes), limits_(limits), err_(err) {}

  // The archive profile: every section into `parts`. The runtime profile: CLIP, SKEL and NOTE
  // into `parts` (no keys), IMAG checked (section 9.4's structure rules) and left in image().
  Status run(ClipSource& parts);  // load.cpp
  bool runtime() const noexcept { return runtime_; }
  // The runtime profile with a rig cache: a SKEL the cache has seen is not parsed; its rig is
  // rig() (else null, and the parsed skeleton is in `parts`). skel(): SKEL's bytes.
  void use_rigs(RigCache* rigs) noexcept { rigs_ = rigs; }
  // The bytes are a bank's member (they must say so: section 10.5), read with `m` (which must
  // outlive run()).
  void use_member(const MemberContext* m) noexcept { member_ = m; }
  const std::shared_ptr<const Rig>& rig() const noexcept { return rig_; }
  std::span<const uint8_t> skel() const noexcept { return {skel_.data, skel_.size}; }
  uint64_t key_count() const noexcept { return key_count_; }
  std::span<const uint8_t> image() const noexcept { return {imag_.data, imag_.size}; }

 private:
  Status fail(Status s, const char* section, uint64_t offset, std::string detail) {
    if (err_ != nullptr) {
      err_->status = s;
      err_->section = section;
      // A member's offsets from the bank's first byte. (The bank's skeleton lies before the
      // member: its content's offset is stored as skel_offset - member_offset, which wraps
      // as u64, and this sum wraps back.)
      err_->byte_offset = offset + (member_ != nullptr ? member_->member_offset : 0);
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
  // Spec section 8: a compressed section's Raw_Size against the most its Stored_Size can make
  // (internal::kMaxZstdExpansion), after the raw-size limit and before the checksum: a small
  // file declaring a large section is refused from the table (zstd_error, as inflating it would be).
  Status check_expansion();
  // `critical` (0..5: CLIP..KVAL, then QUAT at kQuatSlot; -1 for NOTE) bounds a compressed
  // section's Raw_Size by check_declared_size once its zstd frame header is checked, before it
  // is inflated.
  Status get_content(const TableEntry& e, const char* name, Content& out, int critical = -1,
                     const ClipSource* parts = nullptr);
  // Before a compressed critical section is inflated (get_content): its Raw_Size against what the sections
  // before it fix (CLIP 32 bytes, SKEL and KTIM at least a record or a byte per node or key,
  // KTIM at most 5 bytes a key, CHAN and 3.x KVAL exactly), failing as the parse of the
  // inflated content would: a declared size cannot make the loader inflate what it then refuses.
  Status check_declared_size(const TableEntry& e, int critical, const ClipSource& parts);
  // KVAL's size in 3.x: each channel's keys times its Residual_Bytes (CHAN parsed).
  uint64_t kval_fixed_bytes(const ClipSource& parts) const noexcept;
  Status parse_clip(const Content& c, ClipSource& parts);
  Status parse_skel(const Content& c, ClipSource& parts);
  Status parse_quat(const Content& c, ClipSource& parts);  // 5.x
  Status parse_chan(const Content& c, ClipSource& parts);
  Status parse_ktim(const Content& c, ClipSource& parts);
  Status parse_kval(const Content& c, ClipSource& parts);        // 1.x and 2.x: varint planes
  Status parse_kval_fixed(const Content& c, ClipSource& parts);  // 3.x: fixed-width byte planes
  // IMAG (image_check.cpp): the header, the channels, then the curves and lists, then the records.
  Status check_image(const Content& c, const ClipSource& parts, const Skeleton& skeleton);
  Status check_image_curves(const Content& c, const ImageLayout& lay, const ImageCounts& n, const ClipSource& parts);
  Status check_image_quats(const Content& c, const ImageLayout& lay, const ImageCounts& n, const ClipSource& parts,
                           const Skeleton& skeleton);
  Status check_shared_frames(const Content& c, const ImageLayout& lay, const ImageCounts& n, uint64_t ch, uint64_t x);
  Status check_image_records(const Content& c, const ImageLayout& lay, const ImageCounts& n, const ClipSource& parts);
  Status run_runtime(ClipSource& parts);  // run() for the runtime profile
  // A member's skeleton as SKEL's content (MemberContext); else table entry `index`'s.
  Status get_skel(int index, Content& out);
  // Header_Flags: the reserved bits, and Member/Bank against how the bytes are read.
  Status check_header_flags(uint16_t major, uint32_t flags);
  // Turns channel ch's residual r (of key i, found at section offset at) into q, checking the
  // bounds of section 4.5; q and q_prev carry the previous two.
  Status residual_to_q(const Content& c, size_t at, size_t ch, uint32_t i, uint64_t zigzag, int64_t& q,
                       int64_t& q_prev, ClipSource& parts);

  std::span<const uint8_t> bytes_;
  const DecodeLimits& limits_;
  ErrorInfo* err_;

  uint16_t major_ = 0;
  uint16_t minor_ = 0;
  bool runtime_ = false;  // the runtime profile (Header_Flags bit 0, version 4)
  Content imag_;          // its IMAG, once checked
  Content skel_;          // its SKEL
  RigCache* rigs_ = nullptr;
  const MemberContext* member_ = nullptr;
  std::shared_ptr<const Rig> rig_;
  std::vector<TableEntry> table_;
  // Table index of CLIP, SKEL, CHAN, KTIM, KVAL, QUAT (kQuatSlot; 5.x archive); runtime: CLIP,
  // IMAG, SKEL.
  int critical_index_[6] = {-1, -1, -1, -1, -1, -1};
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
  // From QUAT and CHAN (5.x): what each channel stores, and the key frames KTIM holds (a
  // quaternion node's y and z share its x's).
  std::vector<Stored> kinds_;
  uint64_t time_count_ = 0;
};

}  // namespace keyanim::internal
