// Writes a bank (spec/FORMAT.md section 10): the members are the clips' files without SKEL,
// each skeleton is stored once, and archive members are compressed with a dictionary that zstd
// trains on the members' own sections.
#include <zdict.h>
#include <zstd.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "internal/bank_layout.h"
#include "internal/byte_writer.h"
#include "internal/format.h"
#include "internal/xxh64.h"
#include "keyanim/offline/bank.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/error.h"
#include "keyanim/version.h"
#include "offline/container_parts.h"
#include "runtime/bank/bank_index.h"

namespace keyanim::offline {
namespace {

using internal::next_part;
using internal::put_le;

// The members' sections before compression (archive) or as stored (runtime), SKEL left out.
struct Pending {
  std::vector<std::vector<RawSection>> raw;      // archive
  std::vector<std::vector<Section>> sections;    // runtime
};

template <typename S>
void drop_skel(std::vector<S>& sections) {
  std::erase_if(sections, [](const S& s) { return s.tag == internal::kTagSkel; });
}

// The samples a dictionary is trained on: every section zstd will compress (CHAN, KTIM, KVAL,
// NOTE), concatenated, and their sizes.
struct Samples {
  std::vector<uint8_t> bytes;
  std::vector<size_t> sizes;
};

Samples samples_of(const std::vector<std::vector<RawSection>>& members) {
  Samples out;
  for (const auto& m : members)
    for (const RawSection& s : m)
      if (s.z.level > 0 && !s.bytes.empty()) {
        out.bytes.insert(out.bytes.end(), s.bytes.begin(), s.bytes.end());
        out.sizes.push_back(s.bytes.size());
      }
  return out;
}

// A dictionary of at most `capacity` bytes, or none when zstd cannot train one (too few or too
// small samples).
std::vector<uint8_t> train_dictionary(const Samples& samples, size_t capacity) {
  if (samples.sizes.size() < 8) return {};
  std::vector<uint8_t> dict(capacity);
  const size_t n = ZDICT_trainFromBuffer(dict.data(), dict.size(), samples.bytes.data(), samples.sizes.data(),
                                         static_cast<unsigned>(samples.sizes.size()));
  if (ZDICT_isError(n)) return {};
  dict.resize(n);
  return dict;
}

// A member's version: 5.0 for a clip with quaternion nodes (QUAT, section 4.7; IMAG's of version
// 5), else the bank's 4.1.
bool quat_member(const std::vector<Section>& sections) {
  return std::any_of(sections.begin(), sections.end(), [](const Section& s) { return s.tag == internal::kTagQuat; });
}

std::vector<uint8_t> member_bytes(const std::vector<Section>& sections, bool runtime, bool quat) {
  const uint32_t flags = internal::kHeaderMember | (runtime ? internal::kHeaderRuntime : 0u);
  std::vector<uint8_t> out = assemble(sections, quat ? kQuatFormatVersionMajor : kRuntimeFormatVersionMajor,
                                      quat ? kQuatFormatVersionMinor : internal::kBankVersionMinor, flags,
                                      runtime ? internal::kRuntimeChecksumSize : internal::kChecksumSize);
  if (runtime) put_le<uint64_t>(out, internal::xxh64_of(out.data(), out.size()));
  else put_le<uint32_t>(out, crc32_of(out.data(), out.size()));
  return out;
}

std::vector<std::vector<uint8_t>> archive_members(const std::vector<std::vector<RawSection>>& raw,
                                                  std::span<const uint8_t> dictionary) {
  std::vector<std::vector<uint8_t>> out;
  for (const auto& m : raw) {
    std::vector<Section> sections = compress_sections(m, dictionary);
    const bool quat = quat_member(sections);
    out.push_back(member_bytes(sections, false, quat));
  }
  return out;
}

// Pads `out` with zeros to the next part (section 10.1).
void pad(std::vector<uint8_t>& out) { out.resize(next_part(out.size()), 0); }

struct Parts {
  std::vector<Section> skeletons;  // stored as write_kanim stores SKEL (10.3: compressed or not)
  std::vector<uint32_t> skeleton_of;  // per clip
  std::vector<std::vector<uint8_t>> members;
  std::vector<uint8_t> dictionary;
  bool quat = false;  // a member of version 5: the bank is version 5.0 (section 10.2)
};

// Header, tables, names, dictionary, skeletons, checksum, members, each where 10.1 puts it.
std::vector<uint8_t> assemble_bank(const std::vector<BankInput>& clips, const Parts& p, bool runtime) {
  std::string names;
  std::vector<uint32_t> name_at;
  for (const BankInput& c : clips) {
    name_at.push_back(static_cast<uint32_t>(names.size()));
    names += c.name;
  }
  const auto l = *internal::bank_index_layout(static_cast<uint32_t>(clips.size()), static_cast<uint32_t>(p.skeletons.size()),
                                              names.size(), p.dictionary.size(), UINT64_MAX / 2);
  // Every part's offset, in layout order: skeletons, the checksum, then members.
  uint64_t end = l.dictionary_end;
  std::vector<uint64_t> skel_at, member_at;
  for (const auto& s : p.skeletons) skel_at.push_back(next_part(end)), end = skel_at.back() + s.stored.size();
  const uint64_t checksum_at = next_part(end);
  end = checksum_at + internal::kBankChecksumSize;
  for (const auto& m : p.members) member_at.push_back(next_part(end)), end = member_at.back() + m.size();

  std::vector<uint8_t> out(internal::kSignature, internal::kSignature + internal::kSignatureSize);
  out.reserve(end);
  put_le<uint16_t>(out, p.quat ? kQuatFormatVersionMajor : kRuntimeFormatVersionMajor);
  put_le<uint16_t>(out, p.quat ? kQuatFormatVersionMinor : internal::kBankVersionMinor);
  put_le<uint32_t>(out, internal::kHeaderBank | (runtime ? internal::kHeaderRuntime : 0u));
  put_le<uint32_t>(out, static_cast<uint32_t>(clips.size()));
  put_le<uint32_t>(out, static_cast<uint32_t>(p.skeletons.size()));
  put_le<uint64_t>(out, names.size());
  put_le<uint64_t>(out, p.dictionary.size());
  for (size_t s = 0; s < p.skeletons.size(); ++s) {
    put_le<uint64_t>(out, skel_at[s]);
    put_le<uint64_t>(out, p.skeletons[s].stored.size());
    put_le<uint64_t>(out, p.skeletons[s].raw_size);
    put_le<uint32_t>(out, (p.skeletons[s].flags & internal::kSectionCompressed) ? internal::kSkeletonCompressed : 0u);
    put_le<uint32_t>(out, 0);  // Skeleton_Reserved
  }
  for (size_t i = 0; i < clips.size(); ++i) {
    put_le<uint64_t>(out, member_at[i]);
    put_le<uint64_t>(out, p.members[i].size());
    put_le<double>(out, clips[i].clip.frame_time);
    put_le<uint32_t>(out, clips[i].clip.frame_count);
    put_le<uint32_t>(out, p.skeleton_of[i]);
    put_le<uint32_t>(out, name_at[i]);
    put_le<uint32_t>(out, static_cast<uint32_t>(clips[i].name.size()));
  }
  std::vector<uint32_t> order(clips.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return std::string_view(clips[a].name) < clips[b].name; });
  for (uint32_t i : order) put_le<uint32_t>(out, i);
  internal::put_bytes(out, names.data(), names.size());
  pad(out);
  internal::put_bytes(out, p.dictionary.data(), p.dictionary.size());
  for (const auto& s : p.skeletons) pad(out), internal::put_bytes(out, s.stored.data(), s.stored.size());
  pad(out);
  put_le<uint64_t>(out, internal::xxh64_of(out.data(), out.size()));
  for (const auto& m : p.members) pad(out), internal::put_bytes(out, m.data(), m.size());
  return out;
}

void check_names(const std::vector<BankInput>& clips) {
  std::map<std::string_view, size_t> seen;
  for (size_t i = 0; i < clips.size(); ++i) {
    if (std::string p = bank_name_problem(clips[i].name); !p.empty())
      throw Error(ErrorKind::invalid_argument, "clip name '" + clips[i].name + "': " + p);
    if (!seen.emplace(clips[i].name, i).second)
      throw Error(ErrorKind::invalid_argument, "two clips named '" + clips[i].name + "' (a bank's names are distinct)");
  }
  if (clips.size() > UINT32_MAX) throw Error(ErrorKind::invalid_argument, "more than 2^32 - 1 clips in one bank");
}

}  // namespace

std::string bank_name_problem(std::string_view name) { return internal::bank_name_problem(name); }

WrittenBank write_bank(const std::vector<BankInput>& clips, const BankOptions& options) {
  check_names(clips);
  Parts p;
  std::unordered_multimap<uint64_t, uint32_t> skeleton_index;  // XXH64 of SKEL's bytes -> skeleton
  std::vector<std::vector<uint8_t>> skeletons;                 // their contents
  std::vector<std::vector<RawSection>> raw;
  for (const BankInput& c : clips) {
    // Skeletons are shared when their SKEL bytes are equal (the rig hash's fields, exactly).
    std::vector<uint8_t> skel = skel_section(c.clip.skeleton);
    const uint64_t hash = internal::xxh64_of(skel.data(), skel.size());
    uint32_t index = static_cast<uint32_t>(skeletons.size());
    for (auto [it, end] = skeleton_index.equal_range(hash); it != end; ++it)
      if (skeletons[it->second] == skel) index = it->second;
    if (index == skeletons.size()) {
      skeleton_index.emplace(hash, index);
      p.skeletons.push_back(stored_skel(skel));
      skeletons.push_back(std::move(skel));
    }
    p.skeleton_of.push_back(index);
    p.quat |= !c.clip.quat_nodes.empty();
    try {
      if (options.runtime) {
        std::vector<Section> s = runtime_sections(to_clip(c.clip));
        drop_skel(s);
        p.members.push_back(member_bytes(s, true, !c.clip.quat_nodes.empty()));
      } else {
        raw.push_back(archive_raw_sections(c.clip, options.zstd_level));
        drop_skel(raw.back());
      }
    } catch (const Error& e) {
      throw Error(e.kind(), "clip '" + c.name + "': " + e.what());
    }
  }
  WrittenBank out;
  if (options.runtime) {
    out.bytes = assemble_bank(clips, p, true);
  } else {
    // Without a dictionary, and with one of each of a few sizes (what pays depends on how much
    // the clips share: on the corpus' Bandai clips a 46 KB dictionary cost more than it saved):
    // the smallest bank is kept (`always`: the smallest with a dictionary).
    p.members = archive_members(raw, {});
    std::vector<uint8_t> best = assemble_bank(clips, p, false);
    out.bytes_without_dictionary = best.size();
    if (options.dictionary != BankDictionary::never) {
      const Samples samples = samples_of(raw);
      std::vector<uint8_t> with;
      for (size_t share : {200, 50, 12}) {
        Parts d = p;
        d.dictionary = train_dictionary(samples, std::clamp<size_t>(samples.bytes.size() / share, 1024, 112640));
        if (d.dictionary.empty()) continue;
        d.members = archive_members(raw, d.dictionary);
        std::vector<uint8_t> bank = assemble_bank(clips, d, false);
        if (with.empty() || bank.size() < with.size()) with = std::move(bank), out.dictionary_bytes = d.dictionary.size();
      }
      if (!with.empty() && (options.dictionary == BankDictionary::always || with.size() < best.size())) best = std::move(with);
      else out.dictionary_bytes = 0;
    }
    if (out.dictionary_bytes == 0) out.bytes_without_dictionary = 0;
    out.bytes = std::move(best);
  }
  out.skeletons = static_cast<uint32_t>(p.skeletons.size());
  return out;
}

}  // namespace keyanim::offline
