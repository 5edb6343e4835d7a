#include "manifest.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <mutex>
#include <optional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <unordered_set>

#include "batch.h"
#include "encode_one.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "manifest_bank.h"
#include "manifest_report.h"
#include "tally.h"
#include "keyanim/clip.h"

namespace keyanim::cli {
namespace fs = std::filesystem;

Shard parse_shard(const std::string& text) {
  Shard s;
  const size_t slash = text.find('/');
  auto number = [&](std::string_view part, uint64_t& out) {
    const auto [p, ec] = std::from_chars(part.data(), part.data() + part.size(), out);
    return ec == std::errc() && p == part.data() + part.size() && !part.empty();
  };
  const std::string_view all(text);
  if (slash == std::string::npos || !number(all.substr(0, slash), s.index) || !number(all.substr(slash + 1), s.count) ||
      s.count == 0 || s.index >= s.count)
    fail(kUsage, "--shard expects I/N with 0 <= I < N, got '" + text + "'");
  return s;
}

std::string read_manifest(const std::string& list) {
  std::string text;
  if (list == "-") {
    text.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
  } else {
    std::ifstream in(list, std::ios::binary);
    if (!in) fail(kBadInput, list + ": cannot open the list: " + std::strerror(errno));
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return text;
}

std::vector<std::string> manifest_entries(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

std::string mirrored_output(const std::string& input, const std::string& outdir) {
  fs::path p = fs::path(input).lexically_normal();
  if (p.is_relative() && !p.empty() && *p.begin() == "..") p = fs::absolute(p).lexically_normal();
  if (p.is_absolute()) p = p.relative_path();
  return (fs::path(outdir) / p).replace_extension(".kanim").string();
}

namespace {

// The max_error= line of an existing output's notes, or null.
nlohmann::json noted_error(const Clip& clip) {
  const std::string& notes = clip.encoder_notes();
  const size_t at = notes.find("max_error=");
  if (at == std::string::npos) return nullptr;
  double v = 0.0;
  const char* p = notes.data() + at + 10;
  const auto [end, ec] = std::from_chars(p, notes.data() + notes.size(), v);
  return ec == std::errc() ? nlohmann::json(v) : nlohmann::json(nullptr);
}

// The entries without the repeats of one (the first stays where it is): an input listed twice
// is encoded once.
std::vector<std::string> distinct(std::vector<std::string> entries) {
  std::unordered_set<std::string_view> seen;  // views into `entries`, which stays put
  std::vector<std::string> out;
  for (const std::string& e : entries)
    if (seen.insert(e).second) out.push_back(e);
  return out;
}

// Before any work, over the whole list (so that every shard refuses it alike): two different
// inputs with one output (m.bvh and m.BVH), or the report being one of the outputs.
void check_manifest_outputs(const std::vector<std::string>& all, const std::string& outdir, const std::string& report) {
  std::vector<std::string> inputs = all, outputs;
  outputs.reserve(all.size() + 1);
  for (const std::string& in : all) outputs.push_back(mirrored_output(in, outdir));
  if (!report.empty()) inputs.push_back("--report"), outputs.push_back(report);
  check_distinct(inputs, outputs);
}

// The report is appended to: it may exist, but it is never the list or one of this process's
// inputs (appending a JSON line to a BVH file would break it).
void check_report(const std::string& report, const std::string& list, const std::vector<std::string>& inputs) {
  std::vector<FileId> ids;
  if (auto id = input_id(list)) ids.push_back(*id);
  for (const std::string& in : inputs)
    if (auto id = input_id(in)) ids.push_back(*id);
  check_not_input(report, ids);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Each input to its own .kanim below `outdir`.
int encode_shard_files(const Args& args, const offline::EncodeSettings& settings, const Globals& g, const std::string& list,
                       const std::string& outdir, const std::vector<std::string>& inputs, const std::set<std::string>& done,
                       Report& report) {
  const bool skip_existing = args.has("--skip-existing");
  Globals quiet = g;
  quiet.verbosity = std::min(g.verbosity, 1);
  EncodeTally tally;
  offline::EncodeSettings one = settings;
  one.threads = 1;  // files in parallel, each on one thread
  const int code = run_batch(inputs.size(), thread_count(args), g, [&](size_t i) {
    const std::string& in = inputs[i];
    const std::string out = mirrored_output(in, outdir);
    const auto t0 = std::chrono::steady_clock::now();
    nlohmann::json line = {{"input", in}, {"output", out}};
    try {
      std::error_code ec;
      Globals mine = quiet;
      if (skip_existing && fs::exists(out, ec)) {
        // Only a regular file can be a finished output: a FIFO would never end the read, and a
        // device is neither an output to keep nor one to replace.
        if (!fs::is_regular_file(out, ec)) fail(kOutputFailed, out + ": is not a regular file; not an output of keyanim");
        Clip clip;
        if (Clip::load_file(out, clip) == Status::ok) {
          line.update({{"status", "skipped"}, {"bytes", fs::file_size(out, ec)}, {"max_error", noted_error(clip)},
                       {"seconds", seconds_since(t0)}});
          if (!done.count(in)) report.add(line);
          tally.skipped();
          return;
        }
        mine.force = true;  // damaged or incomplete: replaced
      }
      // Another run on the same OUTDIR may finish this very output first: with --skip-existing
      // that is no failure, and the rename replaces it, atomically, with an equal encoding.
      if (skip_existing) mine.force = true;
      fs::create_directories(fs::path(out).parent_path(), ec);
      if (ec) fail(kOutputFailed, fs::path(out).parent_path().string() + ": cannot create: " + ec.message());
      const nlohmann::json r = encode_one(in, out, one, args.has("--error"), false, args.has("--runtime"), mine).summary;
      tally.encoded(r);
      line.update({{"status", "ok"}, {"bytes", r["kanim_bytes"]}, {"max_error", r["error"]["max"]},
                   {"tolerance", r.value("tolerance", r.value("error_limit", 0.0))}, {"seconds", seconds_since(t0)}});
      report.add(line);
    } catch (const Failure& f) {
      line.update({{"status", "failed"}, {"exit", f.code}, {"message", f.message}, {"seconds", seconds_since(t0)}});
      report.add(line);
      throw;
    } catch (const std::exception& e) {  // out of memory, say: still one line, then run_batch reports it
      line.update({{"status", "failed"}, {"exit", int(kBadInput)}, {"message", in + ": " + e.what()},
                   {"seconds", seconds_since(t0)}});
      report.add(line);
      throw;
    }
  }, inputs);
  if (g.verbosity > 0) std::cerr << tally.line(list == "-" ? "(standard input)" : list, outdir, inputs.size()) << "\n";
  return code;
}

}  // namespace

int encode_manifest(const Args& args, const offline::EncodeSettings& settings, Globals& g) {
  if (!args.positional().empty()) fail(kUsage, "encode --manifest takes no input file: the list names them");
  const bool bank = args.has("--bank");
  const std::string list = *args.get("--manifest");
  const std::string out = args.get("-o").value_or(args.get("--output").value_or(""));
  if (out.empty() || out == "-") fail(kUsage, bank ? "encode --manifest --bank needs -o LIB.kbank" : "encode --manifest needs -o OUTDIR");
  const Shard shard = parse_shard(args.get("--shard").value_or("0/1"));
  const std::string report_path = args.get("--report").value_or("");

  const std::vector<std::string> all = distinct(manifest_entries(read_manifest(list)));
  if (bank) check_manifest_names(all);
  else check_manifest_outputs(all, out, report_path);
  std::vector<std::string> inputs;
  // (i + count could wrap around with a huge N and take every entry: step only while it fits.)
  for (uint64_t i = shard.index; i < all.size(); i = all.size() - i > shard.count ? i + shard.count : all.size())
    inputs.push_back(all[size_t(i)]);
  if (!report_path.empty()) {
    check_report(report_path, list, inputs), check_output_name(report_path, json_lines_format());
    // Their names differ (.jsonl, .kbank), but a link can make them one file.
    const std::optional<FileId> report_id = input_id(report_path);
    if (bank && report_id && report_id == input_id(out)) fail(kOutputFailed, report_path + ": is the bank (-o) too");
  }
  const std::set<std::string> done = report_path.empty() ? std::set<std::string>{} : reported_done(report_path);
  Report report(report_path);
  if (bank) return encode_shard_bank(args, settings, g, inputs, done, report);
  return encode_shard_files(args, settings, g, list, out, inputs, done, report);
}

}  // namespace keyanim::cli
