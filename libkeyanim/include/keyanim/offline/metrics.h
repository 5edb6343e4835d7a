// How far a decoded motion is from the original: world-space positions of every joint and End
// Site by forward kinematics, and per-channel value differences.
#pragma once
#include <cstdint>
#include <vector>

#include "keyanim/offline/motion.h"

namespace keyanim::offline {

struct ErrorReport {
  double max_error = 0.0;     // file length units, over every node and frame
  double rms_error = 0.0;     // over every node and frame
  uint32_t worst_joint = 0;   // node index (may be an End Site)
  uint32_t worst_frame = 0;
  std::vector<double> joint_max;    // per node
  std::vector<double> channel_max;  // per channel: length units, or degrees (compared modulo 360)
  double max_leaf_rotation = 0.0;   // degrees, largest channel error on a joint whose children
                                    // are all zero-length End Sites (a position metric misses it)
};

// Both motions must share the skeleton and frame count.
ErrorReport measure_error(const Motion& original, const Motion& decoded);

}  // namespace keyanim::offline
