// keyanim encode: BVH -> .kanim, reporting size and the error actually reached.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "batch.h"
#include "escape.h"
#include "formats.h"
#include "encode_one.h"
#include "io.h"
#include "manifest.h"
#include "progress.h"
#include "keyanim/offline/report.h"
#include "settings.h"
#include "tally.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kEncodeHelp =
    "usage: keyanim encode IN.bvh|DIR [-o OUT.kanim|OUTDIR] [--to kanim] [--error E|E%] [--shell D|D%]\n"
    "                      [--keys MODE] [--tension T|fit] [--rotations quaternion|euler] [--level N]\n"
    "                      [--runtime] [-j N] [--json] [-f]\n"
    "  or:  keyanim encode --manifest LIST -o OUTDIR|LIB.kbank [--bank] [--shard I/N] [--skip-existing]\n"
    "                      [--report R.jsonl] [--error E|E%] [--shell D|D%] [--keys MODE] [-j N] [-f]\n"
    "Stores only keyframes; every frame decodes within the tolerance (error mode): every joint,\n"
    "End Site and shell point (--shell) stays within --error of the original.\n"
    "  -o, --output FILE     output (default: IN with .kanim; '-' = standard output).\n"
    "                        IN may be a directory: every .bvh below it is encoded to the same\n"
    "                        relative path below -o OUTDIR, in parallel; bad files are reported\n"
    "                        and skipped, and the exit code is then non-zero. Outputs that\n"
    "                        would collide (m.bvh and m.BVH), exist (without -f) or are inputs\n"
    "                        stop the run before any file is encoded.\n"
    "  --to kanim            write the .kanim under a name that does not end in .kanim (without\n"
    "                        it, a name that says another format, out.bvh, is refused)\n"
    "  -j N                  threads (default and most: one per core): a file's channels, or\n"
    "                        a directory's (or a manifest's) files\n"
    "  --manifest LIST       encode every path listed (one per line; '-': standard input) to the\n"
    "                        same path below OUTDIR, as .kanim (an absolute path loses its root)\n"
    "  --shard I/N           only entries I, I+N, I+2N, ... (0 <= I < N): N machines, no coordination\n"
    "  --bank                write the shard's clips into one bank, -o LIB.kbank, named as their\n"
    "                        files below OUTDIR would be, without .kanim (`keyanim pack` merges\n"
    "                        the shards' banks)\n"
    "  --skip-existing       skip an input whose output exists and loads as a valid file (with\n"
    "                        --bank: keep a bank that holds the shard's clips)\n"
    "  --report R.jsonl      append one JSON line per finished input: input, output, status\n"
    "                        (ok, skipped, failed), bytes, max_error, tolerance, seconds\n"
    "  --runtime             write the runtime profile (format 5.0; 4.0 with --rotations euler):\n"
    "                        the image a player samples where it lies, loaded with no\n"
    "                        decoding, about twice the archive's bytes (`keyanim convert`\n"
    "                        turns either profile into the other)\n"
    "  --json                one JSON object on standard output (not with -o -); names that\n"
    "                        are not UTF-8 keep their bytes as \\udcHH escapes\n";

// Encodes one file. Every check that needs no work comes first (input, output, options against
// the input); the output is written only when everything else has succeeded. Memory: the BVH
// text goes once parsed, the motion's values once encoded. With `bar`, the stages show on it.
Encoded encode_one(const std::string& in, const std::string& out, offline::EncodeSettings settings,
                   bool error_given, bool to_given, bool runtime, const Globals& g, Progress* bar) {
  Input input(in, g);
  Output output(out, true, g, ids_of({&input}), kanim_format(to_given));
  EncodeProgress progress(bar, settings.key_mode == offline::KeyMode::error);
  offline::Motion motion;
  size_t bvh_size = 0;
  {
    const std::vector<uint8_t> bvh_bytes = input.read(Kind::bvh);
    bvh_size = bvh_bytes.size();
    motion = load_bvh_bytes(in, bvh_bytes, g, &progress);
  }
  check_settings_for(settings, motion, in);
  const auto t0 = std::chrono::steady_clock::now();
  settings.progress = progress.encoding();
  // The exit code follows the kind of error: a tolerance below float32 precision is a limit
  // reached (6), not bad input (2).
  offline::EncodeResult result;
  try {
    result = offline::encode(motion, settings);
  } catch (const offline::Error& e) {
    const Failure f = failure_of(e);
    fail(f.code, in + ": " + f.message);
  }
  std::vector<double>().swap(motion.values);
  progress.compressing();
  // encode() made a clip the container can store: write_kanim cannot fail here.
  const std::vector<uint8_t> bytes = runtime ? offline::write_kanim_runtime(offline::to_clip(result.clip))
                                             : offline::write_kanim(result.clip, settings.zstd_level);
  const double encode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  Encoded e;
  e.summary = offline::encode_summary(in, out, motion, bvh_size, settings, result, bytes.size(), encode_ms);
  if (error_given) e.warning = offline::tolerance_warning(settings, result.tolerance_units, result.error.max_error);
  output.write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  output.commit();
  return e;
}

namespace {

std::string human_line(const nlohmann::json& j) {
  auto g = [](const nlohmann::json& v) { return offline::general_text(v.get<double>()); };  // as a stream's %g
  std::ostringstream line;
  line << j["input"].get<std::string>() << " -> " << j["output"].get<std::string>() << ": " << j["kanim_bytes"]
       << " bytes, " << g(j["ratio_raw_f32"]) << "x raw float32, " << j["keys"] << " keys; error max "
       << g(j["error"]["max"]) << " (" << j["error"]["worst_point"].get<std::string>() << ", frame "
       << j["error"]["worst_frame"];
  if (j["error"].contains("worst_reading")) line << ", " << j["error"]["worst_reading"].get<std::string>() << " reading";
  line << ")";
  if (j.contains("tolerance")) line << ", tolerance " << g(j["tolerance"]);
  line << ", shell " << g(j["error"]["shell"]);
  return printable(line.str());
}

void print_warning(const Encoded& e, const Globals& g) {
  if (!e.warning.empty() && g.verbosity > 0)
    std::cerr << "keyanim: warning: " << printable(e.summary["input"].get<std::string>() + ": " + e.warning) << "\n";
}

// Directory: every .bvh below IN goes to the same relative path below OUT, as .kanim. All the
// outputs are checked before the first file is encoded.
int encode_directory(const std::string& in, const std::string& out, const offline::EncodeSettings& settings,
                     const Args& args, bool json, const Globals& g) {
  if (out.empty()) fail(kUsage, "encoding a directory needs -o OUTDIR");
  if (out == "-") fail(kUsage, "encoding a directory cannot write to standard output");
  const std::vector<std::string> files = expand_inputs({in});
  if (files.empty()) fail(kBadInput, in + ": no .bvh files found");
  std::vector<std::string> targets;
  for (const std::string& f : files) {
    // Lexically, from the path as listed (IN/...): relative() would resolve a symlinked input
    // and name its output after the link's target, possibly outside OUTDIR.
    const std::filesystem::path rel = std::filesystem::path(f).lexically_normal().lexically_relative(
        std::filesystem::path(in).lexically_normal());
    if (rel.empty() || *rel.begin() == "..") fail(kBadInput, f + ": not below " + in);
    targets.push_back(swap_extension((std::filesystem::path(out) / rel).string(), ".kanim"));
  }
  check_outputs(files, targets, g);
  EncodeTally tally;
  std::vector<Encoded> results(files.size());
  Globals quiet = g;
  quiet.verbosity = std::min(g.verbosity, 1);
  const bool error_given = args.has("--error");
  const int code = run_batch(files.size(), thread_count(args), g, [&](size_t i) {
    const std::filesystem::path dir = std::filesystem::path(targets[i]).parent_path();
    std::error_code mk;
    std::filesystem::create_directories(dir, mk);
    if (mk) fail(kOutputFailed, dir.string() + ": cannot create: " + mk.message());
    results[i] = encode_one(files[i], targets[i], settings, error_given, false, args.has("--runtime"), quiet);
  }, files);
  nlohmann::json all = nlohmann::json::array();
  for (const Encoded& r : results) {
    if (r.summary.is_null()) continue;
    all.push_back(r.summary);
    tally.encoded(r.summary);
    print_warning(r, g);
    if (!json && g.verbosity > 1) std::cerr << human_line(r.summary) << "\n";
  }
  if (json) std::cout << json_text({{"files", all}, {"failed", files.size() - all.size()}}) << "\n";
  else if (g.verbosity > 0) std::cerr << tally.line(in, out, files.size()) << "\n";
  return code;
}

}  // namespace

int cmd_encode(const Argv& argv, Globals& g) {
  std::set<std::string> valued{"-o", "--output", "-j", "--to"}, flags{"--json", "--runtime"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  valued.insert(std::begin(kManifestValuedOptions), std::end(kManifestValuedOptions));
  flags.insert(std::begin(kManifestFlags), std::end(kManifestFlags));
  const Args args(argv, valued, flags);
  const bool to_kanim = stated_format(args, "kanim");
  std::error_code ec;
  const bool directory = args.positional().size() == 1 && args.positional()[0] != "-" &&
                         std::filesystem::is_directory(args.positional()[0], ec);
  if (to_kanim && (args.has("--manifest") || directory))
    fail(kUsage, "--to names the format of one output file; a directory or manifest run names each output .kanim");
  if (args.has("--manifest")) return encode_manifest(args, encode_settings(args), g);
  for (const char* o : {"--shard", "--report", "--skip-existing", "--bank"})
    if (args.has(o)) fail(kUsage, std::string(o) + " goes with --manifest LIST");
  if (args.positional().size() != 1) fail(kUsage, "encode takes one input file or directory");
  offline::EncodeSettings settings = encode_settings(args);
  const std::string in = args.positional()[0];
  std::string out = args.get("-o").value_or("");
  const bool json = args.has("--json");

  if (directory) return encode_directory(in, out, settings, args, json, g);
  if (out.empty()) out = in == "-" ? "-" : swap_extension(in, ".kanim");
  if (json && out == "-") fail(kUsage, "--json and the .kanim would both go to standard output: give -o FILE");
  settings.threads = thread_count(args);  // one file: its channels in parallel
  Progress bar(g, in);
  const Encoded e = encode_one(in, out, settings, args.has("--error"), to_kanim, args.has("--runtime"), g, &bar);
  bar.erase();
  if (json) std::cout << json_text(e.summary) << "\n";
  else if (g.verbosity > 0) std::cerr << human_line(e.summary) << "\n";
  print_warning(e, g);
  return kOk;
}

}  // namespace keyanim::cli
