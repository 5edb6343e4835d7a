#include "cli.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cmath>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

#include "keyanim/offline/bvh.h"
#include "keyanim/offline/decode.h"

namespace keyanim::cli {
namespace {

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
int write_all(int fd, const std::string& data) {
  size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : EIO;
    done += size_t(n);
  }
  return 0;
}

}  // namespace

void install_interrupt_cleanup() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) std::signal(sig, remove_temps_and_die);
}

void fail(int code, const std::string& message) { throw Failure{code, message}; }

Args::Args(const std::vector<std::string>& argv, const std::set<std::string>& valued,
           const std::set<std::string>& flags) {
  bool options_done = false;
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (options_done || a == "-" || a.empty() || a[0] != '-') {
      positional_.push_back(a);
      continue;
    }
    if (a == "--") {
      options_done = true;
      continue;
    }
    std::string name = a, value;
    bool has_inline = false;
    if (const size_t eq = a.find('='); a.rfind("--", 0) == 0 && eq != std::string::npos) {
      name = a.substr(0, eq), value = a.substr(eq + 1), has_inline = true;
    }
    if (valued.count(name)) {
      if (!has_inline) {
        if (i + 1 >= argv.size()) fail(kUsage, "option " + name + " needs a value");
        value = argv[++i];
      }
      values_[name] = value;
    } else if (flags.count(name) && !has_inline) {
      values_[name] = "";
    } else {
      fail(kUsage, "unknown option '" + a + "'");
    }
  }
}

std::optional<std::string> Args::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

double parse_double(const std::string& option, const std::string& text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  auto [p, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || p != end || !std::isfinite(v)) fail(kUsage, option + " expects a number, got '" + text + "'");
  return v;
}

uint32_t parse_uint(const std::string& option, const std::string& text) {
  uint32_t v = 0;
  const char* end = text.data() + text.size();
  auto [p, ec] = std::from_chars(text.data(), end, v);
  if (ec != std::errc() || p != end) fail(kUsage, option + " expects a non-negative integer, got '" + text + "'");
  return v;
}

double Args::get_double(const std::string& name, double fallback) const {
  auto v = get(name);
  return v ? parse_double(name, *v) : fallback;
}

uint32_t Args::get_uint(const std::string& name, uint32_t fallback) const {
  auto v = get(name);
  return v ? parse_uint(name, *v) : fallback;
}

std::vector<uint8_t> read_input(const std::string& path) {
  if (path == "-") {
    std::vector<uint8_t> bytes;
    char buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, stdin)) > 0) bytes.insert(bytes.end(), buf, buf + n);
    if (std::ferror(stdin)) fail(kBadInput, "-: cannot read standard input");
    return bytes;
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(kBadInput, path + ": is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(kBadInput, path + ": cannot open: " + std::strerror(errno));
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail(kBadInput, path + ": read error");
  return bytes;
}

bool looks_like_kanim(const std::vector<uint8_t>& b) {
  return b.size() >= 4 && b[0] == 0x89 && b[1] == 'K' && b[2] == 'A' && b[3] == 'N';
}

offline::Motion load_bvh_bytes(const std::string& path, const std::vector<uint8_t>& bytes, const Globals& g) {
  if (looks_like_kanim(bytes)) fail(kBadInput, path + ": is a .kanim file, expected BVH text");
  offline::Motion m;
  offline::BvhError err;
  std::vector<std::string> warnings;
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (!offline::read_bvh(text, path, m, err, &warnings)) fail(kBadInput, err.to_string());
  if (g.verbosity > 0)
    for (const std::string& w : warnings) std::cerr << "keyanim: warning: " << w << "\n";
  return m;
}

offline::Motion load_bvh(const std::string& path, const Globals& g) { return load_bvh_bytes(path, read_input(path), g); }

Clip load_kanim(const std::string& path, const std::vector<uint8_t>& bytes) {
  Clip clip;
  ErrorInfo info;
  const Status s = Clip::load(bytes, clip, &info);
  if (s != Status::ok) {
    char where[64];
    std::snprintf(where, sizeof where, "offset %llu (0x%llX)", static_cast<unsigned long long>(info.byte_offset),
                  static_cast<unsigned long long>(info.byte_offset));
    fail(s == Status::unsupported_version ? kUnsupported : kBadInput,
         path + ": section " + (info.section.empty() ? "?" : info.section) + ", " + where + ": " +
             status_string(s) + ": " + info.detail);
  }
  return clip;
}

offline::Motion load_motion(const std::string& path, const Globals& g) {
  const std::vector<uint8_t> bytes = read_input(path);
  if (!looks_like_kanim(bytes)) return load_bvh_bytes(path, bytes, g);
  const Clip clip = load_kanim(path, bytes);
  offline::Motion m;
  std::string error;
  if (!offline::decode_motion(clip, {}, m, error)) fail(kBadInput, path + ": " + error);
  return m;
}

std::string swap_extension(const std::string& path, const std::string& ext) {
  std::filesystem::path p(path);
  p.replace_extension(ext);
  return p.string();
}

void write_output(const std::string& path, const std::string& data, bool binary, const Globals& g) {
  if (path == "-") {
    if (binary && isatty(STDOUT_FILENO) && !g.force)
      fail(kOutputFailed, "refusing to write binary data to a terminal (use -o FILE, a pipe, or -f)");
    if (std::fwrite(data.data(), 1, data.size(), stdout) != data.size() || std::fflush(stdout) != 0)
      fail(kOutputFailed, "-: cannot write standard output: " + std::string(std::strerror(errno)));
    return;
  }
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(path, ec) && !g.force) fail(kOutputFailed, path + ": already exists; not overwritten (use -f)");
  if (fs::is_directory(path, ec)) fail(kOutputFailed, path + ": is a directory");
  // An existing device or pipe (e.g. -f -o /dev/null) is written to, never replaced by a file.
  if (const auto st = fs::status(path, ec); fs::exists(st) && !fs::is_regular_file(st)) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) fail(kOutputFailed, path + ": cannot open: " + std::strerror(errno));
    int err = write_all(fd, data);
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) fail(kOutputFailed, path + ": cannot write: " + std::strerror(err));
    return;
  }
  // A temporary file beside the target, renamed over it only once complete.
  fs::path target(path);
  std::string tmpl = (target.has_parent_path() ? target.parent_path() / "" : fs::path()).string() + "." +
                     target.filename().string() + ".tmp.XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const int fd = mkstemp(name.data());
  if (fd < 0) fail(kOutputFailed, path + ": cannot create a file in its directory: " + std::strerror(errno));
  const std::string tmp(name.data());
  const int slot = register_temp(tmp);
  int err = write_all(fd, data);  // first errno seen
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0) {  // mkstemp makes 0600; give the file the usual permissions
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::chmod(tmp.c_str(), 0666 & ~mask);
    // Without --force the rename itself refuses to replace a file that appeared meanwhile.
    const int r = g.force ? std::rename(tmp.c_str(), path.c_str())
                          : ::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, path.c_str(), RENAME_NOREPLACE);
    if (r != 0) err = errno;
  }
  if (err != 0) std::remove(tmp.c_str());
  unregister_temp(slot);
  if (err != 0) {
    if (err == EEXIST) fail(kOutputFailed, path + ": already exists; not overwritten (use -f)");
    fail(kOutputFailed, path + ": cannot write: " + std::strerror(err));
  }
}

}  // namespace keyanim::cli
