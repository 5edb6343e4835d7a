// Library and format versions. The format version is what a file carries; see spec/FORMAT.md.
#pragma once
#include <cstdint>

#define KEYANIM_VERSION_MAJOR 0
#define KEYANIM_VERSION_MINOR 2
#define KEYANIM_VERSION_PATCH 0
#define KEYANIM_VERSION_STRING "0.2.0"

namespace keyanim {
// What the writer writes: archive files as 3.0 (4.0's archive profile has 3.0's bytes, and
// every 3.x decoder reads them), runtime-profile files as 4.0; a clip with rotations stored as
// quaternions (QuatNode, spec section 4.7) as 5.0 in either profile, which only 5.x decoders read.
inline constexpr uint16_t kFormatVersionMajor = 3;
inline constexpr uint16_t kFormatVersionMinor = 0;
inline constexpr uint16_t kRuntimeFormatVersionMajor = 4;
inline constexpr uint16_t kRuntimeFormatVersionMinor = 0;
inline constexpr uint16_t kQuatFormatVersionMajor = 5;
inline constexpr uint16_t kQuatFormatVersionMinor = 0;
// The loader reads every major version from kOldestFormatVersionMajor to kNewestFormatVersionMajor.
inline constexpr uint16_t kOldestFormatVersionMajor = 1;
inline constexpr uint16_t kNewestFormatVersionMajor = 5;
}  // namespace keyanim
