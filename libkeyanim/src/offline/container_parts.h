// The parts both profiles' writers share (spec/FORMAT.md sections 2 to 4 and 9): CLIP, SKEL,
// and the signature, header and table around the sections. Internal to the offline library.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/skeleton.h"

namespace keyanim::offline {

struct Section {
  uint32_t tag = 0;
  uint32_t flags = 0;
  uint64_t raw_size = 0;
  std::vector<uint8_t> stored;
};

std::vector<uint8_t> clip_section(uint32_t frame_count, const Skeleton& skeleton, size_t channels, TangentRule rule,
                                  double frame_time, uint64_t keys);
std::vector<uint8_t> skel_section(const Skeleton& skel);
// Signature, header, table and the sections' bytes, with room reserved for the checksum the
// caller appends (checksum_size bytes).
std::vector<uint8_t> assemble(const std::vector<Section>& sections, uint16_t major, uint16_t minor, uint32_t flags,
                              size_t checksum_size);

}  // namespace keyanim::offline
