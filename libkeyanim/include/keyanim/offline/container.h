// Writing the .kanim container (spec/FORMAT.md). Reading is the runtime's job (keyanim/clip.h).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/encode.h"

namespace keyanim::offline {

// Returns if `clip` can be written (it follows every rule of spec/FORMAT.md: key frames strictly
// increasing and below frame_count, |q| <= 2^53, finite values, step > 0, tension in [-1, 1],
// parents before children, End Sites without channels ...); else throws Error
// (invalid_argument) naming the first rule it breaks.
void validate_encoded_clip(const EncodedClip& clip);

// The complete file: signature, header, section table, sections, CRC-32. Each section is a
// zstd frame when that is smaller, else stored raw: without `zstd_level`, at the parameters
// measured for that section (about -12 to -15: within 0.3% of -19's bytes on the test corpus
// for a quarter of its instructions; container_writer.cpp); with one, at that level on every
// section (clamped to at most zstd's maximum; <= 0 stores every section raw). One thread, one
// zstd context at a time (memory). Throws as validate_encoded_clip(clip).
std::vector<uint8_t> write_kanim(const EncodedClip& clip, std::optional<int> zstd_level = std::nullopt);

// The runtime profile of a loaded clip (spec/FORMAT.md section 9, version 4.0): its image as
// the file's bytes, which Clip::view samples in place. It samples to the same values, bit for
// bit, as the file it was loaded from.
std::vector<uint8_t> write_kanim_runtime(const Clip& clip);
// A loaded clip's keys as write_kanim takes them: from a runtime-profile file back to the
// archive profile. The same keys, frames and values bit for bit; a channel with a single key
// comes back as q = +-1 and step = |value|, since a clip keeps only that key's value.
EncodedClip encoded_clip(const Clip& clip);
// The clip a decoder builds from write_kanim(clip), without the bytes: the encoder verifies
// its error on this. Its arrays are identical to those Clip::load builds from the file.
// `clip` must be valid (validate_encoded_clip).
Clip to_clip(const EncodedClip& clip);

}  // namespace keyanim::offline
