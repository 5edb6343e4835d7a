// keyanim eval: compression against reconstruction error, for files and tolerances.
#include <zstd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "keyanim/offline/acl_compare.h"
#include "batch.h"
#include "eval_report.h"
#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/metrics.h"
#include "keyanim/offline/report.h"
#include "settings.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kEvalHelp =
    "usage: keyanim eval IN.bvh|DIR... [--error E1,E2,...] [--shell D|D%] [--keys MODE[+MODE...]]\n"
    "                    [--tension T|fit] [--rotations quaternion|euler] [--level N] [-j N] [--json]\n"
    "                    [--svg RD.svg] [--report R.jsonl] [--acl TABLE.tsv]\n"
    "Encodes each file at each tolerance and measures what a decoder gets back: keys, bytes,\n"
    "ratios against raw float32 (frames x channels x 4), the BVH text and the BVH text compressed\n"
    "by zstd -19, the max and RMS world-space error of joints, End Sites and shell points with\n"
    "the worst point and frame, and the encode and decode times. Nothing is written. The table\n"
    "names files below the inputs' common directory, and ends with a total row per setting\n"
    "(sums, ratios of the sums, the largest error, the RMS error over every file's frames).\n"
    "  --error LIST          comma-separated tolerances, each E or E% (default 0.05%,0.5%)\n"
    "  --svg RD.svg          compression ratio against error, log axes: a line per file, or\n"
    "                        with several key modes a line per mode over every file\n"
    "  --report R.jsonl      the figures as JSON lines, one per file and setting, then a total\n"
    "                        per setting with the bytes per second of motion over every file\n"
    "  --acl TABLE.tsv       compare with ACL at equal error: ACL's bytes and error measured on\n"
    "                        the same files under the shell metric (e.g. the project's\n"
    "                        ../shared/anchors/acl_shell.tsv), interpolated log-log at the error\n"
    "                        reached (under the replace reading, as ACL was measured); per file\n"
    "                        the ratio of bytes, per group (CMU 120 fps, Bandai 30 fps, other)\n"
    "                        the median and worst ratio\n"
    "  -j N                  threads (default: one per core)\n"
    "  --json                one JSON object on standard output\n"
    "--keys takes several modes joined by + (error+uniform:10+curvature): every one is run at\n"
    "every tolerance. With --keys other than error, --error only guides quantization: the error\n"
    "reached is reported as it is, under the heading --error, with a warning where it exceeds a\n"
    "given --error.\n";

namespace {

using Clock = std::chrono::steady_clock;
double ms(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

size_t zstd19_size(const std::vector<uint8_t>& text) {
  std::vector<uint8_t> out(ZSTD_compressBound(text.size()));
  const size_t n = ZSTD_compress(out.data(), out.size(), text.data(), text.size(), 19);
  return ZSTD_isError(n) ? 0 : n;
}

// ACL at this file's error, from the table (nothing when the table has no such file).
void compare_with_acl(const std::map<std::string, offline::AclFile>& acl, const std::string& path, const offline::ErrorReport& e,
                      double bytes, nlohmann::json& result) {
  const auto it = acl.find(std::filesystem::path(path).filename().string());
  if (it == acl.end() || it->second.rows.empty()) return;
  const double error = e.reading_max[size_t(PositionReading::replace)];
  nlohmann::json a = offline::acl_at(it->second, error);
  a["error"] = error;
  a["group"] = offline::comparison_group(it->second);
  a["ratio"] = bytes / a["bytes"].get<double>();
  result["acl"] = a;
}

nlohmann::json eval_file(const std::string& path, const std::vector<EvalRun>& runs,
                         const std::map<std::string, offline::AclFile>& acl, const Globals& g) {
  const std::vector<uint8_t> text = read_input(path, Kind::bvh, g);
  const auto t0 = Clock::now();
  const offline::Motion m = load_bvh_bytes(path, text, g);
  for (const EvalRun& run : runs) check_settings_for(run.settings, m, path);
  const double parse_ms = ms(t0);
  const double raw = 4.0 * m.frame_count * m.channel_count();
  const size_t z19 = zstd19_size(text);
  const double size = offline::reference_size(m);
  nlohmann::json file = {{"file", path},
                         {"frames", m.frame_count},
                         {"channels", m.channel_count()},
                         {"nodes", m.skeleton.joints.size()},
                         {"frame_time", m.frame_time},
                         {"seconds", m.frame_count * m.frame_time},
                         {"size", size},
                         {"raw_f32_bytes", raw},
                         {"bvh_bytes", text.size()},
                         {"bvh_zstd19_bytes", z19},
                         {"parse_ms", parse_ms},
                         {"results", nlohmann::json::array()}};
  for (size_t r = 0; r < runs.size(); ++r) {
    const auto te = Clock::now();
    const offline::EncodeSettings& settings = runs[r].settings;
    const offline::EncodeResult enc = or_fail(kBadInput, path + ": ", [&] { return offline::encode(m, settings); });
    const std::vector<uint8_t> bytes = offline::write_kanim(enc.clip, settings.zstd_level);
    const double encode_ms = ms(te);
    const auto td = Clock::now();
    const Clip clip = load_kanim(path + " (encoded)", bytes, g);
    const offline::Motion back = or_fail(kBadInput, path + ": ", [&] { return offline::decode_motion(clip); });
    const double decode_ms = ms(td);
    const offline::ErrorReport e = offline::measure_error(m, back, enc.shell_units);
    const double n = double(bytes.size());
    const double seconds = m.frame_count * m.frame_time;
    nlohmann::json result = {{"key_mode", runs[r].keys},
                      {"bytes_per_second", seconds > 0 ? nlohmann::json(n / seconds) : nlohmann::json(nullptr)},
                      {"max_error_percent", size > 0 ? 100.0 * e.max_error / size : 0.0},
                      {"keys", enc.total_keys},
                      {"kanim_bytes", bytes.size()},
                      {"ratio_raw_f32", raw / n},
                      {"ratio_bvh", double(text.size()) / n},
                      {"ratio_bvh_zstd19", double(z19) / n},
                      {"error", offline::error_json(m.skeleton, e)},
                      {"encode_ms", encode_ms},
                      {"decode_ms", decode_ms}};
    // Only error mode applies the tolerance; the other modes say whether --error held.
    if (settings.key_mode == offline::KeyMode::error) {
      result["tolerance"] = runs[r].tolerance;
      result["tolerance_units"] = enc.tolerance_units;
    } else {
      result["error_limit"] = runs[r].tolerance;
      result["error_limit_units"] = enc.tolerance_units;
      result["error_limit_met"] = e.max_error <= enc.tolerance_units;
      result["warning"] = offline::tolerance_warning(settings, enc.tolerance_units, e.max_error);
    }
    compare_with_acl(acl, path, e, n, result);
    file["results"].push_back(std::move(result));
  }
  return file;
}

// Per setting (key mode and tolerance), per group: the median and worst ratio against ACL.
nlohmann::json acl_summary(const std::vector<nlohmann::json>& files) {
  std::map<std::string, std::vector<offline::RatioEntry>> runs;
  for (const auto& f : files) {
    if (f.is_null()) continue;
    for (const auto& r : f["results"]) {
      if (!r.contains("acl")) continue;
      const std::string run = r["key_mode"].get<std::string>() + " " +
                              r[r.contains("tolerance") ? "tolerance" : "error_limit"].get<std::string>();
      runs[run].push_back({r["acl"]["group"].get<std::string>(), f["file"].get<std::string>(),
                           r["acl"]["ratio"].get<double>()});
    }
  }
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [run, entries] : runs) out[run] = offline::group_summary(entries);
  return out;
}

void print_acl_summary(const nlohmann::json& summary) {
  for (const auto& [run, groups] : summary.items())
    for (const auto& [group, g] : groups.items())
      std::printf("against ACL, %s, %s: %zu files, median %s, worst %s (%s)\n", run.c_str(), group.c_str(),
                  g["files"].get<size_t>(), offline::fixed_text(g["median_ratio"].get<double>(), 3).c_str(),
                  offline::fixed_text(g["worst_ratio"].get<double>(), 3).c_str(),
                  printable(g["worst_file"].get<std::string>()).c_str());
}

}  // namespace

int cmd_eval(const Argv& argv, Globals& g) {
  std::set<std::string> valued{"-j", "--svg", "--report", "--acl"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  const Args args(argv, valued, {"--json"});
  if (args.positional().empty()) fail(kUsage, "eval needs at least one BVH file or directory");
  if (std::count(args.positional().begin(), args.positional().end(), "-") > 1)
    fail(kUsage, "only one input can be standard input");
  const std::vector<EvalRun> runs = eval_runs(args);
  std::map<std::string, offline::AclFile> acl;
  if (auto table = args.get("--acl")) {
    std::string why;
    acl = offline::read_acl_table(*table, why);
    if (!why.empty()) fail(kBadInput, why);
  }
  const std::vector<std::string> files = expand_inputs(args.positional());
  if (files.empty()) fail(kBadInput, "no .bvh files found");
  // The figure and the report are checked (and their temporary files opened) before the work.
  std::vector<FileId> ids;
  for (const std::string& f : files)
    if (auto id = input_id(f)) ids.push_back(*id);
  std::optional<Output> svg, report;
  if (auto path = args.get("--svg")) svg.emplace(*path, false, g, ids, svg_format(false, false));
  if (auto path = args.get("--report")) report.emplace(*path, false, g, ids, json_lines_format());
  std::vector<nlohmann::json> results(files.size());
  Globals quiet = g;
  quiet.verbosity = std::min(g.verbosity, 1);
  const int code = run_batch(files.size(), thread_count(args), g,
                             [&](size_t i) { results[i] = eval_file(files[i], runs, acl, quiet); }, files);

  // Warnings only when --error was given: the default list is not a request.
  for (auto& f : results) {
    if (f.is_null()) continue;
    for (auto& r : f["results"]) {
      if (!r.contains("warning")) continue;
      const std::string w = r["warning"].get<std::string>();
      if (!w.empty() && args.has("--error") && g.verbosity > 0)
        std::cerr << "keyanim: warning: " << printable(f["file"].get<std::string>() + ": " + w) << "\n";
      r.erase("warning");
    }
  }
  if (svg) svg->write(eval_svg(results)), svg->commit();
  if (report) report->write(eval_jsonl(results)), report->commit();
  const nlohmann::json summary = acl_summary(results);
  if (args.has("--json")) {
    nlohmann::json all = nlohmann::json::array();
    for (const auto& r : results)
      if (!r.is_null()) all.push_back(r);
    nlohmann::json out = {{"files", all}};
    if (args.has("--acl")) out["acl_summary"] = summary;
    std::cout << json_text(out) << "\n";
    return code;
  }
  std::fputs(eval_table(results, args.has("--acl")).c_str(), stdout);
  if (args.has("--acl")) print_acl_summary(summary);
  return code;
}

}  // namespace keyanim::cli
