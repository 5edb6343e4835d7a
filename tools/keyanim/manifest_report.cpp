#include "manifest_report.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "cli.h"
#include "escape.h"

namespace keyanim::cli {
namespace fs = std::filesystem;

Report::Report(const std::string& path) : path_(path) {
  if (path.empty()) return;
  std::error_code ec;  // in OUTDIR, say, not made yet
  if (fs::path(path).has_parent_path()) fs::create_directories(fs::path(path).parent_path(), ec);
  fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0666);
  if (fd_ < 0) fail(kOutputFailed, path + ": cannot open the report: " + std::strerror(errno));
}

Report::~Report() {
  if (fd_ >= 0) ::close(fd_);
}

void Report::add(const nlohmann::json& line) {
  if (fd_ < 0) return;
  const std::string text = json_text(line) + "\n";  // a name that is not UTF-8 keeps its line
  std::lock_guard<std::mutex> lock(mutex_);
  const ssize_t n = ::write(fd_, text.data(), text.size());
  if (n != ssize_t(text.size())) fail(kOutputFailed, path_ + ": cannot append to the report: " + std::strerror(errno));
}

std::set<std::string> reported_done(const std::string& path) {
  std::set<std::string> done;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return done;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);  // a torn last line is skipped
    if (j.is_object() && j.contains("input") && j["input"].is_string() &&
        (j.value("status", "") == "ok" || j.value("status", "") == "skipped"))
      done.insert(j["input"].get<std::string>());
  }
  return done;
}

}  // namespace keyanim::cli
