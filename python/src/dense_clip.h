// A clip holding every frame of a motion as a key: how keyanim.Clip.from_motion (and so a
// Dataset over BVH files) samples a BVH at any time with the clip's own curves.
#pragma once
#include "keyanim/clip.h"
#include "keyanim/offline/motion.h"

namespace keyanim::python {

// Every channel keyed at every frame, Catmull-Rom (tension 0); rotation channels unwrapped as the
// encoder unwraps them. Each channel is quantized with the power-of-two step that keeps its
// largest magnitude to float32 precision, so a key is within half that step of the source
// value. Throws offline::Error for what a .kanim cannot hold (validate_encoded_clip).
Clip dense_clip(const offline::Motion& motion);

}  // namespace keyanim::python
