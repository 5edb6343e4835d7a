// The keyanim Python module (imported as keyanim; this is keyanim._keyanim): BVH reading and
// writing, encoding, loading and sampling clips, with numpy arrays. Datasets of many clips are
// built on it in keyanim/dataset.py.
#include "common.h"
#include "keyanim/version.h"

PYBIND11_MODULE(_keyanim, m) {
  using namespace keyanim::python;
  m.doc() = "keyanim: skeletal motion stored as keyframes, rebuilt by Cardinal splines.";
  m.attr("__version__") = KEYANIM_VERSION_STRING;
  // The version encode() writes by default (rotations as quaternion curves), as
  // keyanim_format_version() says; encode(rotations='euler') writes 3.0, which older decoders read.
  m.attr("format_version") = std::to_string(keyanim::kQuatFormatVersionMajor) + "." +
                             std::to_string(keyanim::kQuatFormatVersionMinor);
  register_errors(m);
  register_motion(m);
  register_encode(m);
  register_clip(m);
  register_bank(m);
}
