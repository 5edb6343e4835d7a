// Long clips for the benchmarks, made from a corpus file: its motion played forward, then
// backward, and so on (no jump at the seams), with a slow drift per channel so that no two
// passes are the same, written as the CMU files are (their header, values with 4 decimals).
#pragma once
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <string>
#include <string_view>

#include "keyanim/offline/motion.h"

namespace keyanim::bench {

// BVH text of `frames` frames from `source` (the motion of `source_text`).
inline std::string long_bvh_text(std::string_view source_text, const offline::Motion& source, uint32_t frames) {
  const size_t motion = source_text.find("MOTION");
  std::string out(source_text.substr(0, motion == std::string_view::npos ? 0 : motion));
  char line[64];
  std::snprintf(line, sizeof line, "MOTION\nFrames: %u\nFrame Time: %.7g\n", frames, source.frame_time);
  out += line;
  const uint32_t n = source.frame_count, channels = source.channel_count();
  const uint64_t period = n > 1 ? 2 * uint64_t(n - 1) : 1;
  out.reserve(out.size() + size_t(frames) * channels * 9);
  for (uint32_t f = 0; f < frames; ++f) {
    const uint64_t i = f % period;
    const size_t at = size_t(i < n ? i : period - i) * channels;
    for (uint32_t c = 0; c < channels; ++c) {
      const double drift = 0.5 * std::sin(2.0 * std::numbers::pi * f / (1500.0 + 37.0 * c) + c);
      const int len = std::snprintf(line, sizeof line, c ? " %.4f" : "%.4f", source.values[at + c] + drift);
      out.append(line, size_t(len));
    }
    out += '\n';
  }
  return out;
}

}  // namespace keyanim::bench
