// The ways to choose key frames that do not look at the error: every N-th frame, or a list.
// (Curvature feature points: curvature.h. Error-bounded selection: encode.h.)
#pragma once
#include <cstdint>
#include <vector>

namespace keyanim::offline {

// 0, N, 2N, ... and the last frame. interval >= 1.
std::vector<uint32_t> uniform_keys(uint32_t frame_count, uint32_t interval);

// The user's frames, sorted, duplicates removed, with the first and last frame added. Throws
// Error (invalid_argument) if a frame is out of range.
std::vector<uint32_t> manual_keys(std::vector<uint32_t> frames, uint32_t frame_count);

}  // namespace keyanim::offline
