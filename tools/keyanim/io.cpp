#include "io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>

#include "keyanim/offline/guarded_read.h"
#include "keyanim/offline/in_place.h"
#include "keyanim/offline/bvh.h"

namespace keyanim::cli {
namespace {

namespace fs = std::filesystem;

// Temporary outputs being written, so that an interrupt removes them (no partial files). Slots
// are fixed arrays: the signal handler may only touch memory that is already there.
constexpr int kMaxTemps = 256;
char g_temp_names[kMaxTemps][4096];
std::atomic<bool> g_temp_used[kMaxTemps];

int register_temp(const std::string& name) {
  if (name.size() >= sizeof g_temp_names[0]) return -1;
  for (int i = 0; i < kMaxTemps; ++i) {
    bool expected = false;
    if (g_temp_used[i].load() || !g_temp_used[i].compare_exchange_strong(expected, true)) continue;
    std::memcpy(g_temp_names[i], name.c_str(), name.size() + 1);
    return i;
  }
  return -1;
}

void unregister_temp(int slot) {
  if (slot >= 0) g_temp_used[slot].store(false);
}

extern "C" void remove_temps_and_die(int sig) {
  for (int i = 0; i < kMaxTemps; ++i)
    if (g_temp_used[i].load()) ::unlink(g_temp_names[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

// Writes everything, retrying short writes; 0 or the errno that stopped it.
int write_all(int fd, std::string_view data) {
  size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : EIO;
    done += size_t(n);
  }
  return 0;
}

std::optional<FileId> regular_id(const struct stat& st) {
  if (!S_ISREG(st.st_mode)) return std::nullopt;
  return FileId{st.st_dev, st.st_ino};
}

std::optional<FileId> fd_id(int fd) {
  struct stat st;
  if (::fstat(fd, &st) != 0) return std::nullopt;
  return regular_id(st);
}

bool contains(const std::vector<FileId>& ids, const std::optional<FileId>& id) {
  return id && std::find(ids.begin(), ids.end(), *id) != ids.end();
}

// Runs `work`, a guarded read (guarded_read.h): its offline::Error fails with the code of its
// kind (2 unreadable or malformed, 6 a limit).
template <class Work>
auto guarded(Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const offline::Error& e) {
    const Failure f = failure_of(e);
    fail(f.code, f.message);
  }
}

const char* const kLimitHint = "raise it with --max-input SIZE";

// The parent directory of `path` as a path that can be passed to the system ("." if none).
fs::path parent_of(const std::string& path) {
  const fs::path p(path);
  return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

// What is at an output path, after the checks every output gets (exit 4): it is not an input,
// not a directory, and not an existing file or symbolic link unless --force.
void check_target(const std::string& path, const std::vector<FileId>& inputs, bool force) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    if (::lstat(path.c_str(), &st) == 0 && !force)
      fail(kOutputFailed, path + ": already exists (a symbolic link); not overwritten (use -f)");
    return;
  }
  if (contains(inputs, regular_id(st)))
    fail(kOutputFailed, path + ": is an input; an input is never overwritten, even with -f");
  if (S_ISDIR(st.st_mode)) fail(kOutputFailed, path + ": is a directory");
  if (!force) fail(kOutputFailed, path + ": already exists; not overwritten (use -f)");
}

// Every directory on the way to `output` must be a directory, or not exist yet (a directory run
// creates it), and the deepest existing one must be writable.
void check_directories(const std::string& output) {
  struct stat st;
  for (fs::path dir = parent_of(output);;) {
    if (::stat(dir.c_str(), &st) == 0) {
      if (!S_ISDIR(st.st_mode)) fail(kOutputFailed, output + ": " + dir.string() + " is not a directory");
      if (::access(dir.c_str(), W_OK | X_OK) != 0)
        fail(kOutputFailed, output + ": cannot create files in " + dir.string() + ": " + std::strerror(errno));
      return;
    }
    if (errno == ENOTDIR) fail(kOutputFailed, output + ": " + dir.string() + " is not a directory");
    if (errno != ENOENT) return;  // left to the write itself to report
    const fs::path up = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
    if (up == dir) return;
    dir = up;
  }
}

}  // namespace

void install_interrupt_cleanup() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT}) std::signal(sig, remove_temps_and_die);
  // Past `ulimit -f` a write then fails with EFBIG, reported (exit 4) and cleaned up like a full
  // disk, instead of the process dying of SIGXFSZ with its temporary file left behind.
  std::signal(SIGXFSZ, SIG_IGN);
}

void flush_standard_output() {
  errno = 0;
  std::cout.flush();
  const bool lost = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout);
  const int err = errno;
  if (lost) fail(kOutputFailed, "-: cannot write standard output" + (err ? ": " + std::string(std::strerror(err)) : std::string()));
}

std::optional<FileId> input_id(const std::string& path) {
  if (path == "-") return fd_id(STDIN_FILENO);
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  return regular_id(st);
}

Input::Input(const std::string& path, const Globals& g)
    : path_(path), member_(member_path(path)), globals_(&g), max_bytes_(g.limits.max_input_bytes) {
  struct stat st;
  const std::string& file = member_ ? member_->bank : path;
  if (path == "-") {
    fd_ = STDIN_FILENO;
    if (::fstat(fd_, &st) != 0) fail(kBadInput, "-: cannot read: " + std::string(std::strerror(errno)));
    if (S_ISDIR(st.st_mode)) fail(kBadInput, "-: is a directory");
    if (S_ISREG(st.st_mode) && uint64_t(st.st_size) > max_bytes_)
      fail(kLimit, "-: larger than the input limit of " + std::to_string(max_bytes_) + " bytes (" + kLimitHint + ")");
    id_ = regular_id(st);
  } else {
    const offline::OpenedInput in = guarded([&] { return offline::open_guarded(file, max_bytes_, kLimitHint); });
    fd_ = in.fd;
    if (::fstat(fd_, &st) == 0) id_ = regular_id(st);
  }
  if (id_) size_hint_ = uint64_t(st.st_size);
  if (id_ && fd_id(STDOUT_FILENO) == id_) {
    if (fd_ > STDIN_FILENO) ::close(fd_);  // the destructor will not run
    fail(kOutputFailed, path + ": is also standard output; an input is never written to");
  }
}

Input::~Input() {
  if (fd_ > STDIN_FILENO) ::close(fd_);
}

std::vector<uint8_t> Input::read(Kind kind) {
  if (member_) {
    const std::vector<uint8_t> bank = guarded([&] {
      return offline::read_guarded(fd_, member_->bank, Kind::kanim, max_bytes_, size_hint_, kLimitHint);
    });
    return member_file(*member_, bank, *globals_);
  }
  return guarded([&] { return offline::read_guarded(fd_, path_, kind, max_bytes_, size_hint_, kLimitHint); });
}

std::vector<uint8_t> read_input(const std::string& path, Kind kind, const Globals& g) {
  return Input(path, g).read(kind);
}

offline::Motion load_bvh(const std::string& path, const Globals& g) {
  return load_bvh_bytes(path, read_input(path, Kind::bvh, g), g);
}

std::vector<FileId> ids_of(const std::vector<const Input*>& inputs) {
  std::vector<FileId> ids;
  for (const Input* in : inputs)
    if (in->id()) ids.push_back(*in->id());
  return ids;
}

void check_output_name(const std::string& path, const OutputFormat& format) {
  if (path == "-" || format.stated) return;
  std::string ext = fs::path(path).extension().string();
  if (ext.empty()) return;
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) return;
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (std::find(format.extensions.begin(), format.extensions.end(), ext) != format.extensions.end()) return;
  std::string names;
  for (size_t i = 0; i < format.extensions.size(); ++i)
    names += (i == 0 ? "" : i + 1 == format.extensions.size() ? " or " : ", ") + format.extensions[i];
  fail(kUsage, path + ": this writes " + format.what + ", which a " + ext + " name does not say; name it " + names +
                   (format.to.empty() ? "" : ", or give " + format.to + " to keep this name") + format.note);
}

Output::Output(const std::string& path, bool binary, const Globals& g, const std::vector<FileId>& inputs,
               const OutputFormat& format)
    : path_(path), force_(g.force) {
  if (path == "-") {
    if (binary && isatty(STDOUT_FILENO) && !g.force)
      fail(kOutputFailed, "refusing to write binary data to a terminal (use -o FILE, a pipe, or -f)");
    if (contains(inputs, fd_id(STDOUT_FILENO)))
      fail(kOutputFailed, "standard output is an input file; an input is never written to");
    fd_ = STDOUT_FILENO;
    return;
  }
  // An existing device, pipe or link to one (-f -o /dev/null), or a link to this process's own
  // standard output or error (-o /dev/stdout), is written in place, never renamed over.
  check_target(path, inputs, g.force);
  check_output_name(path, format);
  fd_ = offline::open_in_place(path);
  if (fd_ == -2) fail(kOutputFailed, path + ": cannot open: " + std::strerror(errno));
  if (fd_ >= 0) return;
  // A temporary file beside the target, renamed over it only once complete.
  const fs::path target(path);
  std::string tmpl = (target.has_parent_path() ? target.parent_path() / "" : fs::path()).string() + "." +
                     target.filename().string() + ".tmp.XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  fd_ = mkstemp(name.data());
  if (fd_ < 0) {
    const int err = errno;
    const std::string dir = parent_of(path).string();
    if (err == ENOENT) fail(kOutputFailed, path + ": directory " + dir + " does not exist");
    if (err == ENOTDIR) fail(kOutputFailed, path + ": " + dir + " is not a directory");
    fail(kOutputFailed, path + ": cannot create a file in " + dir + ": " + std::strerror(err));
  }
  temp_ = name.data();
  slot_ = register_temp(temp_);
}

Output::~Output() {
  if (committed_ || fd_ == STDOUT_FILENO) return;
  if (fd_ >= 0) ::close(fd_);
  if (!temp_.empty()) ::unlink(temp_.c_str());
  unregister_temp(slot_);
}

void Output::write(std::string_view data) {
  if (const int err = write_all(fd_, data); err != 0) {
    if (fd_ == STDOUT_FILENO) fail(kOutputFailed, "-: cannot write standard output: " + std::string(std::strerror(err)));
    fail(kOutputFailed, path_ + ": cannot write: " + std::strerror(err));
  }
}

void Output::commit() {
  if (fd_ == STDOUT_FILENO) {
    committed_ = true;
    return;
  }
  int err = 0;  // first errno seen
  if (!temp_.empty() && ::fsync(fd_) != 0) err = errno;
  if (::close(fd_) != 0 && err == 0) err = errno;
  fd_ = -1;
  if (err == 0 && !temp_.empty()) {  // mkstemp makes 0600; give the file the usual permissions
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::chmod(temp_.c_str(), 0666 & ~mask);
    // Without --force the rename itself refuses to replace a file that appeared meanwhile.
    const int r = force_ ? std::rename(temp_.c_str(), path_.c_str())
                         : ::renameat2(AT_FDCWD, temp_.c_str(), AT_FDCWD, path_.c_str(), RENAME_NOREPLACE);
    if (r != 0) err = errno;
  }
  if (err == EEXIST) fail(kOutputFailed, path_ + ": already exists; not overwritten (use -f)");
  if (err != 0) fail(kOutputFailed, path_ + ": cannot write: " + std::strerror(err));
  committed_ = true;
  unregister_temp(slot_);
}

void check_not_input(const std::string& output, const std::vector<FileId>& inputs) {
  struct stat st;
  if (::stat(output.c_str(), &st) == 0 && contains(inputs, regular_id(st)))
    fail(kOutputFailed, output + ": is an input; an input is never overwritten, even with -f");
}

void check_distinct(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs) {
  // By a hash of the lower-case path (16 bytes an entry, for lists of millions), equal hashes
  // compared in full; the first input by order is named first.
  auto key = [&](size_t i) {
    std::string k = fs::path(outputs[i]).lexically_normal().string();
    std::transform(k.begin(), k.end(), k.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return k;
  };
  std::vector<std::pair<size_t, size_t>> order;  // (hash, index)
  order.reserve(outputs.size());
  for (size_t i = 0; i < outputs.size(); ++i) order.emplace_back(std::hash<std::string>{}(key(i)), i);
  std::sort(order.begin(), order.end());
  for (size_t a = 0; a < order.size(); ++a)
    for (size_t b = a + 1; b < order.size() && order[b].first == order[a].first; ++b) {
      const size_t i = order[a].second, j = order[b].second;
      if (inputs[i] == inputs[j] || key(i) != key(j)) continue;  // one input listed twice is one input
      fail(kOutputFailed, inputs[i] + " and " + inputs[j] + " would both be written to " + outputs[j] +
                              (outputs[i] != outputs[j] ? " (or " + outputs[i] + ": the same file where case is ignored)" : "") +
                              "; rename one of them");
    }
}

void check_outputs(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs, const Globals& g) {
  check_distinct(inputs, outputs);
  std::vector<FileId> ids;
  for (const std::string& in : inputs)
    if (auto id = input_id(in)) ids.push_back(*id);
  for (const std::string& out : outputs) {
    check_target(out, ids, g.force);
    check_directories(out);
  }
}

}  // namespace keyanim::cli
