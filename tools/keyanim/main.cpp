// keyanim: command-line front end. Dispatches to one subcommand; global options may appear
// anywhere before "--".
#include <cstdio>
#include <cstring>
#include <iostream>
#include <new>
#include <optional>
#include <string>
#ifdef __GLIBC__
#include <malloc.h>  // mallopt
#endif

#include "commands.h"
#include "escape.h"
#include "io.h"
#include "keyanim/version.h"
#include "settings.h"
#include "suggest.h"

namespace keyanim::cli {
namespace {

struct Command {
  const char* name;
  int (*run)(const Argv&, Globals&);
  const char* const* help;
  enum { none, all, all_but_error } encoder_options;  // the shared ones of settings.h
  const char* summary;
};

const Command kCommands[] = {
    {"encode", cmd_encode, &kEncodeHelp, Command::all, "BVH -> .kanim (keyframes within a tolerance)"},
    {"decode", cmd_decode, &kDecodeHelp, Command::none, ".kanim -> BVH, at the source or another frame rate"},
    {"info", cmd_info, &kInfoHelp, Command::none, "describe a BVH or .kanim file"},
    {"sample", cmd_sample, &kSampleHelp, Command::none, "one pose of a .kanim at a frame or time"},
    {"plot", cmd_plot, &kPlotHelp, Command::all, "SVG: one channel, original against reconstruction, keys marked"},
    {"render", cmd_render, &kRenderHelp, Command::all, "SVG: one frame as a stick figure, front and side view"},
    {"eval", cmd_eval, &kEvalHelp, Command::all_but_error, "compression against error for files and tolerances"},
    {"convert", cmd_convert, &kConvertHelp, Command::none, ".kanim -> .kanim in the other profile: runtime (sampled in place) or archive"},
    {"pack", cmd_pack, &kPackHelp, Command::all, "many clips into one bank (.kbank): each skeleton once, clips by name"},
    {"list", cmd_list, &kListHelp, Command::none, "the clips of a bank, from its index"},
    {"unpack", cmd_unpack, &kUnpackHelp, Command::none, "every clip of a bank as a .kanim file of its own"},
    {"verify", cmd_verify, &kVerifyHelp, Command::none, "check a .kanim, and its error against the original"},
    {"view", cmd_view, &kViewHelp, Command::none, "HTML page that plays a .kanim in the browser (3D skeleton)"},
};

const char* const kGlobalHelp =
    "global options (before or after the command; short ones combine, e.g. -qV or -fq):\n"
    "  -h, --help            this help (after a command: that command's help)\n"
    "  -V, --version         tool and format versions (-qV: the bare version)\n"
    "  -v, --verbose         more messages on standard error\n"
    "  -q, --quiet           no messages but errors, no progress\n"
    "  -f, --force           overwrite existing outputs (never an input); allow binary output\n"
    "                        to a terminal\n"
    "  --max-input SIZE      largest input file read, in bytes (K, M, G: powers of 1024);\n"
    "                        default 1G\n"
    "  --max-values N        most values (frames x channels) a decode may make, and most keys\n"
    "                        a loaded .kanim may hold; default 256M\n";

// The usage lines and the list of commands: the start of --help, and all a bare `keyanim` says.
void print_usage(std::ostream& out) {
  out << "Usage: keyanim [GLOBAL OPTIONS] COMMAND [OPTIONS] INPUT [-o OUTPUT]\n"
         "  or:  keyanim help [COMMAND]\n"
         "keyanim " KEYANIM_VERSION_STRING ": skeletal motion stored as keyframes only, every other frame\n"
         "rebuilt by Cardinal-spline interpolation.\n\ncommands:\n";
  char line[160];
  for (const Command& c : kCommands) {
    std::snprintf(line, sizeof line, "  %-8s %s\n", c.name, c.summary);
    out << line;
  }
  out << "  help     this help, or a command's: keyanim help COMMAND (= keyanim COMMAND --help)\n";
}

void print_main_help() {
  print_usage(std::cout);
  std::cout << "\n" << kGlobalHelp << "\n" << kExitCodeTable << "\nRun 'keyanim help COMMAND' for a command's options.\n";
}

const Command* find_command(const std::string& name) {
  for (const Command& c : kCommands)
    if (name == c.name) return &c;
  return nullptr;
}

[[noreturn]] void unknown_command(const std::string& name) {
  std::vector<std::string> names;
  for (const Command& c : kCommands) names.push_back(c.name);
  fail(kUsage, "unknown command '" + name + "'" + did_you_mean(name, names));
}

void print_command_help(const Command& c) {
  std::cout << *c.help;
  if (c.encoder_options != Command::none) std::cout << encoder_options_help(c.encoder_options == Command::all);
  std::cout << "\n" << kGlobalHelp << "\n" << kExitCodeTable;
}

// `keyanim help [COMMAND]`.
int help_command(const Argv& rest) {
  if (rest.empty()) return print_main_help(), kOk;
  if (rest.size() > 1) fail(kUsage, "help takes at most one command");
  const Command* c = find_command(rest.front());
  if (!c) unknown_command(rest.front());
  print_command_help(*c);
  return kOk;
}

// The value of global option `name` at argv[i] ("--name V" or "--name=V"), advancing i past it.
std::optional<std::string> global_value(const std::string& a, const std::string& name, int argc, char** argv, int& i) {
  if (a.rfind(name + "=", 0) == 0) return a.substr(name.size() + 1);
  if (a != name) return std::nullopt;
  if (i + 1 >= argc) fail(kUsage, "option " + name + " needs a value");
  return std::string(argv[++i]);
}

// A global short flag, or a cluster of them ("-qV", "-fq"), applied left to right as if given
// one by one. False if `a` is not made of global flags only (it may be a command's option).
bool global_flags(const std::string& a, Globals& g, bool& help, bool& version) {
  if (a.size() < 2 || a[0] != '-' || a.find_first_not_of("hVvqf", 1) != std::string::npos) return false;
  for (size_t k = 1; k < a.size(); ++k) {
    switch (a[k]) {
      case 'h': help = true; break;
      case 'V': version = true; break;
      case 'v': ++g.verbosity; break;
      case 'q': g.verbosity = 0; break;
      default: g.force = true; break;
    }
  }
  return true;
}

int run(int argc, char** argv) {
  Globals g;
  bool help = false, version = false;
  Argv rest;
  bool options_done = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (!options_done && a == "--") options_done = true;
    if (options_done) { rest.push_back(a); continue; }
    if (global_flags(a, g, help, version)) continue;
    if (a == "--help") help = true;
    else if (a == "--version") version = true;
    else if (a == "--verbose") ++g.verbosity;
    else if (a == "--quiet") g.verbosity = 0;
    else if (a == "--force") g.force = true;
    else if (auto in = global_value(a, "--max-input", argc, argv, i)) g.limits.max_input_bytes = parse_size("--max-input", *in);
    else if (auto n = global_value(a, "--max-values", argc, argv, i)) g.limits.max_values = parse_size("--max-values", *n);
    else rest.push_back(a);
  }
  if (version) {
    if (g.verbosity == 0) std::cout << KEYANIM_VERSION_STRING "\n";
    else std::cout << "keyanim " KEYANIM_VERSION_STRING " (format " << kQuatFormatVersionMajor << "." << kQuatFormatVersionMinor << ")\n";
    return kOk;
  }
  if (rest.empty()) {
    if (help) { print_main_help(); return kOk; }
    print_usage(std::cerr);  // like git and zstd: what there is to type
    std::cerr << "\nkeyanim: missing command. Run 'keyanim help' for the global options and exit codes.\n";
    return kUsage;
  }
  const std::string name = rest.front();
  rest.erase(rest.begin());
  if (name == "help") return help_command(help ? Argv{} : rest);
  const Command* c = find_command(name);
  if (!c) unknown_command(name);
  if (help) return print_command_help(*c), kOk;
  return c->run(rest, g);
}

}  // namespace
}  // namespace keyanim::cli

int main(int argc, char** argv) {
  using namespace keyanim::cli;
#ifdef __GLIBC__
  // glibc's default mmap threshold (128 KiB), kept fixed: by default it rises to the size of the
  // largest block freed, after which the encoder's per-round vectors of a long clip (hundreds of
  // KiB each, of changing sizes) fragment the heap instead of going back to the system. A
  // quaternion encode of the 44,032-frame clip peaked at 3.40x its BVH's bytes so, 2.8x with it
  // (bench_codec's peak_rss_over_bvh_bytes). A process-wide policy: the command's, not the
  // library's to set.
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
  install_interrupt_cleanup();
  Failure failure;
  try {
    const int code = run(argc, argv);
    flush_standard_output();  // a full standard output is a failure, whatever the code
    return code;
  } catch (const Failure& f) {
    failure = f;
  } catch (const std::exception& e) {
    failure = failure_of(e);
  } catch (...) {
    failure = {kInternal, "internal error (a bug in keyanim; please report it): an unknown exception"};
  }
  std::cerr << "keyanim: " << printable(failure.message) << "\n";
  if (failure.code == kUsage) std::cerr << "Try 'keyanim --help'.\n";
  return failure.code;
}
