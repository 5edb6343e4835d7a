// The Python module's shared pieces: the objects it wraps, text and path conversion, JSON to
// Python, and the registration function of each part (one file per part of the API).
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string_view>
#include <optional>
#include <string>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/motion.h"

namespace keyanim::python {

namespace py = pybind11;

// keyanim.Motion: a motion and, when it was read from a file, the file's path and size (the
// encode report gives them as input and bvh_bytes).
struct PyMotion {
  offline::Motion motion;
  std::optional<std::string> source;
  std::optional<uint64_t> bvh_bytes;
};

// keyanim.Clip: a loaded clip, and the file and byte count it came from (the info dict).
struct PyClip {
  Clip clip;
  std::optional<std::string> file;
  uint64_t bytes = 0;
};

// The most read from one file (read_bvh, Clip): the CLI's default --max-input, 1 GiB.
inline constexpr uint64_t kMaxInputBytes = uint64_t(1) << 30;
inline constexpr const char* kLimitHint = "the module reads at most 1 GiB of a file";

// The bytes of a buffer (bytes, bytearray, memoryview, ...) for as long as this lives: a bytes
// object's in place, any other buffer copied in C order as bytes(view) would (a strided or
// reversed view, memoryview(b)[::-1], is never read past its memory), so that the span may be
// read with the GIL released while other threads run. Destroy it with the GIL held.
class BufferBytes {
 public:
  explicit BufferBytes(const py::handle& source);
  ~BufferBytes();
  BufferBytes(const BufferBytes&) = delete;
  BufferBytes& operator=(const BufferBytes&) = delete;
  std::span<const uint8_t> bytes() const { return bytes_; }

 private:
  Py_buffer view_{};
  std::vector<uint8_t> copy_;
  std::span<const uint8_t> bytes_;
};
// bytes, bytearray or memoryview: what Clip and Bank take as a file's bytes (rather than a path).
bool is_bytes_like(const py::handle& source);

// Text from files (joint names, notes) may hold any bytes: bytes that are not UTF-8 become
// lone surrogates (PEP 383, "surrogateescape"), as `keyanim ... --json` writes them.
py::str text(const std::string& bytes);
// str, bytes or os.PathLike -> the path's bytes (os.fsencode).
std::string path_of(const py::handle& path);
// A JSON value of the CLI's reports as Python objects (dict, list, str, int, float, bool, None).
py::object to_python(const nlohmann::json& j);

// A float64 array of frame indices or times as a flat vector, with the array's shape kept for
// the result. Rejects NaN (ValueError).
struct Positions {
  std::vector<double> values;
  std::vector<py::ssize_t> shape;
};
Positions positions_arg(const py::handle& array, const char* what);
// Shape `lead` followed by `tail`.
std::vector<py::ssize_t> shape_with(std::vector<py::ssize_t> lead, std::initializer_list<py::ssize_t> tail);

// shell= of encode and measure_error, as --shell D|D%: a str ("2%", "3", "0") by the library's
// grammar, or a number of units -> settings.shell and shell_in_percent. keyanim.Error if
// negative or not finite, TypeError for another type.
void set_shell(const py::handle& shell, offline::EncodeSettings& settings);

// 'replace' or 'add' (position_channels=, as --position-channels), else ValueError.
PositionReading reading_arg(const std::string& reading);

// Frame indices for Motion methods: None -> every frame; else integers in [0, frame_count)
// (negative ones count from the end, as in numpy), IndexError otherwise; the shape is kept.
struct FrameList {
  std::vector<uint32_t> frames;
  std::vector<py::ssize_t> shape;
};
FrameList frames_arg(const py::handle& frames, uint32_t frame_count);

// Skeleton properties shared by Motion and Clip (joint_names, parents, offsets, ...).
template <class Class, class Get>
void def_skeleton_properties(Class& cls, Get skeleton_of);

// An output written by the module's rule (the CLI's): through a temporary file beside `path`,
// renamed over it once complete; an existing file is replaced only with overwrite (else
// FileExistsError); a device, a FIFO or a link to one, or to a standard stream, is written in
// place (in_place.h), never renamed over. check_output refuses the existing file (call it before
// anything else can fail); write_output calls `produce` with a function that writes a chunk.
using Put = std::function<void(std::string_view)>;
void check_output(const std::string& path, bool overwrite);
void write_output(const std::string& path, const std::function<void(const Put&)>& produce);

// Clip.to_motion (and Bank.to_motion): the clip decoded at its frames or at a rate.
std::shared_ptr<PyMotion> clip_to_motion(const Clip& clip, const py::object& fps);

// keyanim.read_bvh: a BVH file (str, bytes or os.PathLike) as a Motion, through the CLI's guards.
PyMotion read_bvh_path(const py::object& path);

// Motion.fps and Clip.fps: 1 / frame_time, None for a clip or motion without a frame time.
inline py::object fps_of(double frame_time) {
  return frame_time > 0.0 ? py::object(py::float_(1.0 / frame_time)) : py::object(py::none());
}

void register_errors(py::module_& m);
void register_motion(py::module_& m);
void register_encode(py::module_& m);
void register_clip(py::module_& m);
void register_bank(py::module_& m);

}  // namespace keyanim::python

#include "skeleton_properties.h"
