// keyanim.read_bvh, keyanim.Motion (its channels as a numpy view, BVH writing, forward
// kinematics) and keyanim.measure_error.
#include <cmath>

#include "common.h"
#include "keyanim/offline/guarded_read.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::python {
namespace {

// BVH text of `path` as a Motion; warnings (more motion lines than Frames: declares) are
// Python warnings.
}  // namespace

PyMotion read_bvh_path(const py::object& path_arg) {
  PyMotion m;
  m.source = path_of(path_arg);
  std::vector<std::string> warnings;
  {
    py::gil_scoped_release unlocked;
    // The CLI's guards (guarded_read.h): /dev/zero or a binary file is refused by its first
    // bytes, and nothing past the limit is read.
    const std::vector<uint8_t> bytes = offline::read_file_guarded(*m.source, offline::InputKind::bvh, kMaxInputBytes, kLimitHint);
    m.motion = offline::read_bvh(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                                 *m.source, &warnings);
    m.bvh_bytes = bytes.size();
  }
  for (const std::string& w : warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, std::string(py::str(text(w))).c_str(), 1) != 0) throw py::error_already_set();
  return m;
}

namespace {

// As BVH text, by the module's output rule (write_output).
void write_bvh_file(const offline::Motion& motion, const std::string& path, bool overwrite) {
  check_output(path, overwrite);
  // BVH text holds finite numbers only: nan or inf (set through `channels`) would write a file
  // that no reader takes back.
  if (!std::isfinite(motion.frame_time) || motion.frame_time < 0.0)
    throw offline::Error(offline::ErrorKind::invalid_argument, "the frame time is " + offline::general_text(motion.frame_time) +
                                                                   ": BVH text cannot hold it", path);
  for (size_t i = 0; i < motion.values.size(); ++i)
    if (!std::isfinite(motion.values[i]))
      throw offline::Error(offline::ErrorKind::invalid_argument,
                           "channel " + std::to_string(i % motion.channel_count()) + " of frame " +
                               std::to_string(i / motion.channel_count()) + " is " + offline::general_text(motion.values[i]) +
                               ": BVH text holds finite numbers only",
                           path);
  write_output(path, [&](const Put& put) {
    offline::BvhWriter writer(motion.skeleton, motion.frame_count, motion.frame_time, put);
    for (uint32_t f = 0; f < motion.frame_count; ++f) writer.frame(motion.frame(f));
    writer.finish();
  });
}

// Per frame of `frames`, `per_node` values for every node, from `pose(row, node, out)`.
template <class Pose>
py::array_t<double> per_node(const PyMotion& m, const py::handle& frames_arg_, size_t width, Pose pose) {
  const offline::Motion& motion = m.motion;
  const FrameList list = frames_arg(frames_arg_, motion.frame_count);
  const size_t nodes = motion.skeleton.joints.size();
  py::array_t<double> out(shape_with(list.shape, {py::ssize_t(nodes), py::ssize_t(width)}));
  double* data = out.mutable_data();
  py::gil_scoped_release unlocked;
  for (size_t i = 0; i < list.frames.size(); ++i) pose(motion.frame(list.frames[i]), data + i * nodes * width);
  return out;
}

// measure_error's shell= in units: as encode's (set_shell), a percentage of the original's size.
double shell_arg(const py::object& shell, const offline::Motion& original) {
  offline::EncodeSettings s;
  set_shell(shell, s);
  return s.shell_in_percent ? s.shell / 100.0 * offline::reference_size(original) : s.shell;
}

const char* const kMotionDoc =
    "A motion read from BVH (keyanim.read_bvh) or decoded from a clip (Clip.to_motion): a\n"
    "skeleton and a frames x channels matrix of values, exactly as the file holds them.\n"
    "Nodes are the joints and End Sites in file order; `channels` columns follow\n"
    "`channel_names`. Angles are in degrees, lengths in the file's units.";

}  // namespace

void register_motion(py::module_& m) {
  py::class_<PyMotion, std::shared_ptr<PyMotion>> cls(m, "Motion", kMotionDoc);
  cls.attr("__module__") = "keyanim";  // as users import it (signatures say keyanim.Motion)
  cls.def_property_readonly("frame_count", [](const PyMotion& self) { return self.motion.frame_count; },
                            "Number of frames.");
  cls.def_property_readonly("frame_time", [](const PyMotion& self) { return self.motion.frame_time; },
                            "Seconds between frames (frame i is at i * frame_time).");
  cls.def_property_readonly("channel_count", [](const PyMotion& self) { return self.motion.channel_count(); },
                            "Number of channels (values per frame).");
  cls.def_property_readonly("fps", [](const PyMotion& self) { return fps_of(self.motion.frame_time); },
                            "Frames per second, 1 / frame_time (None when frame_time is 0). BVH stores the\n"
                            "frame time rounded: a CMU file's 0.0083333 gives 120.0005, not 120.");
  cls.def_property_readonly(
      "duration",
      [](const PyMotion& self) { return self.motion.frame_count ? (self.motion.frame_count - 1) * self.motion.frame_time : 0.0; },
      "(frame_count - 1) * frame_time seconds, the time of the last frame (0 without frames), as\n"
      "Clip.duration.");
  cls.def_property_readonly(
      "source", [](const PyMotion& self) { return self.source ? py::object(text(*self.source)) : py::object(py::none()); },
      "The BVH file it was read from, or None.");
  cls.def_property(
      "channels",
      [](py::object self) {
        PyMotion& p = self.cast<PyMotion&>();
        const py::ssize_t frames = p.motion.frame_count, channels = p.motion.channel_count();
        static double empty = 0.0;  // numpy needs a pointer even for no values
        double* data = p.motion.values.empty() ? &empty : p.motion.values.data();
        return py::array_t<double>({frames, channels}, {py::ssize_t(sizeof(double)) * channels, py::ssize_t(sizeof(double))},
                                   data, self);
      },
      [](PyMotion& self, const py::array_t<double, py::array::c_style | py::array::forcecast>& values) {
        const py::ssize_t frames = self.motion.frame_count, channels = self.motion.channel_count();
        if (values.ndim() != 2 || values.shape(0) != frames || values.shape(1) != channels)
          throw py::value_error("channels must have shape (" + std::to_string(frames) + ", " + std::to_string(channels) + ")");
        std::copy(values.data(), values.data() + values.size(), self.motion.values.begin());
      },
      "float64 array (frames, channels): the motion's values, a view that writes through (edit it,\n"
      "then write_bvh or encode). Assigning an array of the same shape copies it in.");
  def_skeleton_properties(cls, [](const PyMotion& self) -> const Skeleton& { return self.motion.skeleton; });
  cls.def(
      "write_bvh",
      [](const PyMotion& self, const py::object& path, bool overwrite) {
        const std::string p = path_of(path);
        py::gil_scoped_release unlocked;
        write_bvh_file(self.motion, p, overwrite);
      },
      py::arg("path"), py::kw_only(), py::arg("overwrite") = false,
      "Writes the motion as BVH text that reads back bit for bit. The file is written to a\n"
      "temporary file beside `path` and renamed once complete; an existing file is replaced only\n"
      "with overwrite=True (else FileExistsError).");
  cls.def(
      "world_positions",
      [](const PyMotion& self, const py::object& frames, const std::string& position_channels) {
        const PositionReading reading = reading_arg(position_channels);
        return per_node(self, frames, 3, [&](const double* row, double* out) {
          thread_local std::vector<offline::Vec3> pos;
          offline::world_positions(self.motion.skeleton, row, pos, reading);
          for (size_t j = 0; j < pos.size(); ++j) std::copy(pos[j].begin(), pos[j].end(), out + 3 * j);
        });
      },
      py::arg("frames") = py::none(), py::kw_only(), py::arg("position_channels") = "replace",
      "World position of every node by forward kinematics (the ground truth keyanim measures\n"
      "errors with): float64 array frames.shape + (nodes, 3). frames: None (every frame), an int\n"
      "or an array of ints (negative ones count from the end). position_channels: how position\n"
      "channels below the root combine with OFFSET, as `keyanim sample --world\n"
      "--position-channels`: 'replace' (the default: Blender, BVH's usual reading) or 'add'\n"
      "(three.js).");
  cls.def(
      "local_quaternions",
      [](const PyMotion& self, const py::object& frames) {
        return per_node(self, frames, 4, [&](const double* row, double* out) {
          for (const Joint& j : self.motion.skeleton.joints) {
            const offline::Quat q = offline::local_quaternion(j, row);
            std::copy(q.begin(), q.end(), out);
            out += 4;
          }
        });
      },
      py::arg("frames") = py::none(),
      "Each node's local rotation (its Euler channels in their order) as a unit quaternion\n"
      "(x, y, z, w): float64 array frames.shape + (nodes, 4); the identity for End Sites.");
  cls.def("__repr__", [](const PyMotion& self) {
    return "<keyanim.Motion: " + std::to_string(self.motion.frame_count) + " frames, " +
           std::to_string(self.motion.skeleton.joints.size()) + " nodes, " +
           std::to_string(self.motion.channel_count()) + " channels>";
  });

  m.def("read_bvh", &read_bvh_path, py::arg("path"),
        "Reads a BVH file into a Motion, exactly (every value bit for bit). Raises keyanim.Error\n"
        "with file, line and column for malformed text, OSError when the file cannot be read.\n"
        "Releases the GIL while reading.");
  m.def(
      "measure_error",
      [](const PyMotion& original, const PyMotion& decoded, const py::object& shell) {
        const double distance = shell_arg(shell, original.motion);
        offline::ErrorReport report;
        {
          py::gil_scoped_release unlocked;
          report = offline::measure_error(original.motion, decoded.motion, distance);
        }
        return to_python(offline::error_json(original.motion.skeleton, report));
      },
      py::arg("original"), py::arg("decoded"), py::kw_only(), py::arg("shell") = "2%",
      "World-space distance between two motions of the same skeleton and frame count, over every\n"
      "joint, End Site and shell point (shell: as encode's, '2%' of the original's skeleton size\n"
      "by default, or a number of units; 0: joints and End Sites only) and frame, under both\n"
      "readings of position channels below the root when it has some: a dict like the 'error'\n"
      "of the encode report and of `keyanim verify --json` (max, rms, worst_joint, worst_point,\n"
      "worst_shell_axis, worst_frame, shell, readings; worst_reading and max_by_reading when both\n"
      "readings were measured). Raises keyanim.Error for motions that differ in layout.");
}

}  // namespace keyanim::python
