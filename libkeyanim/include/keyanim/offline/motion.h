// A motion as the offline tools see it: a skeleton and a frames x channels matrix of values.
#pragma once
#include <cstdint>
#include <vector>

#include "keyanim/skeleton.h"

namespace keyanim::offline {

struct Motion {
  Skeleton skeleton;
  uint32_t frame_count = 0;
  double frame_time = 0.0;     // seconds; frame i is at i * frame_time (multiplied, never summed)
  std::vector<double> values;  // frame-major: values[f * channel_count + c]

  uint32_t channel_count() const noexcept { return skeleton.channel_count(); }
  const double* frame(uint32_t f) const noexcept { return values.data() + size_t(f) * channel_count(); }
  double* frame(uint32_t f) noexcept { return values.data() + size_t(f) * channel_count(); }
  double value(uint32_t f, uint32_t c) const noexcept { return values[size_t(f) * channel_count() + c]; }
  // One channel as a contiguous signal over frames.
  std::vector<double> channel(uint32_t c) const;
};

}  // namespace keyanim::offline
