// Verification against what a decoder reproduces: the encoded channels decoded with the
// decoder's own arithmetic (cardinal.h), posed by FK and compared with the original pose on
// the measured points (metrics.h), window of frames by window, so that memory does not grow
// with the clip. Internal to the encoder.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"

namespace keyanim::offline {

// The values a decoder computes for channel `ch` at the sorted frames `frames[0..count)`, into
// out[i * stride]: the stored keys dequantized, segment_operands, segment_u, eval_operands, with
// the curve clamped outside its keys and exactly a key's value at a key.
void decode_channel_at(const EncodedChannel& ch, TangentRule rule, const uint32_t* frames, size_t count, double* out,
                       size_t stride);

// Frame ranges [first, last] (increasing, disjoint) outside which `before` and `after` decode
// to the same values over a clip of `frame_count` frames. A value depends on the (up to) four
// keys around it, so each key that differs (present in one only, or with another value)
// spreads to two keys either side in both lists. May include frames whose value is the same.
void changed_ranges(const EncodedChannel& before, const EncodedChannel& after, uint32_t frame_count,
                    std::vector<std::pair<uint32_t, uint32_t>>& out);

// A node farther from its original than the tolerance at some frame.
struct OverNode {
  uint32_t frame = 0;
  uint32_t node = 0;
  double error = 0.0;  // file length units: the largest distance among the node's measured points
};

// Working memory of verify_window, one per thread.
struct VerifyScratch {
  std::vector<uint32_t> frames;
  std::vector<double> rows;
  std::vector<Vec3> original, decoded;
};

// Verifies the frames f of [first, first + count) whose check[f] is set: decodes every channel
// there, poses original and decoded, and appends to `over` each node whose error exceeds
// `tolerance` (frame order, then node order) with its error, computed as measure_error does.
// check[f] stays set for frames with a node over and is cleared for the others.
void verify_window(const Motion& original, const std::vector<EncodedChannel>& channels, TangentRule rule,
                   double tolerance, uint32_t first, uint32_t count, uint8_t* check, std::vector<OverNode>& over,
                   VerifyScratch& scratch);

// The error report of `clip` (valid: validate_encoded_clip) against `original`, on the clip a
// decoder loads (to_clip) sampled by Clip::sample at every frame: measure_error's numbers,
// computed window by window on `threads` threads.
ErrorReport measure_encoded(const Motion& original, const EncodedClip& clip, unsigned threads);

}  // namespace keyanim::offline
