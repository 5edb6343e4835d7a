// Library and format versions. The format version is what a file carries; see spec/FORMAT.md.
#pragma once
#include <cstdint>

#define KEYANIM_VERSION_MAJOR 0
#define KEYANIM_VERSION_MINOR 2
#define KEYANIM_VERSION_PATCH 0
#define KEYANIM_VERSION_STRING "0.2.0"

namespace keyanim {
// What the writer writes.
inline constexpr uint16_t kFormatVersionMajor = 3;
inline constexpr uint16_t kFormatVersionMinor = 0;
// The loader reads every major version from this one to kFormatVersionMajor.
inline constexpr uint16_t kOldestFormatVersionMajor = 1;
}  // namespace keyanim
