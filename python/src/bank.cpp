// keyanim.Bank: many clips in one file (spec/FORMAT.md section 10), opened from its index alone
// (a path is mapped, not read), its clips loaded one at a time as keyanim.Clip; and
// keyanim.write_bank, which writes one from clips.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>

#include "common.h"
#include "keyanim/bank.h"
#include "keyanim/offline/bank.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/error.h"

namespace keyanim::python {
namespace {

struct PyBank {
  Bank bank;
  std::optional<std::string> file;
};

// A bank is mapped, so only a regular file will do: a FIFO is refused without waiting for a
// writer (O_NONBLOCK), a device such as /dev/zero by its type. OSError (with errno) when the
// path cannot be opened, as the module's other reads.
void check_mappable(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw offline::Error::io(path, "cannot open", errno);
  struct stat st {};
  const int err = ::fstat(fd, &st) != 0 ? errno : 0;
  ::close(fd);
  if (err) throw offline::Error::io(path, "cannot read", err);
  if (S_ISDIR(st.st_mode)) throw offline::Error::io(path, "cannot read", EISDIR);
  if (!S_ISREG(st.st_mode))
    throw offline::Error(offline::ErrorKind::io, "not a regular file (a bank is mapped into memory)", path);
}

[[noreturn]] void bank_failed(const std::optional<std::string>& file, ErrorInfo info) {
  if (info.status == Status::invalid_argument && info.section == "bank header")  // a .kanim of one clip
    info.detail += ": open it with keyanim.Clip(path)";
  throw offline::Error::kanim(file.value_or(""), info);
}

std::shared_ptr<PyBank> open_bank(const py::object& source) {
  auto b = std::make_shared<PyBank>();
  ErrorInfo info;
  if (is_bytes_like(source)) {
    const BufferBytes buffer(source);
    py::gil_scoped_release unlocked;
    if (Bank::open(buffer.bytes(), b->bank, &info) != Status::ok) bank_failed(std::nullopt, info);
    return b;
  }
  b->file = path_of(source);
  py::gil_scoped_release unlocked;
  check_mappable(*b->file);
  if (Bank::open_file(*b->file, b->bank, &info) != Status::ok) bank_failed(b->file, info);
  return b;
}

// A clip's name as the bank stores it: a str's UTF-8 (lone surrogates back to the bytes they
// stand for, as names are given out), or bytes as they are.
std::optional<std::string> name_bytes(const py::handle& name) {
  if (py::isinstance<py::bytes>(name)) return std::string(name.cast<py::bytes>());
  if (!py::isinstance<py::str>(name)) return std::nullopt;
  const py::bytes encoded = name.attr("encode")("utf-8", "surrogateescape");
  return std::string(encoded);
}

// A clip by index (an int; negative ones count from the end) or by name: IndexError or KeyError
// when the bank has no such clip.
uint32_t clip_index(const PyBank& b, const py::handle& key) {
  if (const auto name = name_bytes(key)) {
    if (const auto i = b.bank.find(*name)) return *i;
    throw py::key_error(std::string(py::repr(key)) + " names no clip of the bank");
  }
  if (py::isinstance<py::bool_>(key) || !PyIndex_Check(key.ptr()))
    throw py::type_error("a bank's clip is chosen by index (int) or name (str or bytes), not " +
                         std::string(py::str(py::type::handle_of(key).attr("__name__"))));
  const int64_t n = b.bank.clip_count();
  const int64_t i = py::reinterpret_steal<py::int_>(PyNumber_Index(key.ptr())).cast<int64_t>();
  if (i < -n || i >= n)
    throw py::index_error("clip " + std::to_string(i) + " is out of range for a bank of " + std::to_string(n) + " clips");
  return uint32_t(i < 0 ? i + n : i);
}

py::dict entry_dict(const PyBank& b, uint32_t i) {
  const BankEntry e = b.bank.entry(i);
  py::dict d;
  d["name"] = text(std::string(e.name));
  d["index"] = i;
  d["frames"] = e.frame_count;
  d["frame_time"] = e.frame_time;
  d["duration"] = e.frame_count ? (e.frame_count - 1) * e.frame_time : 0.0;  // as Clip.duration
  d["skeleton"] = e.skeleton;
  d["offset"] = e.offset;
  d["bytes"] = e.size;
  return d;
}

// Clip i, checked as Clip(path) checks a file; its file is "BANK:NAME" (the CLI's LIB:NAME).
std::shared_ptr<PyClip> load_clip(const PyBank& b, uint32_t i) {
  auto c = std::make_shared<PyClip>();
  const BankEntry e = b.bank.entry(i);
  if (b.file) c->file = *b.file + ":" + std::string(e.name);
  c->bytes = e.size;
  py::gil_scoped_release unlocked;
  ErrorInfo info;
  DecodeLimits limits;
  limits.check_content = true;  // as Clip(path)
  if (b.bank.clip(i, c->clip, &info, limits) != Status::ok) throw offline::Error::kanim(b.file.value_or(""), info);
  return c;
}

// write_bank's clips: a mapping of names to Clips, or (name, Clip) pairs, in the bank's order.
std::vector<std::pair<std::string, std::shared_ptr<PyClip>>> bank_inputs(const py::object& clips) {
  std::vector<std::pair<std::string, std::shared_ptr<PyClip>>> out;
  const py::iterable items = py::hasattr(clips, "items") ? py::iterable(clips.attr("items")()) : py::iterable(clips);
  for (const py::handle item : items) {
    const py::tuple pair = py::tuple(py::reinterpret_borrow<py::object>(item));
    if (pair.size() != 2) throw py::type_error("write_bank takes {name: clip} or (name, clip) pairs");
    const auto name = name_bytes(pair[0]);
    if (!name) throw py::type_error("a clip's name is a str (or bytes), not " + std::string(py::repr(pair[0])));
    if (!py::isinstance<PyClip>(pair[1]))
      throw py::type_error("write_bank takes keyanim.Clip values (keyanim.Clip(path), keyanim.Clip(keyanim.encode(motion)[0])), "
                           "not " + std::string(py::str(py::type::handle_of(pair[1]).attr("__name__"))));
    out.emplace_back(*name, pair[1].cast<std::shared_ptr<PyClip>>());
  }
  return out;
}

offline::BankOptions bank_options(bool runtime, const std::string& dictionary, const py::object& level) {
  offline::BankOptions o;
  o.runtime = runtime;
  if (dictionary == "auto") o.dictionary = offline::BankDictionary::automatic;
  else if (dictionary == "always") o.dictionary = offline::BankDictionary::always;
  else if (dictionary == "never") o.dictionary = offline::BankDictionary::never;
  else throw py::value_error("dictionary must be 'auto', 'always' or 'never', got '" + dictionary + "'");
  if (!level.is_none()) {
    if (py::isinstance<py::bool_>(level) || !PyIndex_Check(level.ptr()))
      throw py::type_error("level must be None or an integer, got " + std::string(py::repr(level)));
    o.zstd_level = level.cast<int>();
  }
  return o;
}

py::dict write_bank_file(const py::object& path_arg, const py::object& clips, bool runtime, const std::string& dictionary,
                         const py::object& level, bool overwrite) {
  const std::string path = path_of(path_arg);
  check_output(path, overwrite);
  const offline::BankOptions options = bank_options(runtime, dictionary, level);
  const auto inputs = bank_inputs(clips);
  offline::WrittenBank written;
  {
    py::gil_scoped_release unlocked;
    std::vector<offline::BankInput> in;
    in.reserve(inputs.size());
    for (const auto& [name, clip] : inputs) in.push_back({name, offline::encoded_clip(clip->clip)});
    written = offline::write_bank(in, options);
    write_output(path, [&](const Put& put) {
      put({reinterpret_cast<const char*>(written.bytes.data()), written.bytes.size()});
    });
  }
  py::dict report;
  report["file"] = text(path);
  report["clips"] = inputs.size();
  report["skeletons"] = written.skeletons;
  report["bytes"] = written.bytes.size();
  report["profile"] = runtime ? "runtime" : "archive";
  report["dictionary_bytes"] = written.dictionary_bytes;
  report["bytes_without_dictionary"] =
      written.bytes_without_dictionary ? py::object(py::int_(written.bytes_without_dictionary)) : py::object(py::none());
  return report;
}

const char* const kBankDoc =
    "Bank(path_or_bytes): a bank, many clips in one file (.kbank; spec/FORMAT.md section 10),\n"
    "opened from its index alone: no clip is read until asked for. A path (str or os.PathLike)\n"
    "is mapped into memory, so it must be a regular file (a FIFO or a device is refused at\n"
    "once); bytes, bytearray and memoryview are the bank's content, as for Clip, copied (a view\n"
    "that is not C-contiguous in order, as bytes(view) would). A damaged index raises\n"
    "keyanim.Error with its section and offset.\n\n"
    "len(bank) clips; `name in bank`; iterating gives the names in the bank's order. clip(i or\n"
    "name) loads one as a keyanim.Clip (clips of one skeleton share one rig in memory); a damaged\n"
    "clip raises keyanim.Error naming it, while the others still load.";

}  // namespace

void register_bank(py::module_& m) {
  py::class_<PyBank, std::shared_ptr<PyBank>> cls(m, "Bank", kBankDoc);
  cls.attr("__module__") = "keyanim";
  cls.def(py::init(&open_bank), py::arg("path_or_bytes"));
  cls.def("__len__", [](const PyBank& b) { return b.bank.clip_count(); });
  cls.def_property_readonly(
      "names",
      [](const PyBank& b) {
        py::list names;
        for (uint32_t i = 0; i < b.bank.clip_count(); ++i) names.append(text(std::string(b.bank.entry(i).name)));
        return names;
      },
      "The clips' names in the bank's order (str; bytes that are not UTF-8 as lone surrogates).");
  cls.def("__iter__", [](const py::object& self) { return py::iter(self.attr("names")); });
  cls.def("__contains__", [](const PyBank& b, const py::handle& name) {
    const auto bytes = name_bytes(name);
    return bytes && b.bank.find(*bytes).has_value();
  });
  cls.def_property_readonly(
      "entries",
      [](const PyBank& b) {
        py::list out;
        for (uint32_t i = 0; i < b.bank.clip_count(); ++i) out.append(entry_dict(b, i));
        return out;
      },
      "The index, one dict per clip in the bank's order: name, index, frames, frame_time,\n"
      "duration (seconds, (frames - 1) * frame_time), skeleton (its index in the bank), offset and\n"
      "bytes (where the clip lies in the bank). Read without loading any clip.");
  cls.def(
      "entry", [](const PyBank& b, const py::handle& key) { return entry_dict(b, clip_index(b, key)); }, py::arg("clip"),
      "One clip's entry of `entries`, by index or name (IndexError, KeyError).");
  cls.def(
      "find",
      [](const PyBank& b, const py::handle& name) -> py::object {
        const auto bytes = name_bytes(name);
        if (!bytes) throw py::type_error("a clip's name is a str or bytes");
        const auto i = b.bank.find(*bytes);
        return i ? py::object(py::int_(*i)) : py::object(py::none());
      },
      py::arg("name"), "The index of the clip of this name (binary search over the bank's name order), or None.");
  cls.def("clip", [](const PyBank& b, const py::handle& key) { return load_clip(b, clip_index(b, key)); }, py::arg("clip"),
          "The clip at an index (negative ones count from the end; IndexError outside the bank) or\n"
          "of a name (KeyError if none), checked as Clip(path) checks a file. Its `file` is\n"
          "'BANK:NAME'. Releases the GIL while loading.");
  cls.def(
      "to_motion",
      [](const PyBank& b, const py::handle& key, const py::object& fps) {
        return clip_to_motion(load_clip(b, clip_index(b, key))->clip, fps);
      },
      py::arg("clip"), py::arg("fps") = py::none(), "bank.clip(clip).to_motion(fps): the clip decoded to a Motion.");
  cls.def_property_readonly("skeleton_count", [](const PyBank& b) { return b.bank.skeleton_count(); },
                            "Distinct skeletons, each stored once (the entries' `skeleton` indexes them).");
  cls.def_property_readonly("profile", [](const PyBank& b) { return b.bank.runtime_profile() ? "runtime" : "archive"; },
                            "The clips' profile, as Clip.profile: 'archive' or 'runtime' (sampled in place).");
  cls.def_property_readonly("dictionary_bytes", [](const PyBank& b) { return b.bank.dictionary_bytes(); },
                            "Bytes of the zstd dictionary the archive clips share (0: none).");
  cls.def_property_readonly("size_bytes", [](const PyBank& b) { return b.bank.size_bytes(); }, "The bank's bytes.");
  cls.def_property_readonly(
      "file", [](const PyBank& b) { return b.file ? py::object(text(*b.file)) : py::object(py::none()); },
      "The file it was opened from, or None.");
  cls.def("__repr__", [](const PyBank& b) {
    return "<keyanim.Bank: " + std::to_string(b.bank.clip_count()) + " clips, " + std::to_string(b.bank.skeleton_count()) +
           " skeletons, " + (b.bank.runtime_profile() ? "runtime" : "archive") + ">";
  });

  m.def("write_bank", &write_bank_file, py::arg("path"), py::arg("clips"), py::kw_only(), py::arg("runtime") = false,
        py::arg("dictionary") = "auto", py::arg("level") = py::none(), py::arg("overwrite") = false,
        "write_bank(path, clips, *, runtime=False, dictionary='auto', level=None, overwrite=False)\n\n"
        "Writes a bank of `clips` ({name: keyanim.Clip} or (name, Clip) pairs, in the bank's order):\n"
        "each distinct skeleton once. Names are relative paths ('walk/start': no empty, '.' or '..'\n"
        "part, 1 to 1024 bytes, no two alike), else keyanim.Error. The clips' keys are kept as they\n"
        "are (encode a Motion first: keyanim.Clip(keyanim.encode(motion)[0])). runtime: the runtime\n"
        "profile (sampled in place, no dictionary); else the archive profile, its sections\n"
        "compressed with a zstd dictionary trained on them: dictionary 'auto' keeps it only when\n"
        "the bank is then smaller, 'always' whenever zstd trains one, 'never'. level: zstd's, as\n"
        "encode's. The file is written to a temporary file beside `path` and renamed once complete;\n"
        "an existing file is replaced only with overwrite=True (else FileExistsError). Returns a\n"
        "dict: file, clips, skeletons, bytes, profile, dictionary_bytes (0: none) and\n"
        "bytes_without_dictionary (with dictionary='auto' and a dictionary kept, the size the bank\n"
        "would have without it; else None).");
}

}  // namespace keyanim::python
