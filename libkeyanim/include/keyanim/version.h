// Library and format versions. The format version is what a file carries; see spec/FORMAT.md.
#pragma once
#include <cstdint>

#define KEYANIM_VERSION_MAJOR 0
#define KEYANIM_VERSION_MINOR 1
#define KEYANIM_VERSION_PATCH 0
#define KEYANIM_VERSION_STRING "0.1.0"

namespace keyanim {
inline constexpr uint16_t kFormatVersionMajor = 1;
inline constexpr uint16_t kFormatVersionMinor = 0;
}  // namespace keyanim
