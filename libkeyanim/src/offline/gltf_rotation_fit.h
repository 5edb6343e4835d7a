// Quaternion keys for the glTF export: Euler curves do not map onto quaternion splines, so
// each animated joint's rotation is fitted (LINEAR or CUBICSPLINE, whichever takes fewer bytes)
// within a local angle, and the angles are tightened where forward kinematics of what a glTF
// player computes strays beyond the world-space tolerance.
#pragma once
#include <string>
#include <vector>

#include "gltf_curves.h"
#include "gltf_verify.h"

namespace keyanim::offline::gltf {

// Sets model.nodes[j].rotation for every node j whose rotation is not always the identity, so
// that check_model(model, reference, tolerance) finds no violation. Translations must already
// be in the model. Returns false with `error` if float32 keys cannot hold the tolerance.
// `rounds` receives the number of verification rounds.
bool fit_rotations(Model& model, const std::vector<NodeCurves>& nodes, const std::vector<ChannelCurve>& curves,
                   const Reference& reference, double tolerance, uint32_t& rounds, std::string& error);

}  // namespace keyanim::offline::gltf
