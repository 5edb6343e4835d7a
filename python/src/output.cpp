// The module's outputs (Motion.write_bvh, write_bank) written by the CLI's rule: a temporary file
// beside the target, renamed once complete; never clobbering without overwrite; devices, FIFOs
// and links to them or to a standard stream written in place (in_place.h).
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "common.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/in_place.h"

namespace keyanim::python {

void check_output(const std::string& path, bool overwrite) {
  std::error_code ec;
  if (!overwrite && std::filesystem::symlink_status(path, ec).type() != std::filesystem::file_type::not_found && !ec)
    throw offline::Error::io(path, "exists (pass overwrite=True to replace it)", EEXIST);
}

void write_output(const std::string& path, const std::function<void(const Put&)>& produce) {
  int fd = offline::open_in_place(path);
  if (fd == -2) throw offline::Error::io(path, "cannot open", errno);
  std::string temp;
  if (fd < 0) {
    const std::filesystem::path target(path);
    const std::filesystem::path dir = target.has_parent_path() ? target.parent_path() : ".";
    temp = (dir / ("." + target.filename().string() + ".tmp.XXXXXX")).string();
    fd = mkstemp(temp.data());
    if (fd < 0) throw offline::Error::io(path, "cannot create a temporary file beside it", errno);
  }
  // A failed write ends `produce` (no more text is made for an output that cannot take it).
  const Put put = [&](std::string_view chunk) {
    for (size_t done = 0; done < chunk.size();) {
      const ssize_t n = ::write(fd, chunk.data() + done, chunk.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw offline::Error::io(path, "cannot write", n < 0 ? errno : EIO);
      done += size_t(n);
    }
  };
  try {
    produce(put);
  } catch (...) {
    ::close(fd);
    if (!temp.empty()) std::remove(temp.c_str());
    throw;
  }
  int failed = 0;
  if (!failed && !temp.empty() && ::fchmod(fd, 0644) != 0) failed = errno;  // mkstemp makes 0600
  if (::close(fd) != 0 && !failed) failed = errno;
  if (!failed && !temp.empty() && std::rename(temp.c_str(), path.c_str()) != 0) failed = errno;
  if (failed) {
    if (!temp.empty()) std::remove(temp.c_str());
    throw offline::Error::io(path, "cannot write", failed);
  }
}

}  // namespace keyanim::python
