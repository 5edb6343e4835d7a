// keyanim::Bank: a bank's bytes (owned, mapped or the caller's), its checked index, the
// dictionary ready for zstd, and one rig cache, so that clips of one skeleton share a rig.
#include "keyanim/bank.h"

#include <zstd.h>
#include <zstd_errors.h>

#include <cstring>
#include <new>
#include <vector>

#include "runtime/bank/bank_file.h"
#include "runtime/bank/bank_index.h"
#include "runtime/load/member.h"

namespace keyanim {

struct DDictDeleter {
  void operator()(ZSTD_DDict* d) const noexcept { ZSTD_freeDDict(d); }
};

struct Bank::State {
  std::shared_ptr<const void> storage;  // owns the bytes (a copy or a mapping); null: the caller does
  internal::BankIndex index;
  std::unique_ptr<ZSTD_DDict, DDictDeleter> dictionary;
  std::vector<std::vector<uint8_t>> skeletons;  // each one's content, inflated once at open
  mutable RigCache rigs;  // thread-safe
};

Bank::Bank() = default;
Bank::~Bank() = default;
Bank::Bank(const Bank&) = default;
Bank& Bank::operator=(const Bank&) = default;
Bank::Bank(Bank&&) noexcept = default;
Bank& Bank::operator=(Bank&&) noexcept = default;

namespace {

Status out_of_memory(ErrorInfo* err) {
  if (err != nullptr) *err = ErrorInfo{Status::limit_exceeded, 0, "bank", "out of memory"};
  return Status::limit_exceeded;
}

// ZSTD_createDDict refused the dictionary: its entropy tables do not decode (the dictionary is
// not what section 10.4 says: corrupt) or memory ran out. zstd's stable API tells which only by
// decompressing with the dictionary: an empty frame (magic, a header without a content size,
// one empty last Raw block), which loads the tables as the DDict did.
Status dictionary_refused(std::span<const uint8_t> dict, uint64_t offset, ErrorInfo* err) {
  static constexpr uint8_t kEmptyFrame[] = {0x28, 0xB5, 0x2F, 0xFD, 0x00, 0x00, 0x01, 0x00, 0x00};
  ZSTD_DCtx* dctx = ZSTD_createDCtx();
  if (dctx == nullptr) return out_of_memory(err);
  const size_t r = ZSTD_decompress_usingDict(dctx, nullptr, 0, kEmptyFrame, sizeof kEmptyFrame, dict.data(), dict.size());
  ZSTD_freeDCtx(dctx);
  if (!ZSTD_isError(r) || ZSTD_getErrorCode(r) == ZSTD_error_memory_allocation) return out_of_memory(err);
  if (err != nullptr)
    *err = ErrorInfo{Status::corrupt, offset, "dictionary",
                     std::string("not a zstd dictionary (RFC 8878 section 5): ") + ZSTD_getErrorName(r)};
  return Status::corrupt;
}

}  // namespace

Status Bank::make(std::span<const uint8_t> bytes, std::shared_ptr<const void> storage, Bank& out, ErrorInfo* err) {
  auto state = std::make_shared<State>();
  if (Status s = internal::check_bank_index(bytes, state->index, err); s != Status::ok) return s;
  const std::span<const uint8_t> dict = state->index.dictionary();
  if (!dict.empty()) {
    // Digested once for all the bank's clips (zstd's stable API copies it).
    state->dictionary.reset(ZSTD_createDDict(dict.data(), dict.size()));
    if (!state->dictionary) return dictionary_refused(dict, state->index.layout.dictionary, err);
  }
  uint64_t limit = DecodeLimits{}.max_decompressed_bytes;  // what all skeletons may inflate to
  state->skeletons.resize(state->index.skeletons);           // bounded: the table fits in the bank
  for (uint32_t k = 0; k < state->index.skeletons; ++k)
    if (Status s = internal::skeleton_content(state->index, k, limit, state->skeletons[k], err); s != Status::ok) return s;
  state->storage = std::move(storage);
  out.state_ = std::move(state);
  return Status::ok;
}

Status Bank::view(std::span<const uint8_t> bytes, Bank& out, ErrorInfo* err) {
  out = Bank{};
  if (reinterpret_cast<uintptr_t>(bytes.data()) % 8 != 0) {
    if (err != nullptr) *err = ErrorInfo{Status::invalid_argument, 0, "bank", "Bank::view needs the bytes at an address that is a multiple of 8"};
    return Status::invalid_argument;
  }
  try {
    return make(bytes, nullptr, out, err);
  } catch (const std::bad_alloc&) {
    return out_of_memory(err);
  }
}

Status Bank::open(std::span<const uint8_t> bytes, Bank& out, ErrorInfo* err) {
  out = Bank{};
  try {
    auto words = std::shared_ptr<uint64_t[]>(new uint64_t[(bytes.size() + 7) / 8]);  // 8-aligned
    if (!bytes.empty()) std::memcpy(words.get(), bytes.data(), bytes.size());
    const std::span<const uint8_t> copy(reinterpret_cast<const uint8_t*>(words.get()), bytes.size());
    return make(copy, std::move(words), out, err);
  } catch (const std::bad_alloc&) {
    return out_of_memory(err);
  }
}

Status Bank::open_file(const std::string& path, Bank& out, ErrorInfo* err) {
  out = Bank{};
  try {
    internal::BankFile file;
    if (Status s = internal::map_bank_file(path, file, err); s != Status::ok) return s;
    return make(file.bytes, std::move(file.storage), out, err);
  } catch (const std::bad_alloc&) {
    return out_of_memory(err);
  }
}

uint32_t Bank::clip_count() const noexcept { return state_ ? state_->index.clips : 0; }
uint32_t Bank::skeleton_count() const noexcept { return state_ ? state_->index.skeletons : 0; }
bool Bank::runtime_profile() const noexcept { return state_ && state_->index.runtime; }
uint64_t Bank::dictionary_bytes() const noexcept { return state_ ? state_->index.dictionary().size() : 0; }
uint64_t Bank::size_bytes() const noexcept { return state_ ? state_->index.bytes.size() : 0; }
BankEntry Bank::entry(uint32_t i) const { return state_->index.entry(i); }

std::optional<uint32_t> Bank::find(std::string_view name) const noexcept {
  if (!state_) return std::nullopt;
  const internal::BankIndex& idx = state_->index;
  uint32_t lo = 0, hi = idx.clips;  // the name order is strictly increasing (checked at open)
  while (lo < hi) {
    const uint32_t mid = lo + (hi - lo) / 2;
    const uint32_t i = idx.order(mid);
    const std::string_view n = idx.name(idx.clip_at(i));
    if (n == name) return i;
    if (n < name) lo = mid + 1;
    else hi = mid;
  }
  return std::nullopt;
}


namespace {
// The index's Frame_Count and Frame_Time must be the member's CLIP (section 10.3), field by field, so
// that a reader listing the bank and a reader decoding a clip agree; each mismatch names its field.
Status check_entry_timing(const internal::BankIndex& idx, uint32_t i, const BankEntry& e, Clip& out, ErrorInfo* err) {
  const uint64_t entry = uint64_t(idx.clip_at(i) - idx.bytes.data());
  const double frame_time = out.frame_time();
  uint64_t at = 0;
  const char* what = nullptr;
  if (out.frame_count() != e.frame_count) {
    at = entry + 24;
    what = "Frame_Count differs from the clip's CLIP";
  } else if (std::memcmp(&e.frame_time, &frame_time, sizeof(double)) != 0) {
    at = entry + 16;
    what = "Frame_Time differs from the clip's CLIP";
  } else {
    return Status::ok;
  }
  if (err != nullptr) *err = ErrorInfo{Status::corrupt, at, "clip table", what};
  out = Clip{};
  return Status::corrupt;
}
}  // namespace

Status Bank::clip(uint32_t i, Clip& out, ErrorInfo* err, const DecodeLimits& limits) const {
  out = Clip{};
  if (err != nullptr) *err = ErrorInfo{};
  if (!state_ || i >= state_->index.clips) {
    if (err != nullptr) *err = ErrorInfo{Status::invalid_argument, 0, "bank", "no clip " + std::to_string(i) + " in the bank"};
    return Status::invalid_argument;
  }
  const internal::BankIndex& idx = state_->index;
  const BankEntry e = idx.entry(i);
  internal::MemberContext m;
  m.skel = state_->skeletons[e.skeleton];
  m.skel_offset = idx.skeleton(e.skeleton).offset;
  m.skel_compressed = idx.skeleton(e.skeleton).compressed;
  m.member_offset = e.offset;
  m.dictionary = state_->dictionary.get();
  m.runtime = idx.runtime;
  m.bank_major = idx.major;
  // The clip keeps the bank's state (and so its bytes and dictionary) alive.
  Status s = internal::check_member_padding(idx, i, err);
  if (s == Status::ok)
    s = internal::load_member(idx.bytes.subspan(e.offset, e.size), m, state_->storage ? state_ : nullptr, limits,
                                   &state_->rigs, out, err);
  if (s == Status::ok) s = check_entry_timing(idx, i, e, out, err);
  if (s != Status::ok && err != nullptr) err->section = "clip " + std::string(e.name) + " (" + std::to_string(i) + "), " + err->section;
  return s;
}

}  // namespace keyanim
