#include "keyanim/offline/guarded_read.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <string_view>

#include "keyanim/offline/bvh.h"
#include "keyanim/offline/error.h"

namespace keyanim::offline {
namespace {

using offline::Error;
using offline::ErrorKind;

// Reads into `bytes` until it holds `want` bytes or the input ends; false at the end.
bool fill(int fd, const std::string& path, std::vector<uint8_t>& bytes, size_t want) {
  while (bytes.size() < want) {
    const size_t at = bytes.size();
    bytes.resize(want);
    const ssize_t n = ::read(fd, bytes.data() + at, want - at);
    bytes.resize(at + size_t(std::max<ssize_t>(n, 0)));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error::io(path, "read error", errno);
    if (n == 0) return false;
  }
  return true;
}

enum class Start { yes, no, undecided };

// Whether `b` can start BVH text: blanks and a UTF-8 byte order mark, then HIERARCHY in any
// case (what the reader accepts). Undecided while only blanks have been seen.
Start bvh_start(const std::vector<uint8_t>& b) {
  size_t i = b.size() >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF ? 3 : 0;
  while (i < b.size() && (b[i] == ' ' || (b[i] >= '\t' && b[i] <= '\r'))) ++i;
  const char* word = "hierarchy";
  for (size_t k = 0; k < 9; ++k, ++i) {
    if (i == b.size()) return Start::undecided;
    if (std::tolower(b[i]) != word[k]) return Start::no;
  }
  return Start::yes;
}

// Fails (malformed) unless the first bytes read can start a `kind` file, naming what is wrong
// as the reader would for BVH text (file:line:column). Undecided when only blanks were read.
// With InputKind::kanim_or_stop, a bad signature is Start::no instead: the caller's loader then says
// where and why, from the bytes read so far.
Start check_start(const std::string& path, const std::vector<uint8_t>& b, InputKind kind) {
  static const uint8_t kMagic[4] = {0x89, 'K', 'A', 'N'};
  const bool kanim = std::equal(b.begin(), b.begin() + std::min<size_t>(b.size(), 4), kMagic) && !b.empty();
  if (kind == InputKind::kanim || kind == InputKind::kanim_or_stop) {
    if (!kanim && !b.empty() && kind == InputKind::kanim_or_stop) return Start::no;
    if (!kanim && !b.empty()) throw Error(ErrorKind::malformed, "not a .kanim file (bad signature)", path);
    return Start::yes;
  }
  if (kanim && b.size() >= 4) {
    if (kind == InputKind::bvh) throw Error(ErrorKind::malformed, "is a .kanim file, expected BVH text", path);
    return Start::yes;
  }
  const Start s = bvh_start(b);
  if (s != Start::no) return s;
  (void)offline::read_bvh(std::string_view(reinterpret_cast<const char*>(b.data()), b.size()), path);
  throw Error(ErrorKind::malformed, "not BVH text", path);  // not reached: the reader wants HIERARCHY first
}

Error too_large(const std::string& path, uint64_t max, const std::string& hint) {
  return Error(ErrorKind::limit, "larger than the input limit of " + std::to_string(max) + " bytes (" + hint + ")", path);
}

}  // namespace

OpenedInput open_guarded(const std::string& path, uint64_t max_bytes, const std::string& limit_hint) {
  OpenedInput in;
  in.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (in.fd < 0) throw Error::io(path, "cannot open", errno);
  struct stat st;
  const int err = ::fstat(in.fd, &st) != 0 ? errno : 0;
  if (err || S_ISDIR(st.st_mode) || (S_ISREG(st.st_mode) && uint64_t(st.st_size) > max_bytes)) {
    ::close(in.fd);
    if (err) throw Error::io(path, "cannot read", err);
    if (S_ISDIR(st.st_mode)) throw Error::io(path, "cannot read", EISDIR);
    throw too_large(path, max_bytes, limit_hint);
  }
  in.regular = S_ISREG(st.st_mode);
  in.size = in.regular ? uint64_t(st.st_size) : 0;
  return in;
}

std::vector<uint8_t> read_guarded(int fd, const std::string& path, InputKind kind, uint64_t max_bytes, uint64_t size_hint,
                                  const std::string& limit_hint) {
  std::vector<uint8_t> bytes;
  // The first bytes decide whether to read on; then all of a regular file at once (one more
  // byte to see that it has not grown), or doubling chunks of a stream.
  uint64_t want = 1 << 16;
  Start start = Start::undecided;
  for (bool more = true; more;) {
    more = fill(fd, path, bytes, size_t(std::min(want, max_bytes + 1)));
    if (bytes.size() > max_bytes) throw too_large(path, max_bytes, limit_hint);
    if (start == Start::undecided) start = check_start(path, bytes, kind);
    if (start == Start::no) break;
    want = std::max<uint64_t>({want * 2, size_hint + 1});
  }
  return bytes;
}

std::vector<uint8_t> read_file_guarded(const std::string& path, InputKind kind, uint64_t max_bytes, const std::string& limit_hint) {
  const OpenedInput in = open_guarded(path, max_bytes, limit_hint);
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{in.fd};
  return read_guarded(in.fd, path, kind, max_bytes, in.size, limit_hint);
}

}  // namespace keyanim::offline
