// Which nodes the encoder stores as quaternion curves (spec/FORMAT.md section 4.7), about which
// reference, and their relative rotations as the signals the fit works on. Internal to the
// encoder.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "keyanim/offline/fk.h"
#include "keyanim/offline/motion.h"
#include "keyanim/rotation.h"

namespace keyanim::offline {

// The nodes whose rotation becomes quaternion curves: every quaternion_capable node whose
// rotation stays within kMaxQuatTurn of one reference over the clip (the mean of its
// sign-continuous quaternions, rounded to binary32). Beyond that, w of the relative rotation
// nears 0, where rebuilding it from x, y, z loses precision and x, y, z jump where it changes
// sign; such a node (a root turning around, say) keeps its Euler channels.
std::vector<QuatNode> choose_quat_nodes(const Motion& motion);

// Node n's rotation relative to its reference at every frame: out[k][f] for x, y, z, w
// (k = 0..3), unit, w >= 0 (the hemisphere rotation.h's rebuilt w lies in).
void quat_signals(const Motion& motion, const QuatNode& n, std::array<std::vector<double>, 4>& out);

// Frame f of `motion` in the form a clip with quaternion nodes `quats` stores it: its row, with
// each such node's rotation channels holding x, y, z of its relative rotation (as
// quat_signals), into out (channel_count values).
void stored_row(const Motion& motion, const QuatForms& quats, uint32_t f, double* out);

}  // namespace keyanim::offline
