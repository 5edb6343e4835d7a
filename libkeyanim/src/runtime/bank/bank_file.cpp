// Why the opened part is read rather than mapped: a page cache filled by one large write holds
// the file in large folios (2 MB on Linux 6.18's ext4), and a fault on a mapping maps the whole
// folio, so touching a 4 KB index maps 2 MB. Read into anonymous pages, the index costs its own
// size, and the members stay in the page cache until a clip is sampled.
#include "runtime/bank/bank_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "internal/bank_layout.h"
#include "internal/byte_reader.h"

namespace keyanim::internal {
namespace {

struct Mapping {
  void* at = nullptr;
  size_t size = 0;
  ~Mapping() {
    if (at != nullptr) ::munmap(at, size);
  }
};

// Reads exactly `n` bytes at `offset`, or fails (a file shorter than fstat said).
bool read_at(int fd, void* to, size_t n, uint64_t offset) {
  auto* p = static_cast<uint8_t*>(to);
  while (n > 0) {
    const ssize_t r = ::pread(fd, p, n, static_cast<off_t>(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) {
      if (r == 0) errno = EIO;
      return false;
    }
    p += r, offset += uint64_t(r), n -= size_t(r);
  }
  return true;
}

// How many bytes from the start Bank's open reads: through the checksum after the skeletons, by
// the header's counts and the skeleton table. Only a hint: a damaged or hostile header gives 0
// or the file's size, and the index checks then decide from the mapping as from any bytes.
uint64_t opened_part(int fd, uint64_t size) {
  uint8_t h[kBankHeaderSize];
  if (size < kBankHeaderSize || !read_at(fd, h, sizeof h, 0)) return 0;
  const auto l = bank_index_layout(load_le<uint32_t>(h + 16), load_le<uint32_t>(h + 20), load_le<uint64_t>(h + 24),
                                   load_le<uint64_t>(h + 32), size);
  if (!l) return 0;
  const uint64_t table = l->clip_table - l->skeleton_table;
  if (table > (uint64_t(1) << 20)) return size;  // thousands of skeletons: read it all
  std::vector<uint8_t> t(table);
  if (!read_at(fd, t.data(), t.size(), l->skeleton_table)) return 0;
  uint64_t end = l->dictionary_end;
  for (size_t at = 0; at < t.size(); at += kBankSkeletonEntrySize) {
    const uint64_t offset = load_le<uint64_t>(&t[at]), stored = load_le<uint64_t>(&t[at + 8]);
    end = std::max(end, offset <= size && stored <= size - offset ? offset + stored : size);
  }
  return std::min(size, next_part(end) + kBankChecksumSize);
}

// Replaces the mapping's first `n` bytes (rounded up to pages) by private pages holding them.
bool read_into_mapping(int fd, Mapping& map, uint64_t n) {
  const size_t page = size_t(::sysconf(_SC_PAGESIZE));
  const size_t span = std::min(map.size, size_t((n + page - 1) / page * page));
  if (span == 0) return true;
  void* at = ::mmap(map.at, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED | MAP_POPULATE, -1, 0);
  return at != MAP_FAILED && read_at(fd, at, span, 0) && ::mprotect(at, span, PROT_READ) == 0;
}

}  // namespace

Status map_bank_file(const std::string& path, BankFile& out, ErrorInfo* err) {
  out = BankFile{};
  auto io_fail = [&](int fd, const char* what) {
    const int e = errno;
    if (fd >= 0) ::close(fd);
    if (err != nullptr) *err = ErrorInfo{Status::io_error, 0, "file", path + ": " + what + ": " + std::strerror(e)};
    return Status::io_error;
  };
  // O_NONBLOCK: a FIFO's open would wait for a writer; it is then refused as not a regular
  // file (the flag changes nothing for a regular file, which is mapped and read).
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return io_fail(-1, "cannot open");
  struct stat st {};
  if (::fstat(fd, &st) != 0) return io_fail(fd, "cannot stat");
  if (!S_ISREG(st.st_mode)) {
    errno = EINVAL;
    return io_fail(fd, "not a regular file");
  }
  auto map = std::make_shared<Mapping>();
  map->size = static_cast<size_t>(st.st_size);
  if (map->size > 0) {
    void* at = ::mmap(nullptr, map->size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (at == MAP_FAILED) return io_fail(fd, "cannot map");
    map->at = at;
    if (!read_into_mapping(fd, *map, opened_part(fd, map->size))) return io_fail(fd, "cannot read");
  }
  ::close(fd);
  out.bytes = std::span<const uint8_t>(static_cast<const uint8_t*>(map->at), map->size);
  out.storage = std::move(map);
  return Status::ok;
}

}  // namespace keyanim::internal
