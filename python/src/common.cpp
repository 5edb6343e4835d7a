#include <cmath>

#include "common.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/settings_text.h"

namespace keyanim::python {

BufferBytes::BufferBytes(const py::handle& source) {
  if (PyObject_GetBuffer(source.ptr(), &view_, PyBUF_FULL_RO) != 0) throw py::error_already_set();
  // bytes cannot change: read in place. Anything else (bytearray, a writable memoryview) is
  // copied, since another thread may write it while the GIL is released.
  if (PyBytes_CheckExact(source.ptr())) {
    bytes_ = {static_cast<const uint8_t*>(view_.buf), size_t(view_.len)};
    return;
  }
  try {
    copy_.resize(size_t(view_.len));
  } catch (...) {
    PyBuffer_Release(&view_);
    throw;
  }
  if (PyBuffer_ToContiguous(copy_.data(), &view_, view_.len, 'C') != 0) {
    PyBuffer_Release(&view_);
    throw py::error_already_set();
  }
  bytes_ = copy_;
}

BufferBytes::~BufferBytes() { PyBuffer_Release(&view_); }

bool is_bytes_like(const py::handle& source) {
  return py::isinstance<py::bytes>(source) || py::isinstance<py::bytearray>(source) || py::isinstance<py::memoryview>(source);
}

py::str text(const std::string& bytes) {
  PyObject* s = PyUnicode_DecodeUTF8(bytes.data(), py::ssize_t(bytes.size()), "surrogateescape");
  if (s == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(s);
}

std::string path_of(const py::handle& path) {
  if (!py::isinstance<py::str>(path) && !py::isinstance<py::bytes>(path) && !py::hasattr(path, "__fspath__"))
    throw py::type_error("expected a path (str, bytes or os.PathLike), got " +
                         std::string(py::str(py::type::handle_of(path).attr("__name__"))));
  const py::bytes encoded = py::module_::import("os").attr("fsencode")(path);
  return std::string(encoded);
}

py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return text(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const auto& v : j) list.append(to_python(v));
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (auto it = j.begin(); it != j.end(); ++it) dict[text(it.key())] = to_python(it.value());
      return dict;
    }
    default: throw std::logic_error("a JSON value the module does not convert");
  }
}

Positions positions_arg(const py::handle& array, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a) throw py::type_error(std::string(what) + " must be a number or an array of numbers");
  Positions p;
  p.shape.assign(a.shape(), a.shape() + a.ndim());
  p.values.assign(a.data(), a.data() + a.size());
  for (double v : p.values)
    if (std::isnan(v)) throw py::value_error(std::string(what) + " must not hold NaN");
  return p;
}

std::vector<py::ssize_t> shape_with(std::vector<py::ssize_t> lead, std::initializer_list<py::ssize_t> tail) {
  lead.insert(lead.end(), tail.begin(), tail.end());
  return lead;
}

FrameList frames_arg(const py::handle& frames, uint32_t frame_count) {
  FrameList list;
  std::vector<uint32_t>& out = list.frames;
  if (frames.is_none()) {
    out.resize(frame_count);
    for (uint32_t f = 0; f < frame_count; ++f) out[f] = f;
    list.shape = {py::ssize_t(frame_count)};
    return list;
  }
  const auto a = py::array::ensure(frames);
  if (!a || (a.size() > 0 && a.dtype().kind() != 'i' && a.dtype().kind() != 'u'))
    throw py::type_error("frames must be None or integers (an int, a list or an integer array)");
  const auto ints = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  list.shape.assign(ints.shape(), ints.shape() + ints.ndim());
  out.reserve(size_t(ints.size()));
  for (py::ssize_t i = 0; i < ints.size(); ++i) {
    int64_t f = ints.data()[i];
    if (f < 0) f += frame_count;
    if (f < 0 || f >= int64_t(frame_count))
      throw py::index_error("frame " + std::to_string(ints.data()[i]) + " is out of range for " +
                            std::to_string(frame_count) + " frames");
    out.push_back(uint32_t(f));
  }
  return list;
}

void set_shell(const py::handle& shell, offline::EncodeSettings& s) {
  if (py::isinstance<py::str>(shell)) {
    try {
      offline::parse_shell(shell.cast<std::string>(), s);
    } catch (const offline::Error& e) {
      throw offline::Error(offline::ErrorKind::invalid_argument, "shell: " + e.message());
    }
    return;
  }
  if (py::isinstance<py::bool_>(shell) || !(py::isinstance<py::float_>(shell) || py::isinstance<py::int_>(shell)))
    throw py::type_error("shell must be a str such as '2%' (percent of the skeleton size) or a number (units)");
  s.shell = shell.cast<double>();
  s.shell_in_percent = false;
  if (!(s.shell >= 0.0) || !std::isfinite(s.shell))
    throw offline::Error(offline::ErrorKind::invalid_argument,
                         "the shell distance must be a number, 0 or more, got " + std::string(py::repr(shell)));
}

PositionReading reading_arg(const std::string& reading) {
  if (reading == "replace") return PositionReading::replace;
  if (reading == "add") return PositionReading::add;
  throw py::value_error("position_channels must be 'replace' (Blender's reading, the default) or 'add' (three.js), got '" +
                        reading + "'");
}

}  // namespace keyanim::python
