// A bank: many clips in one file, each distinct skeleton once (spec/FORMAT.md section 10). It
// opens from its index alone (no clip is read), finds a clip by position in O(1) and by name in
// O(log n), and gives its clips as ordinary Clips: a runtime-profile bank's clips are sampled
// where they lie in the bank's bytes, and the clips of one skeleton share one rig. Each clip has
// its own checksum: a damaged clip fails with its name while the others load.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "keyanim/clip.h"
#include "keyanim/status.h"

namespace keyanim {

// A clip's entry in the bank's index.
struct BankEntry {
  std::string_view name;  // valid as long as the bank (or a clip of it) holds the bytes
  uint32_t frame_count = 0;
  double frame_time = 0.0;  // seconds
  uint32_t skeleton = 0;    // index of its skeleton in the bank
  uint64_t offset = 0;      // the clip's bytes in the bank
  uint64_t size = 0;
};

class Bank {
 public:
  Bank();  // empty: no clips
  ~Bank();
  Bank(const Bank&);
  Bank& operator=(const Bank&);
  Bank(Bank&&) noexcept;
  Bank& operator=(Bank&&) noexcept;

  // Checks the header, the index and the bank's checksum (section 10.1 to 10.4), in time
  // proportional to the clips and their names; no clip is read. On failure `out` is left empty
  // and `err` says where (an offset from the bank's first byte). open() copies `bytes`;
  // view() keeps pointers into them, which must be 8-aligned (invalid_argument otherwise) and
  // stay alive and unchanged as long as the bank or any clip taken from it; open_file() maps
  // the file read-only (so only the pages read are resident) and the bank and its clips keep
  // the mapping.
  static Status open(std::span<const uint8_t> bytes, Bank& out, ErrorInfo* err = nullptr);
  static Status view(std::span<const uint8_t> bytes, Bank& out, ErrorInfo* err = nullptr);
  static Status open_file(const std::string& path, Bank& out, ErrorInfo* err = nullptr);

  uint32_t clip_count() const noexcept;
  uint32_t skeleton_count() const noexcept;
  // Whether the clips are of the runtime profile (sampled in place), else the archive's.
  bool runtime_profile() const noexcept;
  uint64_t dictionary_bytes() const noexcept;  // 0: none
  uint64_t size_bytes() const noexcept;        // the bank's bytes
  BankEntry entry(uint32_t i) const;           // i < clip_count()
  // The clip of this exact name, by binary search over the name order.
  std::optional<uint32_t> find(std::string_view name) const noexcept;

  // Clip i, checked as Clip::load checks a file (section 10.5), with `limits`. A runtime-profile
  // clip is viewed in place: it keeps the bank's bytes alive when the bank owns them (open,
  // open_file). Clips of one skeleton share one rig. On failure `out` is empty and `err` names
  // the clip: section "clip NAME" (index i), offsets from the bank's first byte.
  Status clip(uint32_t i, Clip& out, ErrorInfo* err = nullptr, const DecodeLimits& limits = {}) const;

 private:
  struct State;
  // Checks `bytes` (kept alive by `storage`, or by the caller when null) into `out`.
  static Status make(std::span<const uint8_t> bytes, std::shared_ptr<const void> storage, Bank& out, ErrorInfo* err);
  std::shared_ptr<const State> state_;
};

}  // namespace keyanim
