// Which x86-64 level the runtime's hot loops run at, chosen once per process. Neither popcnt
// nor BMI1/2 (blsr, andn, shlx, tzcnt) nor AVX2 is part of baseline x86-64, so the sampler and
// the pose code are compiled three times (baseline; popcnt; popcnt + BMI1/2 + AVX2, the
// x86-64-v3 level of every x86 CPU since about 2015) and dispatch on cpu_level(). Results are
// identical at every level: integer operations, and the same IEEE binary32/binary64 operation
// per lane (-ffp-contract=off keeps products and sums apart, so no FMA is ever formed);
// tests/scalar checks every level against the scalar build.
//
// KEYANIM_CPU=baseline|popcnt|v3 in the environment caps the level (for tests and for
// comparing speed); a level the CPU lacks is never chosen.
#pragma once
#include <cstdlib>
#include <cstring>

namespace keyanim::internal {

enum class CpuLevel { baseline = 0, popcnt = 1, v3 = 2 };

// Forces inlining into each level's copy (a lambda or helper left out of line would run at the
// baseline level). A v3 copy must call nothing compiled for the baseline: legacy-SSE code run
// between AVX code costs a transition each way, and on the machines we measure that cost far
// more than the call (a pose of CMU 01_01 spent about 1 us of its 2.2 us in six calls of an
// out-of-line list search and one of the position's; inlined, the pose took 1.0 us).
// tests/architecture/check_v3_calls.py checks the built library for such calls.
#define KEYANIM_INLINE __attribute__((always_inline))

#if defined(__x86_64__) && !defined(__POPCNT__)
#define KEYANIM_POPCNT_TARGET [[gnu::target("popcnt")]]
#define KEYANIM_V3_TARGET [[gnu::target("popcnt,bmi,bmi2,avx,avx2")]]
inline CpuLevel detected_cpu_level() noexcept {
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
      __builtin_cpu_supports("popcnt"))
    return CpuLevel::v3;
  return __builtin_cpu_supports("popcnt") ? CpuLevel::popcnt : CpuLevel::baseline;
}
#else  // other architectures, or a build for a level with popcnt: one copy serves
#define KEYANIM_POPCNT_TARGET
#define KEYANIM_V3_TARGET
inline CpuLevel detected_cpu_level() noexcept { return CpuLevel::v3; }
#endif

inline CpuLevel cpu_level() noexcept {
  static const CpuLevel level = [] {
    const CpuLevel found = detected_cpu_level();
    const char* cap = std::getenv("KEYANIM_CPU");
    CpuLevel want = CpuLevel::v3;
    if (cap != nullptr && std::strcmp(cap, "baseline") == 0) want = CpuLevel::baseline;
    if (cap != nullptr && std::strcmp(cap, "popcnt") == 0) want = CpuLevel::popcnt;
    return static_cast<int>(want) < static_cast<int>(found) ? want : found;
  }();
  return level;
}

}  // namespace keyanim::internal
