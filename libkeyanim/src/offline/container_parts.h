// The parts both profiles' writers share (spec/FORMAT.md sections 2 to 4 and 9): CLIP, SKEL,
// and the signature, header and table around the sections. Internal to the offline library.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "keyanim/offline/encode.h"
#include "keyanim/skeleton.h"

namespace keyanim::offline {

struct Section {
  uint32_t tag = 0;
  uint32_t flags = 0;
  uint64_t raw_size = 0;
  std::vector<uint8_t> stored;
};

// zstd's parameters for one section: a level, and a minimum match length (0: the level's).
struct Zstd {
  int level = 0;  // <= 0: stored raw
  int min_match = 0;
};

// A section before compression, with the parameters it is compressed at and the offsets where
// a zstd block ends (KVAL's planes).
struct RawSection {
  uint32_t tag = 0;
  uint32_t flags = 0;
  std::vector<uint8_t> bytes;
  Zstd z;
  std::vector<size_t> breaks;
};

// The archive profile's sections of `clip` (CLIP, SKEL, CHAN, KTIM, KVAL, NOTE if any), not yet
// compressed, at write_kanim's parameters. Throws as validate_encoded_clip.
std::vector<RawSection> archive_raw_sections(const EncodedClip& clip, std::optional<int> zstd_level);
// Each section a zstd frame (made with `dictionary` when it is not empty: a bank's, spec
// section 10.4) when that is smaller, else stored raw; one zstd context at a time.
std::vector<Section> compress_sections(std::vector<RawSection> raw, std::span<const uint8_t> dictionary);
// SKEL's content as write_kanim stores it: a zstd frame at its parameters when that is smaller.
Section stored_skel(std::vector<uint8_t> skel);
// The runtime profile's sections of `clip`: CLIP, IMAG, SKEL, NOTE if any (section 9.1).
std::vector<Section> runtime_sections(const Clip& clip);
uint32_t crc32_of(const uint8_t* p, size_t n);  // the archive profile's checksum (3.3)

std::vector<uint8_t> clip_section(uint32_t frame_count, const Skeleton& skeleton, size_t channels, TangentRule rule,
                                  double frame_time, uint64_t keys);
std::vector<uint8_t> skel_section(const Skeleton& skel);
std::vector<uint8_t> quat_section(const std::vector<QuatNode>& nodes);  // QUAT's content (4.7)
// The archive profile's major version of `clip`: 5 with quaternion nodes, else 3; the runtime
// profile's: 5 with quaternion nodes, else 4.
uint16_t archive_version_major(const EncodedClip& clip);
uint16_t runtime_version_major(const Clip& clip);
// Signature, header, table and the sections' bytes, with room reserved for the checksum the
// caller appends (checksum_size bytes).
std::vector<uint8_t> assemble(const std::vector<Section>& sections, uint16_t major, uint16_t minor, uint32_t flags,
                              size_t checksum_size);

}  // namespace keyanim::offline
