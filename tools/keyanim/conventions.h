// What a BVH file does not say, guessed for drawing it: which axis is up, and which reading of
// position channels below the root (keyanim/pose.h's PositionReading) keeps its bones rigid.
// `render` uses the guesses unless told (--up, --position-channels) and says so when the file
// leaves them open; the viewer's up axis follows the same rule (viewer/src/upaxis.js).
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include "keyanim/offline/motion.h"
#include "keyanim/pose.h"

namespace keyanim::cli {

enum class UpAxis : uint8_t { y = 1, z = 2 };  // the value is the axis's index

// A body is taller than it is deep: in the rest pose (Offsets alone), the one of y and z along
// which the skeleton spans more is up. When neither spans 1.5 times the other the guess is
// ambiguous and y (BVH's usual convention) is taken. CMU and Bandai files are y-up, MakeHuman's
// z-up.
struct UpGuess {
  UpAxis axis = UpAxis::y;
  bool ambiguous = true;
  std::array<double, 3> extents{};  // the rest pose's extent along x, y, z
};
UpGuess detect_up_axis(const Skeleton& skeleton);

// Bones are rigid. Of the nodes below the root that have position channels and a non-zero
// Offset, in frame `frame` of `motion`: how many keep their Offset's length (within 5%) under
// each reading (indexed by PositionReading), and how many there are. Bandai's channels repeat
// the Offset (every bone kept under replace, doubled under add) but for Hips, which carries the
// translation; MakeHuman's hold small deltas (replace collapses the bones, add keeps them).
struct RigidBones {
  std::array<uint32_t, 2> kept{0, 0};
  uint32_t nodes = 0;
};
RigidBones rigid_bones(const offline::Motion& motion, uint32_t frame);

// The reading under which the bones of that frame keep their lengths, when one clearly does
// (it keeps at least half of them, and 3 times as many as the other); else nothing.
std::optional<PositionReading> rigid_reading(const offline::Motion& motion, uint32_t frame);

}  // namespace keyanim::cli
