// Shared plumbing of the keyanim subcommands: exit codes, limits, option parsing and turning
// input bytes into motions and clips. (Opening inputs and writing outputs safely: io.h.)
#pragma once
#include <cstdint>
#include <exception>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "keyanim/clip.h"
#include "keyanim/offline/error.h"
#include "keyanim/offline/motion.h"

namespace keyanim::cli {

class EncodeProgress;

// Exit codes: one per kind of error, documented by kExitCodeTable (--help) and the README;
// scripts depend on them.
enum Exit : int {
  kOk = 0,
  kUsage = 1,         // bad option or value, conflicting options, a frame or joint the input lacks
  kBadInput = 2,      // input unreadable or malformed, or without what the command needs
  kUnsupported = 3,   // valid input using an unsupported version or feature
  kOutputFailed = 4,  // output cannot be written (exists without -f, is an input, collides, I/O)
  kCheckFailed = 5,   // a requested check failed
  kLimit = 6,         // a limit was reached: --max-input, --max-values, the loader's, memory
  kInternal = 7,      // a bug in keyanim
};
// The table as printed by --help (the README holds the same lines; a test compares them).
extern const char* const kExitCodeTable;

// A failure carrying its exit code; thrown inside commands, caught once in main() (or per
// input by a batch).
struct Failure {
  int code;
  std::string message;
};
[[noreturn]] void fail(int code, const std::string& message);
// The exit code and message for an exception that is not a Failure: an offline::Error that no
// command turned into one by its kind (invalid argument 1, malformed or unreadable input 2,
// unsupported 3, a limit 6), out of memory (or of threads) kLimit, anything else a bug
// (kInternal).
Failure failure_of(const std::exception& e);
// Runs `work`; an offline::Error it throws fails the command with `code`, `prefix` before the
// error's text.
template <class Work>
auto or_fail(int code, const std::string& prefix, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const offline::Error& e) {
    fail(code, prefix + e.what());
  }
}

// What keyanim takes from untrusted input at most (README, "Untrusted input").
struct Limits {
  uint64_t max_input_bytes = uint64_t(1) << 30;  // --max-input: bytes of one input file
  uint64_t max_values = uint64_t(1) << 28;       // --max-values: frames x channels made by a decode,
                                                 // and keys held by a loaded .kanim
};

struct Globals {
  int verbosity = 1;   // 0 with -q, 2+ with -v
  bool force = false;  // -f/--force
  Limits limits;
};

// Parsed command line of one subcommand. Options are declared up front so that a typo is a
// usage error, not a silently ignored flag.
class Args {
 public:
  // `valued`: options that take a value (e.g. "-o", "--error"); `flags`: options that do not.
  // "--output" is stored as "-o". An option given twice keeps its last value.
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
// --position-channels replace|add (default replace): how position channels below the root
// combine with OFFSET when posing (keyanim/pose.h). Usage error for another value.
PositionReading position_reading(const Args& args);
// "1000", "64K", "512M", "2G", "1T" (powers of 1024); at least 1.
uint64_t parse_size(const std::string& option, const std::string& text);

// Fails with kLimit unless `frames` frames of `channels` values (at least one a frame: each is
// a line of text) fit in --max-values. `what` names the request in the message.
void check_values(uint64_t frames, uint64_t channels, const std::string& what, const Globals& g);

bool looks_like_kanim(const std::vector<uint8_t>& bytes);
// BVH text -> motion, or exit 2 naming file:line:column. Warnings go to stderr unless quiet.
// With `progress`, parsing shows on its bar (progress.h).
offline::Motion load_bvh_bytes(const std::string& path, const std::vector<uint8_t>& bytes, const Globals& g,
                               EncodeProgress* progress = nullptr);
// .kanim bytes -> clip, or exit 2 (3 for an unsupported version, 6 over the loader's limits or
// more keys than --max-values) naming section and offset.
Clip load_kanim(const std::string& path, const std::vector<uint8_t>& bytes, const Globals& g);

// "walk.bvh" + ".kanim" -> "walk.kanim" (LIB.kbank:NAME: beside the bank, named after NAME)
std::string swap_extension(const std::string& path, const std::string& ext);

}  // namespace keyanim::cli
