#include "keyanim/offline/in_place.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace keyanim::offline {

namespace {

bool same_file(const struct stat& a, int fd) {
  struct stat b;
  return ::fstat(fd, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

}  // namespace

int open_in_place(const std::string& path) {
  struct stat st, lst;
  if (::stat(path.c_str(), &st) != 0) return -1;
  if (!S_ISREG(st.st_mode)) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);  // a FIFO waits for its reader
    return fd >= 0 ? fd : -2;
  }
  if (::lstat(path.c_str(), &lst) != 0 || !S_ISLNK(lst.st_mode)) return -1;
  for (int fd : {STDOUT_FILENO, STDERR_FILENO})
    if (same_file(st, fd)) {
      const int copy = ::fcntl(fd, F_DUPFD_CLOEXEC, 3);  // shares the stream's offset
      return copy >= 0 ? copy : -2;
    }
  return -1;
}

}  // namespace keyanim::offline
