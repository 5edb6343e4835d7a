// Fuzz target: banks (spec/FORMAT.md section 10), keyanim::Bank's index and its members.
// The input is a bank's bytes. Unless the input says otherwise, the checksums are recomputed
// first, so that mutations reach the index checks, the names and the member parsers instead of
// stopping at checksum_mismatch: each member's own (its last 4 bytes, CRC-32, in the archive
// profile; its last 8, XXH64, in the runtime profile: section 10.5, as fuzz_load repairs a
// file's) for the first kMaxClips clips of the clip table whose Offset and Size lie in the input,
// then Bank_Checksum (10.4), which lies 8 bytes before the first member's Offset (10.1: the
// members follow it; with no clip, the last 8 bytes). Minor_Version (bytes 10-11), which a
// decoder reads as any value, is the switch: bit 15 keeps Bank_Checksum as given, bit 14 the
// members' checksums (write_bank's seeds have neither set).
// Then:
//  * Bank::open (a copy) and Bank::view (the bytes in place, in an allocation of exactly the
//    input's size so that a read past its end is seen) agree on the status and the error; a
//    failure leaves the bank empty and names a section and an offset <= the input's size.
//  * An open bank keeps section 10's promises, checked here from the entries and not from the
//    library's layout: fewer than size / 44 clips, members 8-aligned, in clip-table order, not
//    overlapping, inside the bank and ending at its end; skeleton < skeleton count; every name
//    keeps 10.3's rules and lies in the caller's bytes (view); find(name) of every clip is that
//    clip (the name order is strictly increasing), "" and a 1025-byte name are not found; both
//    banks give the same entries. All of it for every clip: the index checks are linear.
//  * clip(i) with check_content, for the first kMaxClips clips, from both banks: the same status;
//    a failure names the clip ("clip NAME (i), ...") at an offset <= size and leaves it empty; a
//    success has the entry's Frame_Count and Frame_Time, the bank's profile, a skeleton as the
//    loader promises, key frames strictly increasing and below the frame count, finite key
//    values; it samples (positions around both ends, between frames, block boundaries, local
//    and model poses, a cursor's forward playback) bit for bit as eval_channel (cardinal.h,
//    Appendix A) on its keys (a quaternion node's channels, version 5: the Euler angles of its
//    stored x, y, z so evaluated; sample_stored: those values), the cursor as without one, the
//    viewed bank's clip as the opened one's, with finite values where the keys leave no room
//    for an overflow; clips of one skeleton share a rig; the opened bank's clips still sample
//    after the bank is gone.
// Work per input is capped (kMaxClips clips loaded, kSampleBudget values sampled), so that a
// bank declaring many clips of many channels stays fast; the index checks are not capped.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_common.h"
#include "keyanim/bank.h"
#include "keyanim/clip.h"
#include "clip_reference.h"

namespace {

using keyanim::Bank;
using keyanim::BankEntry;
using keyanim::Clip;
using keyanim::Cursor;
using keyanim::ErrorInfo;
using keyanim::Status;
using keyanim::Transform;

constexpr uint32_t kMaxClips = 64;
constexpr uint64_t kSampleBudget = 100000;  // values sampled per input, all clips together (sample_cost)

uint64_t le(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

void put_le64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}

// The checksums recomputed in place (see the top of this file).
void repair(uint8_t* b, size_t size) {
  if (size < 40) return;
  const uint64_t minor = le(b + 10, 2), clips = le(b + 16, 4), skeletons = le(b + 20, 4);
  const uint64_t clip_table = 40 + 32 * skeletons;  // skeleton table entries of 32 bytes (10.3)
  if ((minor & 0x4000) == 0) {
    for (uint64_t i = 0; i < std::min<uint64_t>(clips, kMaxClips); ++i) {
      const uint64_t e = clip_table + 40 * i;
      if (e > size || size - e < 16) break;
      const uint64_t offset = le(b + e, 8), bytes = le(b + e + 8, 8);
      if (offset <= size && bytes <= size - offset) keyanim::fuzz::fix_checksum(b + offset, bytes);
    }
  }
  if ((minor & 0x8000) != 0) return;
  uint64_t at = size - 8;  // no clip: the bank ends with its checksum
  if (clips > 0) {
    if (clip_table > size || size - clip_table < 8) return;
    const uint64_t first = le(b + clip_table, 8);
    if (first < 8 || first > size) return;
    at = first - 8;
  }
  put_le64(b + at, XXH64(b, at, 0));
}

keyanim::DecodeLimits fuzz_limits() {  // as fuzz_view's, with the content check
  keyanim::DecodeLimits l;
  l.max_decompressed_bytes = 64u << 20;
  l.check_content = true;
  return l;
}

bool same_error(const ErrorInfo& a, const ErrorInfo& b) {
  return a.status == b.status && a.byte_offset == b.byte_offset && a.section == b.section && a.detail == b.detail;
}

// Section 10.3's rules for a name, written from the spec.
bool name_ok(std::string_view n) {
  if (n.empty() || n.size() > 1024 || n.find('\0') != std::string_view::npos) return false;
  size_t from = 0;
  for (;;) {
    const size_t to = std::min(n.find('/', from), n.size());
    const std::string_view part = n.substr(from, to - from);
    if (part.empty() || part == "." || part == "..") return false;
    if (to == n.size()) return true;
    from = to + 1;
  }
}

bool same_entry(const BankEntry& a, const BankEntry& b) {
  return a.name == b.name && a.frame_count == b.frame_count && keyanim::fuzz::same_double(a.frame_time, b.frame_time) &&
         a.skeleton == b.skeleton && a.offset == b.offset && a.size == b.size;
}

void check_failed_open(Status s, const ErrorInfo& err, const Bank& bank, size_t size) {
  FUZZ_CHECK(err.status == s);
  FUZZ_CHECK(!err.section.empty());
  FUZZ_CHECK(err.byte_offset <= size);
  // Opening allocates little (nothing per clip), so a small input never runs out of memory.
  FUZZ_CHECK(s != Status::limit_exceeded);
  FUZZ_CHECK(bank.clip_count() == 0 && bank.skeleton_count() == 0 && bank.size_bytes() == 0);
}

// The index: every clip's entry against section 10's rules, and find.
void check_index(const Bank& viewed, const Bank& opened, std::span<const uint8_t> in) {
  const uint64_t size = in.size();
  const uint32_t n = viewed.clip_count();
  FUZZ_CHECK(opened.clip_count() == n && opened.skeleton_count() == viewed.skeleton_count());
  FUZZ_CHECK(opened.runtime_profile() == viewed.runtime_profile());
  FUZZ_CHECK(opened.dictionary_bytes() == viewed.dictionary_bytes());
  FUZZ_CHECK(viewed.size_bytes() == size && opened.size_bytes() == size);
  FUZZ_CHECK(uint64_t(n) * 44 < size);
  FUZZ_CHECK(viewed.dictionary_bytes() < size);
  if (viewed.runtime_profile()) FUZZ_CHECK(viewed.dictionary_bytes() == 0);
  uint64_t end = 48;  // the header and the checksum at least come before the first member
  for (uint32_t i = 0; i < n; ++i) {
    const BankEntry e = viewed.entry(i);
    FUZZ_CHECK(same_entry(e, opened.entry(i)));
    FUZZ_CHECK(name_ok(e.name));
    const auto* name = reinterpret_cast<const uint8_t*>(e.name.data());
    FUZZ_CHECK(name >= in.data() && e.name.size() <= size_t(in.data() + size - name));
    FUZZ_CHECK(e.skeleton < viewed.skeleton_count());
    FUZZ_CHECK(e.offset % 8 == 0 && e.offset >= end && e.offset <= size && e.size <= size - e.offset);
    end = e.offset + e.size;
    FUZZ_CHECK(viewed.find(e.name) == i);
    FUZZ_CHECK(opened.find(e.name) == i);
  }
  if (n > 0) FUZZ_CHECK(end == size);
  FUZZ_CHECK(!viewed.find("").has_value());
  FUZZ_CHECK(!viewed.find(std::string(1025, 'a')).has_value());
  Clip none;
  ErrorInfo err;
  FUZZ_CHECK(viewed.clip(n, none, &err) == Status::invalid_argument && err.status == Status::invalid_argument);
  FUZZ_CHECK(none.channel_count() == 0);
}

// A clip the loader accepted: what the sampler relies on (as fuzz_load's check_loaded), with
// finite key values (the content check passed). Returns its keys.
std::vector<keyanim::test::ChannelKeys> check_loaded(const Clip& clip) {
  const uint32_t channels = clip.channel_count();
  FUZZ_CHECK(clip.skeleton().channel_count() == channels);
  FUZZ_CHECK(std::isfinite(clip.frame_time()) && clip.frame_time() >= 0.0);
  if (clip.frame_count() > 1) FUZZ_CHECK(clip.frame_time() > 0.0);
  const auto& joints = clip.skeleton().joints;
  for (size_t i = 0; i < joints.size(); ++i) {
    FUZZ_CHECK(joints[i].parent >= -1 && joints[i].parent < static_cast<int32_t>(i));
    if (joints[i].end_site) FUZZ_CHECK(joints[i].channels.empty() && joints[i].parent >= 0);
    for (double o : joints[i].offset) FUZZ_CHECK(std::isfinite(o));
  }
  std::vector<keyanim::test::ChannelKeys> keys;
  uint64_t total = 0;
  for (uint32_t c = 0; c < channels; ++c) {
    const keyanim::ChannelInfo info = clip.channel(c);
    FUZZ_CHECK(info.key_count <= clip.frame_count());
    FUZZ_CHECK(std::isfinite(info.tension) && info.tension >= -1.0f && info.tension <= 1.0f);
    total += info.key_count;
    keys.push_back(keyanim::test::channel_keys(clip, c));
    const auto& k = keys.back();
    FUZZ_CHECK(k.frames.size() == info.key_count);
    for (size_t j = 0; j < k.frames.size(); ++j) {
      FUZZ_CHECK(k.frames[j] < clip.frame_count());
      if (j > 0) FUZZ_CHECK(k.frames[j] > k.frames[j - 1]);
      FUZZ_CHECK(std::isfinite(k.values[j]));
    }
  }
  FUZZ_CHECK(total == clip.total_keys());
  return keys;
}

std::vector<double> positions(const Clip& clip) {
  const double n = static_cast<double>(clip.frame_count());
  std::vector<double> p = {-3.0, -0.25, 0.0, 0.25, 0.5, 1.0, 1.5, n / 3.0, n / 2.0 + 0.375,
                           n - 1.5, n - 1.0, n - 0.75, n, n + 4.0, 1e9, -1e9};
  for (double f : {64.0, 128.0})  // around block boundaries (64 frames)
    if (f < n) p.insert(p.end(), {f - 0.5, f, f + 0.5});
  return p;
}

// Values a player asks of the clip, checked against eval_channel on its keys; returned flat, so
// that the viewed and the opened bank's clips can be compared.
std::vector<float> sample_checked(const Clip& clip, const std::vector<keyanim::test::ChannelKeys>& keys) {
  const uint32_t channels = clip.channel_count();
  float largest = 0.0f;  // |key value|: Hermite segments stay within a few times it
  for (const auto& k : keys)
    for (float v : k.values) largest = std::max(largest, std::fabs(v));
  std::vector<float> out, pose(channels), stored(channels);
  std::vector<Transform> xf(clip.skeleton().joints.size());
  const keyanim::test::SampleReference ref = keyanim::test::sample_reference(clip, keys);
  for (double x : positions(clip)) {
    FUZZ_CHECK(clip.sample(x, pose) == Status::ok);
    FUZZ_CHECK(clip.sample_stored(x, stored) == Status::ok);
    for (uint32_t c = 0; c < channels; ++c) {  // a quaternion node's channels: its Euler angles
      FUZZ_CHECK(keyanim::fuzz::same_float(pose[c], keyanim::test::reference_sample(clip, ref, c, static_cast<float>(x))));
      FUZZ_CHECK(keyanim::fuzz::same_float(stored[c], keyanim::test::reference_value(clip, keys[c], static_cast<float>(x))));
      FUZZ_CHECK(std::isfinite(pose[c]) || largest > 1e30f);
    }
    out.insert(out.end(), pose.begin(), pose.end());
  }
  FUZZ_CHECK(clip.sample(std::nan(""), pose) == Status::invalid_argument);
  // Poses (the sampler is fuzz_view's to explore; here: that a bank's clip gives them).
  const double n = static_cast<double>(clip.frame_count());
  for (double x : {0.5, n / 2.0 + 0.375, n}) {
    FUZZ_CHECK(clip.sample_local(x, xf) == Status::ok);
    for (const Transform& t : xf) {
      out.insert(out.end(), std::begin(t.rotation), std::end(t.rotation));
      out.insert(out.end(), std::begin(t.translation), std::end(t.translation));
    }
    FUZZ_CHECK(clip.sample_model(x, xf) == Status::ok);
  }
  // A cursor playing forward by quarter frames over the first 6 frames, then on to the last
  // frame and back to 0.5.
  Cursor cursor;
  FUZZ_CHECK(cursor.prepare(clip) == Status::ok);
  std::vector<float> plain(channels);
  std::vector<double> walk;
  for (double x = 0.0; x <= std::min(n + 1.0, 6.0); x += 0.25) walk.push_back(x);
  walk.insert(walk.end(), {n - 1.0, n - 0.5, 0.5});
  for (double x : walk) {
    FUZZ_CHECK(clip.sample(x, pose, &cursor) == Status::ok);
    FUZZ_CHECK(clip.sample(x, plain) == Status::ok);
    for (uint32_t c = 0; c < channels; ++c) FUZZ_CHECK(keyanim::fuzz::same_float(pose[c], plain[c]));
    out.insert(out.end(), pose.begin(), pose.end());
  }
  return out;
}

// About the values sample_checked computes, channels and nodes; twice (both banks' clips).
uint64_t sample_cost(const Clip& clip) { return (uint64_t(clip.channel_count()) * 80 + clip.skeleton().joints.size() * 6) * 2; }

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!keyanim::fuzz::same_float(a[i], b[i])) return false;
  return true;
}

void check_clips(const Bank& viewed, Bank& opened, size_t size) {
  const uint32_t n = std::min(viewed.clip_count(), kMaxClips);
  std::vector<Clip> vclips(n), oclips(n);
  std::vector<std::vector<float>> values(n);
  std::vector<bool> loaded(n);
  uint64_t budget = kSampleBudget;
  for (uint32_t i = 0; i < n; ++i) {
    const BankEntry e = viewed.entry(i);
    ErrorInfo verr, oerr;
    const Status vs = viewed.clip(i, vclips[i], &verr, fuzz_limits());
    const Status os = opened.clip(i, oclips[i], &oerr, fuzz_limits());
    FUZZ_CHECK(vs == os);
    if (vs != Status::ok) {
      FUZZ_CHECK(same_error(verr, oerr) && verr.status == vs);
      const std::string prefix = "clip " + std::string(e.name) + " (" + std::to_string(i) + "), ";
      FUZZ_CHECK(verr.section.size() > prefix.size() && verr.section.compare(0, prefix.size(), prefix) == 0);
      FUZZ_CHECK(verr.byte_offset <= size);
      FUZZ_CHECK(vclips[i].channel_count() == 0 && vclips[i].frame_count() == 0 && oclips[i].frame_count() == 0);
      continue;
    }
    loaded[i] = true;
    const Clip& c = vclips[i];
    FUZZ_CHECK(c.frame_count() == e.frame_count);
    const double ft = c.frame_time();
    FUZZ_CHECK(keyanim::fuzz::same_double(ft, e.frame_time));
    FUZZ_CHECK(c.runtime_profile() == viewed.runtime_profile() && oclips[i].runtime_profile() == c.runtime_profile());
    const auto keys = check_loaded(c);
    if (sample_cost(c) <= budget) {
      budget -= sample_cost(c);
      values[i] = sample_checked(c, keys);
    }
    for (uint32_t j = 0; j < i; ++j)
      if (loaded[j] && viewed.entry(j).skeleton == e.skeleton)
        FUZZ_CHECK(vclips[j].shares_rig(c) && oclips[j].shares_rig(oclips[i]));
  }
  // The opened bank's clips keep its bytes alive (a runtime clip samples them in place).
  opened = Bank{};
  for (uint32_t i = 0; i < n; ++i)
    if (!values[i].empty()) FUZZ_CHECK(same_floats(values[i], sample_checked(oclips[i], check_loaded(oclips[i]))));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Exactly `size` bytes (a read past them is a sanitizer report), 8-aligned as Bank::view needs:
  // operator new aligns to __STDCPP_DEFAULT_NEW_ALIGNMENT__.
  static_assert(__STDCPP_DEFAULT_NEW_ALIGNMENT__ >= 8);
  std::vector<uint8_t> copy(data, data + size);
  FUZZ_CHECK(reinterpret_cast<uintptr_t>(copy.data()) % 8 == 0);
  repair(copy.data(), size);
  const std::span<const uint8_t> in(copy.data(), size);

  Bank viewed, opened;
  ErrorInfo verr, oerr;
  const Status vs = Bank::view(in, viewed, &verr);
  const Status os = Bank::open(in, opened, &oerr);
  FUZZ_CHECK(vs == os);
  if (vs != Status::ok) {
    FUZZ_CHECK(same_error(verr, oerr));
    check_failed_open(vs, verr, viewed, size);
    check_failed_open(os, oerr, opened, size);
    return 0;
  }
  FUZZ_CHECK(verr.status == Status::ok && oerr.status == Status::ok);
  check_index(viewed, opened, in);
  check_clips(viewed, opened, size);
  return 0;
}
