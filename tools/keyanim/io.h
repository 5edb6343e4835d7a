// Inputs and outputs of the commands, opened and checked before any work is done. An output is
// never an input (same device and inode, through hard links and symlinks, standard input and
// output included), never replaces an existing file without --force, and is written to a
// temporary file beside its target that is renamed over it only once complete: a failure or an
// interrupt leaves no partial output.
#pragma once
#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bank_io.h"
#include "cli.h"
#include "keyanim/offline/guarded_read.h"

namespace keyanim::cli {

using Kind = offline::InputKind;  // what an input must be (guarded_read.h)

// On SIGINT/SIGTERM/SIGHUP/SIGPIPE/SIGQUIT: remove the temporary outputs being written, then
// die. SIGXFSZ (past `ulimit -f`) is ignored, so that the write fails and is reported.
void install_interrupt_cleanup();

// After a command that succeeded: everything it printed reached standard output (exit 4 if not:
// a full disk, `>/dev/full`), so that lost output is never reported as success.
void flush_standard_output();

struct FileId {
  dev_t dev = 0;
  ino_t ino = 0;
  bool operator==(const FileId&) const = default;
};
// The identity of a regular file ("-": standard input), following symlinks; nothing for
// anything else (a device, a pipe, a missing file), which cannot be lost by writing to it.
std::optional<FileId> input_id(const std::string& path);

class Input {
 public:
  // Opens `path` ("-": standard input): exit 2 if it cannot be opened or is a directory, 6 if
  // it is a regular file larger than --max-input, 4 if standard output is this very file.
  // LIB:NAME (bank_io.h) opens the bank LIB, and read() gives its clip NAME as a .kanim file.
  Input(const std::string& path, const Globals& g);
  ~Input();
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;
  const std::string& path() const { return path_; }
  std::optional<FileId> id() const { return id_; }
  // The whole content. Stops early with exit 2 when the first bytes cannot start a `kind` file
  // (e.g. /dev/zero, a binary file), and with exit 6 past --max-input bytes.
  std::vector<uint8_t> read(Kind kind);

 private:
  std::string path_;
  std::optional<MemberPath> member_;  // LIB:NAME
  const Globals* globals_ = nullptr;
  int fd_ = -1;
  std::optional<FileId> id_;
  uint64_t max_bytes_ = 0;
  uint64_t size_hint_ = 0;  // a regular file's size when opened
};

// Convenience: opens and reads at once, for commands that write no file.
std::vector<uint8_t> read_input(const std::string& path, Kind kind, const Globals& g);
offline::Motion load_bvh(const std::string& path, const Globals& g);

// What an output holds, so that its name can be checked against it: `walk.fbx` holding BVH
// text, or `out.bvh` holding .kanim bytes, misleads every program that opens the file later.
struct OutputFormat {
  std::string what;                     // "BVH text", for the message
  std::vector<std::string> extensions;  // the names it may end with, lower case: {".bvh"}
  std::string to;                       // the option that states it ("--to bvh"), or "" if none
  bool stated = false;                  // the user stated it (--to): any name goes
  std::string note;                     // appended to the refusal: what other names would write
};

// Refuses (exit 1, usage) a name whose extension is none of `format`'s, unless the format was
// stated. Not checked: standard output ("-"), a name without an extension (/dev/stdout,
// `out`), and an existing device or FIFO (written in place: its name is not the user's choice).
void check_output_name(const std::string& path, const OutputFormat& format);

class Output {
 public:
  // Checks and opens `path` ("-": standard output) now, before the work: exit 4 if it exists
  // (without --force), is a directory, is one of `inputs`, or its directory is missing or not
  // writable; then exit 1 if its name does not say `format` (check_output_name); binary data
  // is not sent to a terminal without --force. A regular file is written to a new temporary
  // file beside it; an existing device or pipe is written in place.
  Output(const std::string& path, bool binary, const Globals& g, const std::vector<FileId>& inputs,
         const OutputFormat& format);
  ~Output();  // without commit(): the temporary file is removed
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
  const std::string& path() const { return path_; }
  void write(std::string_view data);  // exit 4 on an I/O error (e.g. a full disk)
  // Complete: the temporary file is renamed over the target (exit 4 if that fails).
  void commit();

 private:
  std::string path_, temp_;
  int fd_ = -1;
  int slot_ = -1;  // in the interrupt cleanup list
  bool force_ = false;
  bool committed_ = false;
};

// The identities of these inputs that are regular files.
std::vector<FileId> ids_of(const std::vector<const Input*>& inputs);

// Refuses (exit 4) `output` if it is one of `inputs` (for outputs that are appended to, such as
// a report, which may exist).
void check_not_input(const std::string& output, const std::vector<FileId>& inputs);

// Refuses (exit 4) two different inputs whose outputs are one file: paths equal ignoring ASCII
// case (as on case-insensitive file systems) once made lexically normal. The same input listed
// twice is not a collision. `inputs[i]` is written to `outputs[i]`.
void check_distinct(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs);

// Before a run over many inputs: refuses (exit 4) outputs that two inputs would share (paths
// equal ignoring ASCII case, as on case-insensitive file systems), outputs that are inputs,
// existing outputs without --force, outputs in the way of a directory, and an output
// directory that is not one. `inputs[i]` is written to `outputs[i]`.
void check_outputs(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs, const Globals& g);

}  // namespace keyanim::cli
