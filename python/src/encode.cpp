// keyanim.encode: a Motion to .kanim bytes and the report `keyanim encode --json` prints.
#include <chrono>
#include <cmath>
#include <cstdint>

#include "common.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/settings_text.h"

namespace keyanim::python {
namespace {

[[noreturn]] void invalid(const std::string& message) {
  throw offline::Error(offline::ErrorKind::invalid_argument, message);
}

// The library's grammar for a text argument, its error naming the argument.
template <class Parse>
void parse_argument(const char* name, const py::handle& value, offline::EncodeSettings& s, Parse parse) {
  try {
    parse(value.cast<std::string>(), s);
  } catch (const offline::Error& e) {
    invalid(std::string(name) + ": " + e.message());
  }
}

void set_tolerance(const py::handle& error, offline::EncodeSettings& s) {
  if (py::isinstance<py::str>(error)) return parse_argument("error", error, s, offline::parse_tolerance);
  if (py::isinstance<py::bool_>(error) || !(py::isinstance<py::float_>(error) || py::isinstance<py::int_>(error)))
    throw py::type_error("error must be a str such as '0.05%' (percent of the skeleton size) or a number (units)");
  s.tolerance = error.cast<double>();
  s.tolerance_in_percent = false;
  if (!(s.tolerance > 0.0) || !std::isfinite(s.tolerance))
    invalid("the tolerance must be a positive number, got " + std::string(py::repr(error)));
}

void set_keys(const py::handle& keys, offline::EncodeSettings& s) {
  if (py::isinstance<py::str>(keys)) return parse_argument("keys", keys, s, offline::parse_key_mode);
  // A sequence of frame numbers: manual keys.
  const auto a = py::array::ensure(keys);
  if (!a || a.ndim() != 1 || (a.size() > 0 && a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw py::type_error("keys must be 'error', 'uniform:N', 'manual:F1,F2,...', 'curvature' or a list of frames");
  const auto frames = py::array_t<int64_t, py::array::forcecast>::ensure(a);
  s.key_mode = offline::KeyMode::manual;
  s.manual_frames.clear();
  for (py::ssize_t i = 0; i < frames.size(); ++i) {
    const int64_t f = frames.at(i);
    if (f < 0 || f > int64_t(UINT32_MAX)) invalid("key frame " + std::to_string(f) + " is not a frame number");
    s.manual_frames.push_back(uint32_t(f));
  }
  if (s.manual_frames.empty()) invalid("keys: the list of key frames is empty");
}

// A whole number for setting `name` (int or numpy integer, not bool): out of int range is the
// setting's own error, not pybind11's "Unable to cast".
int whole_setting(const py::handle& value, const char* name) {
  if (py::isinstance<py::bool_>(value) || !PyIndex_Check(value.ptr()))
    throw py::type_error(std::string(name) + " must be an integer, got " + std::string(py::repr(value)));
  const long long v = PyLong_AsLongLong(py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr())).ptr());
  if (PyErr_Occurred()) PyErr_Clear();
  else if (v >= INT32_MIN && v <= INT32_MAX) return int(v);
  invalid(std::string(name) + " is out of range: " + std::string(py::repr(value)));
}

// The keyword settings, each as `keyanim encode` names it where it has an option.
void set_other(const py::kwargs& kwargs, offline::EncodeSettings& s) {
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (name == "shell") {
      set_shell(value, s);
    } else if (name == "tension") {
      if (py::isinstance<py::str>(value) && value.cast<std::string>() == "fit") s.fit_tension = true;
      else if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) s.tension = value.cast<float>();
      else throw py::type_error("tension must be a number in [-1, 1] or 'fit'");
    } else if (name == "level") {
      s.zstd_level = whole_setting(value, "level");
    } else if (name == "threads") {
      const int t = whole_setting(value, "threads");
      if (t < 0) invalid("threads must be >= 0 (0: one per core)");
      s.threads = uint32_t(t);
    } else if (name == "tangent_rule") {
      const std::string rule = value.cast<std::string>();
      if (rule == "step_adjusted") s.tangent_rule = TangentRule::step_adjusted;
      else if (rule == "uniform") s.tangent_rule = TangentRule::uniform;
      else invalid("tangent_rule must be 'step_adjusted' or 'uniform', got '" + rule + "'");
    } else if (name == "rotations") {
      if (!py::isinstance<py::str>(value))
        throw py::type_error("rotations must be 'quaternion' or 'euler' (a str), got " + std::string(py::repr(value)));
      const std::string form = value.cast<std::string>();
      if (form == "quaternion") s.rotations = offline::Rotations::quaternion;
      else if (form == "euler") s.rotations = offline::Rotations::euler;
      else invalid("rotations must be 'quaternion' or 'euler', got '" + form + "'");
    } else if (name == "allow_linear") {
      s.allow_linear = value.cast<bool>();
    } else if (name == "force_linear") {
      s.force_linear = value.cast<bool>();
    } else {
      throw py::type_error("encode() got an unexpected keyword argument '" + name +
                           "' (settings: shell, tension, level, threads, tangent_rule, rotations, allow_linear, "
                           "force_linear)");
    }
  }
  s.validate();
}

py::tuple encode_motion(const PyMotion& m, const py::object& error, const py::object& keys, const py::kwargs& kwargs) {
  offline::EncodeSettings settings;
  settings.threads = 0;  // as `keyanim encode` does for one file: one thread per core
  set_tolerance(error, settings);
  set_keys(keys, settings);
  set_other(kwargs, settings);
  offline::EncodeResult result;
  std::vector<uint8_t> bytes;
  double encode_ms = 0.0;
  {
    py::gil_scoped_release unlocked;
    const auto t0 = std::chrono::steady_clock::now();
    result = offline::encode(m.motion, settings);
    bytes = offline::write_kanim(result.clip, settings.zstd_level);
    encode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  py::dict report = to_python(offline::encode_summary("", "", m.motion, m.bvh_bytes.value_or(0), settings, result,
                                                  bytes.size(), encode_ms));
  report["input"] = m.source ? py::object(text(*m.source)) : py::object(py::none());
  report["output"] = py::none();
  if (!m.bvh_bytes) report["bvh_bytes"] = py::none();
  return py::make_tuple(py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size()), report);
}

// A Motion, or a path to a BVH file read as read_bvh reads it; anything else is a TypeError that
// says what encode takes (pybind's own lists signatures only).
py::tuple encode(const py::object& motion, const py::object& error, const py::object& keys, const py::kwargs& kwargs) {
  if (py::isinstance<PyMotion>(motion)) return encode_motion(motion.cast<const PyMotion&>(), error, keys, kwargs);
  const py::object fspath = py::module_::import("os").attr("PathLike");
  if (py::isinstance<py::str>(motion) || py::isinstance<py::bytes>(motion) || py::isinstance(motion, fspath))
    return encode_motion(read_bvh_path(motion), error, keys, kwargs);
  throw py::type_error("encode() takes a keyanim.Motion (keyanim.read_bvh(path), Clip.to_motion()) or the path of a "
                       "BVH file, not " + std::string(py::str(motion.get_type().attr("__name__"))));
}

}  // namespace

void register_encode(py::module_& m) {
  m.def("encode", &encode, py::arg("motion"), py::arg("error") = "0.05%", py::arg("keys") = "error",
        "encode(motion, error='0.05%', keys='error', **settings) -> (bytes, report)\n\n"
        "Encodes a Motion (or the BVH file at a path: str, bytes or os.PathLike, read as read_bvh\n"
        "reads it) into a .kanim file's bytes, as `keyanim encode` does, and returns them\n"
        "with a report dict holding the same keys as `keyanim encode --json`: frames, channels,\n"
        "frame_time, keys, bvh_bytes, raw_f32_bytes, kanim_bytes, ratio_raw_f32, encode_ms,\n"
        "error: {max, rms, worst_joint, worst_point, worst_shell_axis, worst_frame, shell,\n"
        "readings, and worst_reading and max_by_reading when both readings of position channels\n"
        "were measured}, and tolerance in file units; input is the motion's file, output None.\n\n"
        "error: the largest world-space distance any joint, End Site or shell point may move,\n"
        "  '0.05%' of the skeleton size (a str ending in %) or a number in the file's length units.\n"
        "keys: 'error' (the fewest keys within error), 'uniform:N', 'manual:F1,F2,...' or a list of\n"
        "  frames, 'curvature'. Modes other than 'error' report error_limit and error_limit_met\n"
        "  instead of tolerance.\n"
        "settings: shell (as --shell: three points per joint at that distance along its local axes,\n"
        "  '2%' of the skeleton size by default, a str ending in % or a number of units; 0: joints\n"
        "  and End Sites only), tension (in [-1, 1], default 0, or 'fit'), level (zstd, 1..22, on\n"
        "  every section; default: each section at its measured parameters), threads (default 0:\n"
        "  one per core; the bytes do not depend on it),\n"
        "  tangent_rule ('step_adjusted' or 'uniform'), rotations (as --rotations, below),\n"
        "  allow_linear (default True), force_linear (False). A motion with position channels below\n"
        "  the root is kept within error under both readings of them (replace and add).\n"
        "rotations: 'quaternion' (the default) stores each joint with three consecutive rotation\n"
        "  channels about three axes whose rotation moves, and stays within 145 degrees of one\n"
        "  reference, as the x, y, z of its rotation relative to that reference, on key frames the\n"
        "  three share: a format 5.0 file (fewer bytes; Clip.quat_nodes lists those joints, their\n"
        "  channels' keys are the stored x, y, z, and sampling still gives Euler angles). 'euler'\n"
        "  keeps every rotation as its Euler channels, keyed one by one: a format 3.0 file, which\n"
        "  decoders of formats 3 and 4 read, its keys the BVH's own angles. As `keyanim encode\n"
        "  --rotations`; anything else is keyanim.Error.\n\n"
        "Releases the GIL while encoding. Raises keyanim.Error for settings that make no sense or a\n"
        "motion the codec cannot store.");
}

}  // namespace keyanim::python
