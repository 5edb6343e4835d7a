// Shared plumbing of the keyanim subcommands: option parsing, exit codes, loading inputs and
// writing outputs safely (temporary file + rename, never clobbering without --force).
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/motion.h"

namespace keyanim::cli {

// Exit codes: documented in --help and the README; scripts depend on them.
enum Exit : int {
  kOk = 0,
  kUsage = 1,        // bad option, missing argument
  kBadInput = 2,     // input unreadable or malformed
  kUnsupported = 3,  // valid input using an unsupported version or feature
  kOutputFailed = 4, // output cannot be written (exists without -f, I/O error, terminal)
  kCheckFailed = 5,  // a requested check failed
};

// A failure carrying its exit code; thrown inside commands, caught once in main().
struct Failure {
  int code;
  std::string message;
};
[[noreturn]] void fail(int code, const std::string& message);

// On SIGINT/SIGTERM/SIGHUP/SIGPIPE: remove the temporary outputs being written, then die.
void install_interrupt_cleanup();

struct Globals {
  int verbosity = 1;   // 0 with -q, 2+ with -v
  bool force = false;  // -f/--force
};

// Parsed command line of one subcommand. Options are declared up front so that a typo is a
// usage error, not a silently ignored flag.
class Args {
 public:
  // `valued`: options that take a value (e.g. "-o", "--error"); `flags`: options that do not.
  Args(const std::vector<std::string>& argv, const std::set<std::string>& valued,
       const std::set<std::string>& flags);
  const std::vector<std::string>& positional() const { return positional_; }
  bool has(const std::string& name) const { return values_.count(name) > 0; }
  std::optional<std::string> get(const std::string& name) const;
  // Converts with a clear usage error naming the option.
  double get_double(const std::string& name, double fallback) const;
  uint32_t get_uint(const std::string& name, uint32_t fallback) const;

 private:
  std::vector<std::string> positional_;
  std::map<std::string, std::string> values_;
};

double parse_double(const std::string& option, const std::string& text);
uint32_t parse_uint(const std::string& option, const std::string& text);

// Whole file ("-" = standard input). Fails with kBadInput.
std::vector<uint8_t> read_input(const std::string& path);
bool looks_like_kanim(const std::vector<uint8_t>& bytes);

// BVH text -> motion, or exit 2 naming file:line:column. Warnings go to stderr unless quiet.
offline::Motion load_bvh(const std::string& path, const Globals& g);
offline::Motion load_bvh_bytes(const std::string& path, const std::vector<uint8_t>& bytes, const Globals& g);
// .kanim bytes -> clip, or exit 2 (3 for an unsupported version) naming section and offset.
Clip load_kanim(const std::string& path, const std::vector<uint8_t>& bytes);
// Either kind, by signature: a BVH becomes a motion; a .kanim is decoded at its source rate.
offline::Motion load_motion(const std::string& path, const Globals& g);

// Writes `data` to `path` atomically ("-" = standard output). Refuses to replace an existing
// file without --force and to write binary data to a terminal without --force.
void write_output(const std::string& path, const std::string& data, bool binary, const Globals& g);

// "walk.bvh" + ".kanim" -> "walk.kanim"
std::string swap_extension(const std::string& path, const std::string& ext);

}  // namespace keyanim::cli
