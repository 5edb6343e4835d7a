// From a loaded clip back to a motion: at the source frame rate, at another rate, or with N
// in-between frames per source frame interval (motion tweening: values come from the curves).
#pragma once
#include <cstdint>
#include <string>

#include "keyanim/clip.h"
#include "keyanim/offline/motion.h"

namespace keyanim::offline {

struct ResampleOptions {
  double fps = 0.0;         // Defaults to 0: the source rate. Otherwise frames every 1/fps s.
  uint32_t inbetweens = 0;  // Defaults to 0. N > 0: N extra frames in every source interval.
  uint32_t first_frame = 0;            // Defaults to 0: source frame range to decode
  uint32_t last_frame = UINT32_MAX;    // Defaults to the last frame (inclusive).
};

// Fails (returns false) only for options that make no sense (fps <= 0 but non-zero, both fps and
// inbetweens, an empty or reversed range); `error` says why.
bool decode_motion(const Clip& clip, const ResampleOptions& options, Motion& out, std::string& error);

}  // namespace keyanim::offline
