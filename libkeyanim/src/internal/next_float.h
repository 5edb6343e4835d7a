// The next binary32 above a finite value, inline. std::nextafter would do, but libm's copy is
// of the baseline level: the AVX2 copy of the Cursor (internal/cpu.h) calling it would pay an
// SSE/AVX transition each time.
#pragma once
#include <cstdint>
#include <cstring>
#include <limits>

#include "internal/cpu.h"

namespace keyanim::internal {

// std::nextafter(x, +infinity) for a finite x (+-0 give the smallest subnormal).
KEYANIM_INLINE inline float next_above(float x) noexcept {
  uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  if ((b & 0x7FFFFFFFu) == 0) return std::numeric_limits<float>::denorm_min();
  b = (b >> 31) == 0 ? b + 1 : b - 1;  // a positive value's magnitude up, a negative one's down
  std::memcpy(&x, &b, sizeof b);
  return x;
}

}  // namespace keyanim::internal
