// keyanim encode: BVH -> .kanim, reporting size and the error actually reached.
#include <chrono>
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "batch.h"
#include "report.h"
#include "settings.h"

namespace keyanim::cli {

const char* const kEncodeHelp =
    "usage: keyanim encode IN.bvh [-o OUT.kanim] [--error E|E%] [--keys MODE] [--tension T|fit]\n"
    "                      [--level N] [--json] [-f]\n"
    "Stores only keyframes; every frame decodes within the tolerance (error mode).\n"
    "  -o, --output FILE     output (default: IN with .kanim; '-' = standard output).\n"
    "                        IN may be a directory: every .bvh below it is encoded to the same\n"
    "                        relative path below -o OUTDIR, in parallel; bad files are reported\n"
    "                        and skipped, and the exit code is then non-zero.\n"
    "  -j N                  threads (default: one per core): a file's channels, or a\n"
    "                        directory's files\n"
    "  --json                one JSON object on standard output\n";

namespace {

// Encodes one file; returns the JSON summary (also used for the human line).
nlohmann::json encode_one(const std::string& in, const std::string& out, const offline::EncodeSettings& settings,
                          const Globals& g) {
  const std::vector<uint8_t> bvh_bytes = read_input(in);
  const offline::Motion motion = load_bvh_bytes(in, bvh_bytes, g);
  const auto t0 = std::chrono::steady_clock::now();
  offline::EncodeResult result;
  std::string error;
  if (!offline::encode(motion, settings, result, error)) fail(kBadInput, in + ": " + error);
  const std::vector<uint8_t> bytes = offline::write_kanim(result.clip, settings.zstd_level);
  if (bytes.empty()) fail(kBadInput, in + ": cannot be stored: " + offline::validate_encoded_clip(result.clip));
  const double encode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  write_output(out, std::string(bytes.begin(), bytes.end()), true, g);
  const double raw = 4.0 * motion.frame_count * motion.channel_count();
  return {
      {"input", in},
      {"output", out},
      {"frames", motion.frame_count},
      {"channels", motion.channel_count()},
      {"frame_time", motion.frame_time},
      {"keys", result.total_keys},
      {"bvh_bytes", bvh_bytes.size()},
      {"raw_f32_bytes", static_cast<uint64_t>(raw)},
      {"kanim_bytes", bytes.size()},
      {"ratio_raw_f32", bytes.empty() ? 0.0 : raw / double(bytes.size())},
      {"tolerance", result.tolerance_units},
      {"error", error_json(motion.skeleton, result.error)},
      {"encode_ms", encode_ms},
  };
}

void print_line(const nlohmann::json& j) {
  std::cerr << j["input"].get<std::string>() << " -> " << j["output"].get<std::string>() << ": "
            << j["kanim_bytes"] << " bytes, " << j["ratio_raw_f32"].get<double>() << "x raw float32, " << j["keys"]
            << " keys; error max " << j["error"]["max"].get<double>() << " (" << j["error"]["worst_joint"].get<std::string>()
            << ", frame " << j["error"]["worst_frame"] << "), tolerance " << j["tolerance"].get<double>() << "\n";
}

}  // namespace

int cmd_encode(const Argv& argv, Globals& g) {
  std::set<std::string> valued{"-o", "--output", "-j"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  const Args args(argv, valued, {"--json"});
  if (args.positional().size() != 1) fail(kUsage, "encode takes one input file or directory");
  offline::EncodeSettings settings = encode_settings(args);
  const std::string in = args.positional()[0];
  std::string out = args.get("-o").value_or(args.get("--output").value_or(""));
  const bool json = args.has("--json");

  std::error_code ec;
  if (in == "-" || !std::filesystem::is_directory(in, ec)) {
    if (out.empty()) out = in == "-" ? "-" : swap_extension(in, ".kanim");
    settings.threads = thread_count(args);  // one file: its channels in parallel
    const nlohmann::json j = encode_one(in, out, settings, g);
    if (json) std::cout << j.dump() << "\n";
    else if (g.verbosity > 0) print_line(j);
    return kOk;
  }

  // Directory: every .bvh below IN goes to the same relative path below OUT, as .kanim.
  if (out.empty()) fail(kUsage, "encoding a directory needs -o OUTDIR");
  if (out == "-") fail(kUsage, "encoding a directory cannot write to standard output");
  const std::vector<std::string> files = expand_inputs({in});
  std::vector<nlohmann::json> results(files.size());
  Globals quiet = g;
  quiet.verbosity = std::min(g.verbosity, 1);
  const int code = run_batch(files.size(), thread_count(args), g, [&](size_t i) {
    const std::filesystem::path rel = std::filesystem::relative(files[i], in);
    const std::filesystem::path target = std::filesystem::path(out) / rel;
    std::error_code mk;
    std::filesystem::create_directories(target.parent_path(), mk);
    if (mk) fail(kOutputFailed, target.parent_path().string() + ": cannot create: " + mk.message());
    results[i] = encode_one(files[i], swap_extension(target.string(), ".kanim"), settings, quiet);
  }, files);
  if (json) {
    nlohmann::json all = nlohmann::json::array();
    for (const auto& r : results)
      if (!r.is_null()) all.push_back(r);
    std::cout << nlohmann::json{{"files", all}, {"failed", files.size() - all.size()}}.dump() << "\n";
  } else if (g.verbosity > 1) {
    for (const auto& r : results)
      if (!r.is_null()) print_line(r);
  }
  if (files.empty()) fail(kBadInput, in + ": no .bvh files found");
  return code;
}

}  // namespace keyanim::cli
