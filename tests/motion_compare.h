// Exact comparison of two motions for round-trip tests: skeleton fields equal, doubles compared
// by their bits (so -0.0 vs 0.0 or a changed last bit is a difference).
#pragma once
#include <cstring>
#include <string>

#include "keyanim/offline/motion.h"

namespace keyanim::test {

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Empty when a and b are identical; otherwise a description of the first difference.
inline std::string motion_difference(const keyanim::offline::Motion& a, const keyanim::offline::Motion& b) {
  const auto& ja = a.skeleton.joints;
  const auto& jb = b.skeleton.joints;
  if (ja.size() != jb.size())
    return "node count " + std::to_string(ja.size()) + " vs " + std::to_string(jb.size());
  for (size_t i = 0; i < ja.size(); ++i) {
    const std::string at = "node " + std::to_string(i) + " ('" + ja[i].name + "'): ";
    if (ja[i].name != jb[i].name) return at + "name vs '" + jb[i].name + "'";
    if (ja[i].parent != jb[i].parent) return at + "parent";
    if (ja[i].end_site != jb[i].end_site) return at + "end_site";
    if (ja[i].channels != jb[i].channels) return at + "channels";
    if (ja[i].first_channel != jb[i].first_channel) return at + "first_channel";
    for (int k = 0; k < 3; ++k)
      if (!same_bits(ja[i].offset[k], jb[i].offset[k])) return at + "offset[" + std::to_string(k) + "]";
  }
  if (a.frame_count != b.frame_count)
    return "frame_count " + std::to_string(a.frame_count) + " vs " + std::to_string(b.frame_count);
  if (!same_bits(a.frame_time, b.frame_time)) return "frame_time";
  if (a.values.size() != b.values.size())
    return "value count " + std::to_string(a.values.size()) + " vs " + std::to_string(b.values.size());
  for (size_t i = 0; i < a.values.size(); ++i)
    if (!same_bits(a.values[i], b.values[i])) return "value " + std::to_string(i);
  return {};
}

}  // namespace keyanim::test
