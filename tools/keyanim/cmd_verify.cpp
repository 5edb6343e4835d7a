// keyanim verify: a .kanim is intact, and (with --against) within an error of the original.
#include <iostream>
#include <optional>

#include "commands.h"
#include "escape.h"
#include "io.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/metrics.h"
#include "keyanim/offline/notes.h"
#include "keyanim/offline/report.h"
#include "settings.h"

namespace keyanim::cli {

const char* const kVerifyHelp =
    "usage: keyanim verify IN.kanim [--against ORIG.bvh [--max-error E|E%] [--shell D|D%]] [--json]\n"
    "Loads and validates every byte of IN (signature, version, sections, checksum). With\n"
    "--against, decodes it and measures the world-space error of every joint, End Site and\n"
    "shell point against ORIG by forward kinematics (under both readings of position channels\n"
    "below the root, where the file has them); the hierarchy, frame count and frame time must\n"
    "match.\n"
    "  --against ORIG.bvh    the original to measure the decoded clip against\n"
    "  --max-error E|E%      fail (exit 5) if the error exceeds E file units, or E percent of\n"
    "                        the skeleton size (default: no limit, just report)\n"
    "  --shell D|D%          shell distance (file units, or percent of the skeleton size; 0:\n"
    "                        none). Default: the one IN was encoded with (its notes), else 2%\n"
    "  --json                one JSON object on standard output\n"
    "Exit 0 when every check passes, 2 for a damaged file or an ORIG that is not the clip's\n"
    "(another skeleton or frame count: nothing to compare, as for render and view --against),\n"
    "3 for an unsupported version, 5 when --max-error fails.\n";

namespace {

// The shell distance in file units: the option, else the clip's notes, else the default.
double shell_units(const std::optional<offline::EncodeSettings>& option, const Clip& clip, const offline::Motion& orig) {
  if (option) return option->shell_in_percent ? option->shell / 100.0 * offline::reference_size(orig) : option->shell;
  const std::optional<double> noted = offline::note_number(clip.encoder_notes(), "shell_units");
  return noted && *noted >= 0.0 ? *noted : offline::default_shell(orig);
}

}  // namespace

int cmd_verify(const Argv& argv, Globals& g) {
  const Args args(argv, {"--against", "--max-error", "--shell"}, {"--json"});
  if (args.positional().size() != 1) fail(kUsage, "verify takes one .kanim file");
  for (const char* o : {"--max-error", "--shell"})
    if (args.has(o) && !args.has("--against")) fail(kUsage, std::string(o) + " needs --against ORIG.bvh");
  const std::string in = args.positional()[0];
  if (args.get("--against") == "-" && in == "-") fail(kUsage, "only one input can be standard input");
  std::optional<offline::EncodeSettings> limit;  // parsed before any work
  if (auto text = args.get("--max-error")) parse_tolerance(*text, limit.emplace(), "--max-error");
  std::optional<offline::EncodeSettings> shell;
  if (auto text = args.get("--shell")) parse_shell(*text, shell.emplace());
  const Clip clip = load_kanim(in, read_input(in, Kind::kanim, g), g);
  nlohmann::json j = {{"file", in}, {"valid", true}};
  bool ok = true;
  std::string why;
  if (auto orig_path = args.get("--against")) {
    const offline::Motion orig = load_bvh(*orig_path, g);
    // Compared before decoding, so that the work follows the original's size, not what the
    // clip declares.
    const bool same_layout = orig.frame_count == clip.frame_count() && orig.channel_count() == clip.channel_count() &&
                             orig.skeleton.joints.size() == clip.skeleton().joints.size();
    // Inputs that cannot be compared are exit 2, as for render and view --against (README's
    // exit table): 5 is a check that ran and failed, and none ran.
    if (!same_layout)
      fail(kBadInput, *orig_path + ": not the same skeleton or frame count as " + in + " (" +
                          count_of(orig.frame_count, "frame") + " and " + count_of(orig.skeleton.joints.size(), "node") +
                          " against " + count_of(clip.frame_count(), "frame") + " and " +
                          count_of(clip.skeleton().joints.size(), "node") + "): nothing to compare");
    const offline::Motion back = or_fail(kBadInput, in + ": ", [&] { return offline::decode_motion(clip); });
    const offline::ErrorReport e = offline::measure_error(orig, back, shell_units(shell, clip, orig));
    j["error"] = offline::error_json(orig.skeleton, e);
    if (limit) {
      const offline::EncodeSettings& s = *limit;
      const double units = s.tolerance_in_percent ? s.tolerance / 100.0 * offline::reference_size(orig) : s.tolerance;
      j["max_error_allowed"] = units;
      if (!(e.max_error <= units)) {
        ok = false;
        // Shortest round-trip text: to_string's %f printed a tolerance of 1e-9 as 0.000000.
        why = "error " + json_text(e.max_error) + " exceeds " + json_text(units);
      }
    }
    if (!args.has("--json") && g.verbosity > 0) std::cerr << printable(in + ": error " + offline::error_text(orig.skeleton, e)) << "\n";
  }
  j["ok"] = ok;
  if (args.has("--json")) std::cout << json_text(j) << "\n";
  if (!ok) fail(kCheckFailed, in + ": " + why);
  if (!args.has("--json") && g.verbosity > 0) std::cerr << printable(in) << ": ok\n";
  return kOk;
}

}  // namespace keyanim::cli
