// keyanim.Clip: a .kanim loaded and sampled in bulk (the GIL released), its info, decoding back
// to a Motion, and a clip made from a Motion's own frames.
#include <cerrno>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>

#include "common.h"
#include "dense_clip.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/guarded_read.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/error.h"

namespace keyanim::python {
namespace {

// A frame rate given to a Clip method: a finite number > 0, and a clip with a frame time.
double rate_arg(const PyClip& c, const py::object& fps) {
  const double r = fps.cast<double>();
  if (!(r > 0.0) || !std::isfinite(r))
    throw offline::Error(offline::ErrorKind::invalid_argument, "fps must be a finite number > 0");
  if (!(c.clip.frame_time() > 0.0))
    throw offline::Error(offline::ErrorKind::invalid_argument, "the clip has no frame time; cannot sample it at a rate");
  return r;
}

// Blanks (and a UTF-8 byte order mark), then HIERARCHY in any case: what the BVH reader takes.
bool starts_like_bvh(std::span<const uint8_t> b) {
  size_t i = b.size() >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF ? 3 : 0;
  while (i < b.size() && (b[i] == ' ' || (b[i] >= '\t' && b[i] <= '\r'))) ++i;
  static const char word[] = "hierarchy";
  for (size_t k = 0; k < 9; ++k, ++i)
    if (i >= b.size() || std::tolower(b[i]) != word[k]) return false;
  return true;
}

// A .kanim's bytes as a clip, or keyanim.Error naming `file` ("" for bytes).
void load_bytes(std::span<const uint8_t> bytes, const std::optional<std::string>& file, RigCache* rigs, PyClip& c) {
  ErrorInfo info;
  DecodeLimits limits;
  limits.check_content = true;  // a runtime-profile file is checked as thoroughly as an archive one
  if (Clip::load(bytes, c.clip, &info, limits, rigs) != Status::ok) {
    // A BVH file given where a .kanim goes: say where it goes instead of "bad signature".
    if (starts_like_bvh(bytes))
      throw offline::Error(offline::ErrorKind::malformed,
                           "is BVH text, not a .kanim: read it with keyanim.read_bvh(path), then keyanim.encode(motion) "
                           "for a .kanim's bytes or keyanim.Clip.from_motion(motion) for a clip of its frames",
                           file.value_or(""));
    throw offline::Error::kanim(file.value_or(""), info);
  }
  c.bytes = bytes.size();
}

std::shared_ptr<PyClip> load(const py::object& source, RigCache* rigs) {
  auto c = std::make_shared<PyClip>();
  if (is_bytes_like(source)) {
    const BufferBytes buffer(source);
    py::gil_scoped_release unlocked;
    load_bytes(buffer.bytes(), std::nullopt, rigs, *c);
    return c;
  }
  c->file = path_of(source);
  py::gil_scoped_release unlocked;
  const std::vector<uint8_t> bytes =
      offline::read_file_guarded(*c->file, offline::InputKind::kanim_or_stop, kMaxInputBytes, kLimitHint);  // the CLI's guards
  load_bytes(bytes, c->file, rigs, *c);
  return c;
}

// A position the clip does not have is keyanim.Error naming it and the clip's range, as
// `keyanim sample` refuses it (exit 1): positions are not clamped. A time may exceed the
// duration by rounding (duration = (frames - 1) frame time).
void check_positions(const PyClip& c, const Positions& p, const Positions* times) {
  const uint32_t n = c.clip.frame_count();
  const double last = n ? double(n - 1) : 0.0;
  for (size_t i = 0; i < p.values.size(); ++i) {
    const double pos = p.values[i];
    if (n > 0 && pos >= 0.0 && (pos <= last || (times && pos <= last * (1.0 + 1e-12)))) continue;
    char what[256];
    if (n == 0) std::snprintf(what, sizeof what, "the clip has no frames to sample");
    else if (times)
      std::snprintf(what, sizeof what, "time %.9g s is not in the clip (it has %u frames, times 0 to %.9g s)",
                    times->values[i], n, c.clip.duration());
    else std::snprintf(what, sizeof what, "frame %.9g is not in the clip (it has %u frames, 0 to %u)", pos, n, n - 1);
    throw offline::Error(offline::ErrorKind::invalid_argument, what, c.file.value_or(""));
  }
}

// Frame positions from times (seconds) or frames: exactly one of them, each in the clip.
Positions where(const PyClip& c, const py::handle& times, const py::handle& frames) {
  if (times.is_none() == frames.is_none()) throw py::type_error("give either times or frames (keyword), not both or neither");
  if (!frames.is_none()) {
    Positions p = positions_arg(frames, "frames");
    check_positions(c, p, nullptr);
    return p;
  }
  const Positions given = positions_arg(times, "times");
  Positions p = given;
  const double ft = c.clip.frame_time();
  for (double& t : p.values) t = ft > 0.0 ? t / ft : 0.0;  // as Clip::sample_time
  check_positions(c, p, &given);
  return p;
}

// Each quaternion node's Euler angles in rows [1, n) of every run of n rows (the positions'
// last axis) moved to the solution nearest the row before (nearest_euler): continuous along the
// positions, as to_motion()'s frames are.
void make_continuous(const Clip& clip, float* data, size_t rows, size_t n) {
  const size_t width = clip.channel_count();
  for (uint32_t q = 0; q < clip.quat_node_count(); ++q) {
    const Joint& joint = clip.skeleton().joints.at(clip.quat_node(q).node);
    uint32_t first = 0;
    quaternion_capable(joint, &first);  // (the loader checked that it is)
    const size_t column = joint.first_channel + first;
    for (size_t i = 0; i < rows; ++i) {
      if (i % n == 0) continue;
      float* row = data + i * width + column;
      const float* before = row - width;
      const double previous[3] = {before[0], before[1], before[2]};
      double deg[3] = {row[0], row[1], row[2]};
      nearest_euler(previous, deg);
      for (int k = 0; k < 3; ++k) row[k] = static_cast<float>(deg[k]);
    }
  }
}

// Every channel at every position: the channels' values (a quaternion node's rotation channels
// as Euler angles, with `continuous` each nearest the position's before), or with `stored`
// what the keys interpolate (its stored x, y, z).
py::array_t<float> sample(const PyClip& c, const Positions& p, bool stored = false, bool continuous = false) {
  const size_t width = c.clip.channel_count();
  py::array_t<float> out(shape_with(p.shape, {py::ssize_t(width)}));
  float* data = out.mutable_data();
  py::gil_scoped_release unlocked;
  Cursor cursor;
  if (cursor.prepare(c.clip) != Status::ok) throw std::bad_alloc();
  for (size_t i = 0; i < p.values.size(); ++i) {
    if (stored) c.clip.sample_stored(p.values[i], {data + i * width, width}, &cursor);
    else c.clip.sample(p.values[i], {data + i * width, width}, &cursor);
  }
  const size_t run = p.shape.empty() ? 1 : size_t(std::max<py::ssize_t>(p.shape.back(), 1));
  if (continuous && !stored) make_continuous(c.clip, data, p.values.size(), run);
  return out;
}

// What channel(c)["stored"] says a channel's keys hold.
const char* stored_name(StoredAs stored) {
  switch (stored) {
    case StoredAs::quat_x: return "quat_x";
    case StoredAs::quat_y: return "quat_y";
    case StoredAs::quat_z: return "quat_z";
    case StoredAs::value: break;
  }
  return "value";
}

// Clip.quat_nodes: one dict per quaternion node, in node order.
py::list quat_nodes(const PyClip& c) {
  py::list out;
  const Skeleton& s = c.clip.skeleton();
  for (uint32_t i = 0; i < c.clip.quat_node_count(); ++i) {
    const QuatNode n = c.clip.quat_node(i);
    const Joint& joint = s.joints.at(n.node);
    uint32_t first = 0;
    quaternion_capable(joint, &first);  // (the loader checked that it is)
    double q[4];
    reference_of(n, q);
    py::dict d;
    d["node"] = n.node;
    d["joint"] = text(offline::node_name(s, n.node));
    const uint32_t column = joint.first_channel + first;
    d["channels"] = py::make_tuple(column, column + 1, column + 2);
    d["reference"] = py::make_tuple(n.reference[0], n.reference[1], n.reference[2]);
    d["reference_quaternion"] = py::make_tuple(q[0], q[1], q[2], q[3]);
    out.append(d);
  }
  return out;
}

// Local or model transforms at every position: quaternions (..., nodes, 4), translations (..., nodes, 3).
std::pair<py::array_t<float>, py::array_t<float>> transforms(const PyClip& c, const Positions& p, bool model,
                                                             PositionReading reading, bool with_rotations) {
  const size_t nodes = c.clip.skeleton().joints.size();
  py::array_t<float> rotations(shape_with(p.shape, {py::ssize_t(with_rotations ? nodes : 0), 4}));
  py::array_t<float> translations(shape_with(p.shape, {py::ssize_t(nodes), 3}));
  float* q = rotations.mutable_data();
  float* t = translations.mutable_data();
  py::gil_scoped_release unlocked;
  Cursor cursor;
  if (cursor.prepare(c.clip) != Status::ok) throw std::bad_alloc();
  std::vector<Transform> pose(nodes);
  for (size_t i = 0; i < p.values.size(); ++i) {
    if (model) c.clip.sample_model(p.values[i], pose, &cursor, reading);
    else c.clip.sample_local(p.values[i], pose, &cursor, reading);
    for (size_t j = 0; j < nodes; ++j) {
      if (with_rotations) std::copy(pose[j].rotation, pose[j].rotation + 4, q + (i * nodes + j) * 4);
      std::copy(pose[j].translation, pose[j].translation + 3, t + (i * nodes + j) * 3);
    }
  }
  return {rotations, translations};
}

// A channel number (negative: from the end), IndexError outside the clip's channels.
uint32_t channel_index(const PyClip& c, int64_t channel) {
  const int64_t n = c.clip.channel_count();
  if (channel < -n || channel >= n)
    throw py::index_error("channel " + std::to_string(channel) + " is out of range for " + std::to_string(n) + " channels");
  return uint32_t(channel < 0 ? channel + n : channel);
}

const char* const kClipDoc =
    "Clip(path_or_bytes): a .kanim file loaded (validated completely: a damaged file raises\n"
    "keyanim.Error with its section and byte offset), sampled at any time or frame position.\n"
    "Values between frames come from the clip's curves. Sampling many positions at once releases\n"
    "the GIL, so threads sampling clips run in parallel. Nodes are the joints and End Sites in\n"
    "file order.\n\n"
    "Quaternion nodes (format 5.0, what encode() writes by default; see quat_nodes): a joint's\n"
    "three rotation channels may hold the x, y, z of its rotation relative to a reference\n"
    "rotation, rather than its Euler angles. sample() and sample_frames() still give every\n"
    "channel's Euler angle in degrees (computed from the rotation at each position, the middle\n"
    "angle in [-90, 90]); sample_stored() and channel_keys() give the stored x, y, z, and\n"
    "channel(c)['stored'] says which a channel holds.";

}  // namespace

std::shared_ptr<PyMotion> clip_to_motion(const Clip& clip, const py::object& fps) {
  offline::ResampleOptions options;
  if (!fps.is_none()) options.fps = fps.cast<double>();
  // As decode --fps: a rate whose frame time 1/fps is not a positive finite number (1e-320)
  // would write Frame Time: inf, which no reader takes back.
  if (!fps.is_none() && !(options.fps > 0.0 && std::isfinite(options.fps) && std::isfinite(1.0 / options.fps)))
    throw offline::Error(offline::ErrorKind::invalid_argument,
                         "fps must be a positive number with a finite frame time 1/fps, got " + std::string(py::repr(fps)));
  auto out = std::make_shared<PyMotion>();
  py::gil_scoped_release unlocked;
  out->motion = offline::decode_motion(clip, options);
  return out;
}

void register_clip(py::module_& m) {
  py::class_<PyClip, std::shared_ptr<PyClip>> cls(m, "Clip", kClipDoc);
  cls.attr("__module__") = "keyanim";  // as users import it (signatures say keyanim.Clip)
  py::class_<RigCache>(m, "RigCache",
                       "Clips of one rig (same nodes, names, parents, offsets, channel lists) loaded with\n"
                       "the same RigCache (Clip(path, rigs=cache)) share one skeleton in memory.")
      .def(py::init<>())
      .def_property_readonly("rig_count", &RigCache::rig_count, "Rigs in use by at least one clip.");
  cls.def(py::init(&load), py::arg("path_or_bytes"), py::arg("rigs") = nullptr,
          "Loads a .kanim from a path (str or os.PathLike) or from bytes (bytes, bytearray,\n"
          "memoryview; a view that is not C-contiguous, such as memoryview(b)[::2], is copied in\n"
          "order first, as bytes(view) would). A file is refused by its first bytes if it is not\n"
          "a .kanim (/dev/zero), and past 1 GiB. With rigs (a RigCache), clips of one rig share\n"
          "their skeleton.");
  cls.def_static(
      "from_motion",
      [](const PyMotion& motion) {
        auto c = std::make_shared<PyClip>();
        py::gil_scoped_release unlocked;
        c->clip = dense_clip(motion.motion);
        return c;
      },
      py::arg("motion"),
      "A clip holding every frame of `motion` as a key (no encoding, no keys dropped): Catmull-Rom\n"
      "curves through the source frames, for sampling a BVH at other times or rates as .kanim\n"
      "clips are sampled. Values at the frames are within half a float32 step of the channel's\n"
      "largest magnitude; angles are unwrapped (consecutive frames differ by less than 180\n"
      "degrees) as the encoder unwraps them.");
  cls.def_property_readonly("frame_count", [](const PyClip& c) { return c.clip.frame_count(); }, "Number of source frames.");
  cls.def_property_readonly("profile", [](const PyClip& c) { return c.clip.runtime_profile() ? "runtime" : "archive"; },
                            "The file's profile (spec/FORMAT.md section 9): 'archive' (entropy-coded, the smallest) or\n"
                            "'runtime' (the image a player samples in place).");
  cls.def(
      "runtime_bytes",
      [](const PyClip& c) {
        std::vector<uint8_t> b;
        {
          py::gil_scoped_release unlocked;
          b = offline::write_kanim_runtime(c.clip);
        }
        return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
      },
      "The clip as a runtime-profile .kanim (format 5.0 with quaternion nodes, else 4.0), which\n"
      "samples to the same values bit for bit: what `keyanim convert --runtime` writes.");
  cls.def(
      "archive_bytes",
      [](const PyClip& c) {
        std::vector<uint8_t> b;
        {
          py::gil_scoped_release unlocked;
          b = offline::write_kanim(offline::encoded_clip(c.clip));
        }
        return py::bytes(reinterpret_cast<const char*>(b.data()), b.size());
      },
      "The clip as an archive-profile .kanim (format 5.0 with quaternion nodes, else 3.0):\n"
      "`keyanim convert --archive`. The same keys and values; a constant channel's single key is\n"
      "stored as +-1 x |value|.");
  cls.def_property_readonly("frame_time", [](const PyClip& c) { return c.clip.frame_time(); }, "Seconds between frames.");
  cls.def_property_readonly("fps", [](const PyClip& c) { return fps_of(c.clip.frame_time()); },
                            "Frames per second, 1 / frame_time (None without a frame time).");
  cls.def_property_readonly("duration", [](const PyClip& c) { return c.clip.duration(); },
                            "(frame_count - 1) * frame_time seconds, 0 without frames.");
  cls.def_property_readonly("channel_count", [](const PyClip& c) { return c.clip.channel_count(); }, "Values per frame.");
  cls.def_property_readonly("total_keys", [](const PyClip& c) { return c.clip.total_keys(); }, "Keys over every channel.");
  cls.def_property_readonly("memory_bytes", [](const PyClip& c) { return c.clip.memory_bytes(); },
                            "Bytes the loaded clip holds in memory: skeleton_bytes + animation_bytes.");
  cls.def_property_readonly("skeleton_bytes", [](const PyClip& c) { return c.clip.skeleton_bytes(); },
                            "Bytes of the rig (names, parents, offsets, channel lists, pose tables): the same "
                            "for every clip of one skeleton.");
  cls.def_property_readonly("animation_bytes", [](const PyClip& c) { return c.clip.animation_bytes(); },
                            "Bytes of the clip's own motion (keys, records, per-channel facts, notes).");
  cls.def_property_readonly("rig_hash", [](const PyClip& c) { return c.clip.rig_hash(); },
                            "64-bit FNV-1a of the rig (each node's name, parent, offset bits, End Site flag and\n"
                            "channel list): equal for clips of one skeleton.");
  cls.def("shares_rig", [](const PyClip& a, const PyClip& b) { return a.clip.shares_rig(b.clip); }, py::arg("other"),
          "Whether both clips hold the very same skeleton in memory (loaded with one RigCache).");
  cls.def_property_readonly("encoder_notes", [](const PyClip& c) { return text(c.clip.encoder_notes()); },
                            "The encoder's key=value notes stored in the file (settings, error reached).");
  cls.def_property_readonly(
      "file", [](const PyClip& c) { return c.file ? py::object(text(*c.file)) : py::object(py::none()); },
      "The file it was loaded from, or None.");
  def_skeleton_properties(cls, [](const PyClip& c) -> const Skeleton& { return c.clip.skeleton(); });
  cls.def_property_readonly(
      "info",
      [](const PyClip& c) {
        py::dict info = to_python(offline::kanim_info(c.file.value_or(""), c.bytes, c.clip));
        if (!c.file) info["file"] = py::none();
        return info;
      },
      "A dict with the keys of `keyanim info --json` (version, frames, frame_time, joints,\n"
      "channels, size, keys per channel, tensions, memory_bytes, encoder_notes, ...).");
  cls.def(
      "sample",
      [](const PyClip& c, const py::object& times, bool continuous) {
        return sample(c, where(c, times, py::none()), false, continuous);
      },
      py::arg("times"), py::kw_only(), py::arg("continuous") = false,
      "Every channel at each time in seconds: float32 array times.shape + (channels,). Times\n"
      "are 0 to duration (others raise keyanim.Error naming them, as `keyanim sample --time`\n"
      "refuses them); between frames the values are in-betweens. A quaternion node's rotation\n"
      "channels give the Euler angles (degrees, in its channels' order) of its rotation at each\n"
      "time, computed time by time with the middle angle in [-90, 90]: not continuous across a\n"
      "wrap, unlike to_motion()'s (use local_transforms for rotations to learn or blend). With\n"
      "continuous=True, along the last axis of times each position's angles are those of the same\n"
      "rotation nearest the position's before (the other Euler solution, whole turns), as\n"
      "to_motion() chooses them: continuous as a BVH file's channels; the first as without.");
  cls.def(
      "sample_frames",
      [](const PyClip& c, const py::object& frames, bool continuous) {
        return sample(c, where(c, py::none(), frames), false, continuous);
      },
      py::arg("frames"), py::kw_only(), py::arg("continuous") = false,
      "Every channel at each frame position (fractional positions are in-betweens): float32\n"
      "array frames.shape + (channels,). Positions are 0 to frame_count - 1; others raise\n"
      "keyanim.Error naming them (as in local_transforms and world_positions). A quaternion\n"
      "node's rotation channels give Euler angles, as sample() does (continuous= too).");
  cls.def(
      "sample_stored",
      [](const PyClip& c, const py::object& frames) { return sample(c, where(c, py::none(), frames), true); },
      py::arg("frames"),
      "sample_frames(frames), but with what the keys hold: a quaternion node's rotation channels\n"
      "give its stored x, y, z (channel(c)['stored'] is 'quat_x', 'quat_y', 'quat_z'; the\n"
      "rotation relative to the node's reference, w = sqrt(max(0, 1 - x^2 - y^2 - z^2))), every\n"
      "other channel the same value as sample_frames. These are the curves through\n"
      "channel_keys() (spec/FORMAT.md Appendix A): equal to the keys' values at the key frames.");
  cls.def_property_readonly(
      "quat_nodes", &quat_nodes,
      "The nodes whose rotation is stored as a quaternion (format 5.0: encode(rotations=\n"
      "'quaternion'), the default), in node order; [] for a clip of Euler channels only. One dict\n"
      "each: node (index into joint_names), joint (its name), channels (the indices of its three\n"
      "rotation channels, which hold x, y, z in that order, whatever their axes), reference (the\n"
      "reference rotation's x, y, z as stored: ints in units of 2^-15, w rebuilt >= 0) and\n"
      "reference_quaternion (the same as a unit quaternion (x, y, z, w), float64). The node's\n"
      "rotation at a position is reference_quaternion * (x, y, z, w), normalized, with x, y, z from\n"
      "sample_stored and w = sqrt(max(0, 1 - x^2 - y^2 - z^2)).");
  cls.def(
      "local_transforms",
      [](const PyClip& c, const py::object& times, const py::object& frames, const std::string& reading) {
        auto [q, t] = transforms(c, where(c, times, frames), false, reading_arg(reading), true);
        return py::make_tuple(q, t);
      },
      py::arg("times") = py::none(), py::kw_only(), py::arg("frames") = py::none(),
      py::arg("position_channels") = "replace",
      "Each node's local transform at each time (or frame position, with frames=): a tuple of\n"
      "quaternions, float32 times.shape + (nodes, 4) as (x, y, z, w), and translations,\n"
      "times.shape + (nodes, 3). Quaternions are continuous in time. position_channels: how\n"
      "position channels below the root combine with OFFSET, as `keyanim sample --world\n"
      "--position-channels`: 'replace' (the default: Blender, BVH's usual reading) or 'add'\n"
      "(three.js).");
  cls.def(
      "world_positions",
      [](const PyClip& c, const py::object& times, const py::object& frames, const std::string& reading) {
        return transforms(c, where(c, times, frames), true, reading_arg(reading), false).second;
      },
      py::arg("times") = py::none(), py::kw_only(), py::arg("frames") = py::none(),
      py::arg("position_channels") = "replace",
      "World (model-space) position of every node at each time (or frame position, with\n"
      "frames=): float32 array times.shape + (nodes, 3). position_channels: 'replace' (the\n"
      "default) or 'add', as local_transforms.");
  cls.def(
      "channel",
      [](const PyClip& c, int64_t channel) {
        const ChannelInfo info = c.clip.channel(channel_index(c, channel));
        py::dict d;
        d["interpolation"] = info.interp == Interpolation::linear ? "linear" : "cardinal";
        d["tension"] = info.tension;
        d["key_count"] = info.key_count;
        d["stored"] = stored_name(info.stored);
        return d;
      },
      py::arg("channel"),
      "How one channel (index into channel_names) is stored: a dict with interpolation\n"
      "('cardinal' or 'linear'), tension (in [-1, 1]; 0 is Catmull-Rom), key_count and stored:\n"
      "what its keys hold, 'value' (the channel's own value: a position, or an Euler angle in\n"
      "degrees) or 'quat_x', 'quat_y', 'quat_z' (a quaternion node's stored x, y or z: quat_nodes).");
  cls.def(
      "channel_keys",
      [](const PyClip& c, int64_t index) {
        const uint32_t channel = channel_index(c, index);
        const uint32_t n = c.clip.channel(channel).key_count;
        py::array_t<uint32_t> frames(n);
        py::array_t<float> values(n);
        c.clip.channel_keys(channel, {frames.mutable_data(), n}, {values.mutable_data(), n});
        return py::make_tuple(frames, values);
      },
      py::arg("channel"),
      "The keys of one channel (index into channel_names): frames (uint32) and values (float32),\n"
      "exactly as the sampler uses them. No keys: the channel is 0 throughout; one: constant.\n"
      "The values are what channel(c)['stored'] says: a quaternion node's stored x, y or z (not\n"
      "degrees; sample_stored() interpolates them), else the channel's own values.");
  cls.def(
      "frame_count_at",
      [](const PyClip& c, const py::object& fps) -> uint64_t {
        if (fps.is_none() || c.clip.frame_count() <= 1) return c.clip.frame_count();
        return offline::rate_map(c.clip.frame_count() - 1, c.clip.frame_time(), rate_arg(c, fps)).count;
      },
      py::arg("fps") = py::none(),
      "How many frames to_motion(fps) makes: frame_count for fps=None; otherwise decode.h's rule\n"
      "(a rate within 0.01% of a multiple or divisor of the clip's own gives its frames, their\n"
      "in-betweens or every M-th of them; any other, frames every 1/fps s up to the end).");
  cls.def(
      "frame_positions_at",
      [](const PyClip& c, const py::object& fps, const py::array_t<int64_t, py::array::forcecast>& frames) {
        py::array_t<double> out(frames.request().shape);
        const int64_t* in = frames.data();
        double* o = out.mutable_data();
        const uint32_t n = c.clip.frame_count();
        const double last = n ? double(n - 1) : 0.0;
        if (fps.is_none() || n <= 1) {
          for (py::ssize_t i = 0; i < frames.size(); ++i) o[i] = std::clamp(double(in[i]), 0.0, last);
          return out;
        }
        const offline::RateMap rate = offline::rate_map(n - 1, c.clip.frame_time(), rate_arg(c, fps));
        for (py::ssize_t i = 0; i < frames.size(); ++i)
          o[i] = in[i] < 0 ? 0.0 : std::min(rate.position(uint64_t(in[i])), last);  // clamped to the clip
        return out;
      },
      py::arg("fps"), py::arg("frames"),
      "Source frame positions (float64, frames.shape) of output frames `frames` of\n"
      "to_motion(fps), clamped to the clip: what Dataset samples at a rate.");
  cls.def(
      "to_motion",
      [](const PyClip& c, const py::object& fps) { return clip_to_motion(c.clip, fps); },
      py::arg("fps") = py::none(),
      "Decodes the clip to a Motion: at the source frames (fps=None), or at frames every 1/fps\n"
      "seconds from the start up to the end (motion tweening: the in-betweens come from the curves),\n"
      "as `keyanim decode` does. Channels stored as values are sample_frames()'s at those\n"
      "positions; a quaternion node's rotation channels are Euler angles computed in float64, each\n"
      "frame's chosen nearest the frame before (continuous, as a BVH file's): the same rotations\n"
      "as sample_frames() gives (to about 1e-6 radians), but possibly other angles for them (by\n"
      "whole turns, or the other Euler triple).");
  cls.def("__repr__", [](const PyClip& c) {
    return "<keyanim.Clip: " + std::to_string(c.clip.frame_count()) + " frames, " +
           std::to_string(c.clip.skeleton().joints.size()) + " nodes, " + std::to_string(c.clip.channel_count()) +
           " channels, " + std::to_string(c.clip.total_keys()) + " keys>";
  });
}

}  // namespace keyanim::python
