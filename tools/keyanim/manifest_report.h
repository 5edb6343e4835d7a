// encode --manifest --report R.jsonl: one JSON line per finished input, and, read back, the
// inputs an earlier run finished (so that a resumed run does not list them again).
#pragma once
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

namespace keyanim::cli {

// Each line is appended by a single write() to a file opened with O_APPEND, so that lines from
// several processes never interleave (on a local file system; on NFS give each process its own
// report). An empty path: no report, add() does nothing.
class Report {
 public:
  explicit Report(const std::string& path);  // exit 4 if it cannot be opened
  ~Report();
  Report(const Report&) = delete;
  Report& operator=(const Report&) = delete;
  void add(const nlohmann::json& line);  // thread-safe; exit 4 if the write fails

 private:
  std::string path_;
  int fd_ = -1;
  std::mutex mutex_;
};

// Inputs already in the report at `path` as done (ok or skipped). Only a regular file is read
// back: a device or a FIFO (--report /dev/stdout) holds no earlier run, and /dev/zero would be
// read without end.
std::set<std::string> reported_done(const std::string& path);

}  // namespace keyanim::cli
