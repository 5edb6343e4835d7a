// keyanim: command-line front end. Dispatches to one subcommand; global options may appear
// anywhere before "--".
#include <cstring>
#include <iostream>
#include <new>
#include <optional>
#include <string>

#include "commands.h"
#include "escape.h"
#include "io.h"
#include "keyanim/version.h"
#include "settings.h"

namespace keyanim::cli {
namespace {

struct Command {
  const char* name;
  int (*run)(const Argv&, Globals&);
  const char* const* help;
  bool encoder_options;
  const char* summary;
};

const Command kCommands[] = {
    {"encode", cmd_encode, &kEncodeHelp, true, "BVH -> .kanim (keyframes within a tolerance)"},
    {"decode", cmd_decode, &kDecodeHelp, false, ".kanim -> BVH, at the source or another frame rate"},
    {"info", cmd_info, &kInfoHelp, false, "describe a BVH or .kanim file"},
    {"sample", cmd_sample, &kSampleHelp, false, "one pose of a .kanim at a frame or time"},
    {"plot", cmd_plot, &kPlotHelp, true, "SVG: one channel, original against reconstruction, keys marked"},
    {"render", cmd_render, &kRenderHelp, true, "SVG: one frame as a stick figure, front and side view"},
    {"eval", cmd_eval, &kEvalHelp, true, "compression against error for files and tolerances"},
    {"verify", cmd_verify, &kVerifyHelp, false, "check a .kanim, and its error against the original"},
    {"view", cmd_view, &kViewHelp, false, "HTML page that plays a .kanim in the browser (3D skeleton)"},
};

const char* const kGlobalHelp =
    "global options:\n"
    "  -h, --help            this help (after a command: that command's help)\n"
    "  -V, --version         tool and format versions (-qV: the bare version)\n"
    "  -v, --verbose         more messages on standard error\n"
    "  -q, --quiet           no messages but errors\n"
    "  -f, --force           overwrite existing outputs (never an input); allow binary output\n"
    "                        to a terminal\n"
    "  --max-input SIZE      largest input file read, in bytes (K, M, G: powers of 1024);\n"
    "                        default 1G\n"
    "  --max-values N        most values (frames x channels) a decode may make, and most keys\n"
    "                        a loaded .kanim may hold; default 256M\n";

void print_main_help() {
  std::cout << "keyanim " KEYANIM_VERSION_STRING " - skeletal motion as keyframes, rebuilt by Cardinal splines\n"
               "usage: keyanim COMMAND [options] INPUT [-o OUTPUT]\n\ncommands:\n";
  for (const Command& c : kCommands) std::printf("  %-8s %s\n", c.name, c.summary);
  std::cout << "\n" << kGlobalHelp << "\n" << kExitCodeTable << "\nRun 'keyanim COMMAND --help' for a command's options.\n";
}

// The value of global option `name` at argv[i] ("--name V" or "--name=V"), advancing i past it.
std::optional<std::string> global_value(const std::string& a, const std::string& name, int argc, char** argv, int& i) {
  if (a.rfind(name + "=", 0) == 0) return a.substr(name.size() + 1);
  if (a != name) return std::nullopt;
  if (i + 1 >= argc) fail(kUsage, "option " + name + " needs a value");
  return std::string(argv[++i]);
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
    if (a == "-h" || a == "--help") help = true;
    else if (a == "-V" || a == "--version") version = true;
    else if (a == "-v" || a == "--verbose") ++g.verbosity;
    else if (a == "-q" || a == "--quiet") g.verbosity = 0;
    else if (a == "-f" || a == "--force") g.force = true;
    else if (a == "-qV" || a == "-Vq") version = true, g.verbosity = 0;
    else if (auto in = global_value(a, "--max-input", argc, argv, i)) g.limits.max_input_bytes = parse_size("--max-input", *in);
    else if (auto n = global_value(a, "--max-values", argc, argv, i)) g.limits.max_values = parse_size("--max-values", *n);
    else rest.push_back(a);
  }
  if (version) {
    if (g.verbosity == 0) std::cout << KEYANIM_VERSION_STRING "\n";
    else std::cout << "keyanim " KEYANIM_VERSION_STRING " (format " << kFormatVersionMajor << "." << kFormatVersionMinor << ")\n";
    return kOk;
  }
  if (rest.empty()) {
    if (help) { print_main_help(); return kOk; }
    std::cerr << "keyanim: missing command\nTry 'keyanim --help'.\n";
    return kUsage;
  }
  const std::string name = rest.front();
  rest.erase(rest.begin());
  for (const Command& c : kCommands) {
    if (name != c.name) continue;
    if (help) {
      std::cout << *c.help << (c.encoder_options ? kEncodeOptionsHelp : "") << "\n" << kGlobalHelp << "\n" << kExitCodeTable;
      return kOk;
    }
    return c.run(rest, g);
  }
  std::cerr << "keyanim: unknown command '" << printable(name) << "'\nTry 'keyanim --help'.\n";
  return kUsage;
}

}  // namespace
}  // namespace keyanim::cli

int main(int argc, char** argv) {
  using namespace keyanim::cli;
  install_interrupt_cleanup();
  Failure failure;
  try {
    return run(argc, argv);
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
