#include "cli.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <new>
#include <system_error>

#include "bank_io.h"
#include "escape.h"
#include "keyanim/offline/bvh.h"
#include "progress.h"
#include "suggest.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kExitCodeTable =
    "exit codes:\n"
    "  0  success\n"
    "  1  usage: no command, an unknown command or option, a bad or out-of-range value,\n"
    "     conflicting options (e.g. --json with -o -), an output name that says another\n"
    "     format (-o walk.fbx for BVH text; --to states the format), a frame, joint or\n"
    "     channel the input does not have\n"
    "  2  input unreadable or malformed, or without what the command needs (no frames), or\n"
    "     not comparable with the other input (--against: another skeleton or frame count)\n"
    "  3  input uses an unsupported format version or feature\n"
    "  4  output cannot be written: exists (without -f), is an input, would also be another\n"
    "     input's output, is a directory, its directory is missing or read-only, disk full\n"
    "  5  a requested check failed (verify --max-error)\n"
    "  6  a limit was reached: input over --max-input, a decode or a .kanim's keys over\n"
    "     --max-values, a .kanim over the loader's other limits, out of memory\n"
    "  7  internal error: a bug in keyanim (please report it)\n";

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
    if (name == "--output" && valued.count("-o")) name = "-o";  // one option, two spellings: the last wins
    if (valued.count(name)) {
      if (!has_inline) {
        if (i + 1 >= argv.size()) fail(kUsage, "option " + name + " needs a value");
        value = argv[++i];
      }
      values_[name] = value;
    } else if (flags.count(name) && !has_inline) {
      values_[name] = "";
    } else {
      std::vector<std::string> known(valued.begin(), valued.end());
      known.insert(known.end(), flags.begin(), flags.end());
      fail(kUsage, "unknown option '" + a + "'" + did_you_mean(name, known));
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

PositionReading position_reading(const Args& args) {
  const std::optional<std::string> v = args.get("--position-channels");
  if (!v || *v == "replace") return PositionReading::replace;
  if (*v == "add") return PositionReading::add;
  fail(kUsage, "--position-channels expects replace or add, got '" + *v + "'");
}

uint64_t parse_size(const std::string& option, const std::string& text) {
  uint64_t v = 0;
  const char* end = text.data() + text.size();
  auto [p, ec] = std::from_chars(text.data(), end, v);
  int shift = 0;
  if (p + 1 == end) {
    const char* units = "KMGT";
    for (int k = 0; k < 4; ++k)
      if (*p == units[k] || *p == units[k] + ('a' - 'A')) shift = 10 * (k + 1), ++p;
  }
  if (ec != std::errc() || p != end || v == 0 || (shift && v > (UINT64_MAX >> shift)))
    fail(kUsage, option + " expects a size such as 1000, 64K, 512M or 2G (at least 1), got '" + text + "'");
  return v << shift;
}

void check_values(uint64_t frames, uint64_t channels, const std::string& what, const Globals& g) {
  const uint64_t per_frame = std::max<uint64_t>(channels, 1);
  if (frames <= g.limits.max_values / per_frame) return;
  const double values = double(frames) * double(per_frame);  // 4 digits shown: double is exact enough
  const std::string text = offline::general_text(values, 4) + " values (" + std::to_string(frames) + " frames x " +
                           std::to_string(channels) + " channels)";
  fail(kLimit, what + " would make " + text + ", over the limit of " + std::to_string(g.limits.max_values) +
                   " (raise it with --max-values N)");
}

Failure failure_of(const std::exception& e) {
  if (const auto* o = dynamic_cast<const offline::Error*>(&e)) {
    switch (o->kind()) {
      case offline::ErrorKind::invalid_argument: return {kUsage, e.what()};
      case offline::ErrorKind::unsupported: return {kUnsupported, e.what()};
      case offline::ErrorKind::limit: return {kLimit, e.what()};
      default: return {kBadInput, e.what()};
    }
  }
  if (dynamic_cast<const std::bad_alloc*>(&e) || dynamic_cast<const std::length_error*>(&e))
    return {kLimit, "out of memory"};
  if (const auto* s = dynamic_cast<const std::system_error*>(&e);
      s && (s->code() == std::errc::resource_unavailable_try_again || s->code() == std::errc::not_enough_memory))
    return {kLimit, std::string("out of resources: ") + e.what()};
  return {kInternal, std::string("internal error (a bug in keyanim; please report it): ") + e.what()};
}

bool looks_like_kanim(const std::vector<uint8_t>& b) {
  return b.size() >= 4 && b[0] == 0x89 && b[1] == 'K' && b[2] == 'A' && b[3] == 'N';
}

offline::Motion load_bvh_bytes(const std::string& path, const std::vector<uint8_t>& bytes, const Globals& g,
                               EncodeProgress* progress) {
  if (looks_like_kanim(bytes)) fail(kBadInput, path + ": is a .kanim file, expected BVH text");
  std::vector<std::string> warnings;
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  offline::BvhReadOptions options;
  if (progress) options.progress = progress->parsing();
  offline::Motion m = or_fail(kBadInput, "", [&] { return offline::read_bvh(text, path, &warnings, options); });
  if (progress && !warnings.empty()) progress->erase();
  if (g.verbosity > 0)
    for (const std::string& w : warnings) std::cerr << "keyanim: warning: " << printable(w) << "\n";
  return m;
}

Clip load_kanim(const std::string& path, const std::vector<uint8_t>& bytes, const Globals& g) {
  Clip clip;
  ErrorInfo info;
  DecodeLimits limits;  // a few compressed bytes can declare many keys: --max-values bounds them too
  limits.max_keys = std::min(limits.max_keys, g.limits.max_values);
  limits.check_content = true;  // a tool reads a runtime-profile file as thoroughly as an archive one
  const Status s = Clip::load(bytes, clip, &info, limits);
  if (s == Status::invalid_argument && looks_like_bank(bytes))
    fail(kBadInput, path + ": a bank of many clips: name one as " + path + ":NAME (keyanim list " + path + " lists them)");
  if (s != Status::ok) {
    const int code = s == Status::unsupported_version ? kUnsupported : s == Status::limit_exceeded ? kLimit : kBadInput;
    fail(code, offline::Error::kanim(path, info).what() +
                   std::string(s == Status::limit_exceeded
                                   ? " (keys are limited by --max-values; the loader's other limits are fixed)"
                                   : ""));
  }
  return clip;
}

std::string swap_extension(const std::string& path, const std::string& ext) {
  // A bank's clip, LIB.kbank:NAME: beside the bank, after the last part of NAME (lib/walk.bvh
  // for lib/data.kbank:cmu/walk), not after the bank's own name.
  if (const std::optional<MemberPath> m = member_path(path))
    return swap_extension((std::filesystem::path(m->bank).parent_path() / std::filesystem::path(m->name).filename()).string(), ext);
  std::filesystem::path p(path);
  p.replace_extension(ext);
  return p.string();
}

}  // namespace keyanim::cli
