// Keys for the glTF export fitted within the world-space tolerance. Euler curves do not map onto
// quaternion splines, so each animated joint's rotation is fitted (LINEAR, or CUBICSPLINE where
// fewer bytes) within a local angle; with LINEAR-only output each animated translation is fitted
// too, within a local distance. The local budgets are tightened where forward kinematics of what
// a glTF player computes strays beyond the tolerance.
#pragma once
#include <vector>

#include "gltf_curves.h"
#include "gltf_verify.h"
#include "keyanim/offline/encode.h"

namespace keyanim::offline::gltf {

// Sets model.nodes[j].rotation for every node j whose rotation is not always the identity (and,
// with linear_only, .translation for every node whose translation leaves its OFFSET), so that
// check_model(model, reference, tolerance) finds no violation. Other tracks already in the model
// stay. Returns the number of verification rounds; throws Error (limit) if float32 keys cannot
// hold the tolerance. `progress` as GltfOptions::progress (fitting, verifying).
uint32_t fit_keys(Model& model, const std::vector<NodeCurves>& nodes, const std::vector<ChannelCurve>& curves,
                  const Reference& reference, double tolerance, bool linear_only,
                  const std::function<void(EncodeStage, double)>& progress = {});

}  // namespace keyanim::offline::gltf
