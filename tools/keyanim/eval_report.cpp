#include "eval_report.h"

#include <algorithm>
#include <map>
#include <sstream>

#include "escape.h"
#include "rd_plot.h"
#include "settings.h"

namespace keyanim::cli {
namespace {

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string part; std::getline(ss, part, sep);) out.push_back(part);
  return out;
}

// The --error of a result: a tolerance in error mode, a limit that guided quantization otherwise.
std::string setting_of(const nlohmann::json& r) {
  return r.contains("tolerance") ? r["tolerance"].get<std::string>() : r.value("error_limit", std::string());
}

// Per run (keys, tolerance), in the order first met.
struct Total {
  std::string keys, tolerance;
  size_t files = 0;
  uint64_t frames = 0;
  double seconds = 0.0, raw = 0.0, bytes = 0.0, max_percent = 0.0, encode_ms = 0.0;
};

std::vector<Total> totals(const std::vector<nlohmann::json>& files) {
  std::vector<Total> out;
  for (const auto& f : files) {
    if (f.is_null()) continue;
    for (const auto& r : f["results"]) {
      const std::string keys = r.value("key_mode", "error"), tol = setting_of(r);
      auto it = std::find_if(out.begin(), out.end(), [&](const Total& t) { return t.keys == keys && t.tolerance == tol; });
      if (it == out.end()) it = out.insert(out.end(), Total{keys, tol});
      ++it->files;
      it->frames += f["frames"].get<uint64_t>();
      it->seconds += f["seconds"].get<double>();
      it->raw += f["raw_f32_bytes"].get<double>();
      it->bytes += r["kanim_bytes"].get<double>();
      it->max_percent = std::max(it->max_percent, r["max_error_percent"].get<double>());
      it->encode_ms += r["encode_ms"].get<double>();
    }
  }
  return out;
}

// Legend labels: the paths below the inputs' common directory (short, and still unique); the
// figure shortens a label too long for its legend in the middle (rd_plot.h), keeping its end.
std::vector<std::string> short_names(const std::vector<std::string>& paths) {
  std::string prefix = paths.empty() ? "" : paths[0].substr(0, paths[0].rfind('/') + 1);  // npos + 1: none
  for (const std::string& p : paths) {
    while (!prefix.empty() && p.compare(0, prefix.size(), prefix) != 0) {
      prefix.pop_back();                        // "a/b/" -> "a/b"
      prefix.erase(prefix.rfind('/') + 1);      // -> "a/" (or "" when no '/' is left)
    }
  }
  std::vector<std::string> out;
  for (const std::string& p : paths) {
    out.push_back(p.substr(prefix.size()));
  }
  return out;
}

}  // namespace

std::vector<EvalRun> eval_runs(const Args& args) {
  std::vector<std::string> tolerances{"0.05%", "0.5%"}, modes{"error"};
  if (auto list = args.get("--error")) tolerances = split(*list, ',');
  if (auto list = args.get("--keys")) modes = split(*list, '+');
  if (tolerances.empty()) fail(kUsage, "--error needs at least one tolerance");
  if (modes.empty()) fail(kUsage, "--keys needs at least one mode");
  const offline::EncodeSettings common = encode_settings(args, false, false);  // --tension, --level
  std::vector<EvalRun> runs;
  for (const std::string& keys : modes) {
    for (const std::string& tol : tolerances) {
      EvalRun run{tol, keys, common};
      parse_key_mode(keys, run.settings);
      parse_tolerance(tol, run.settings);
      or_fail(kUsage, "", [&] { run.settings.validate(); });
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

std::string eval_svg(const std::vector<nlohmann::json>& files) {
  std::vector<RdSeries> series;
  std::vector<Total> t = totals(files);
  size_t count = 0;
  std::vector<std::string> modes;
  for (const Total& x : t)
    if (std::find(modes.begin(), modes.end(), x.keys) == modes.end()) modes.push_back(x.keys);
  if (modes.size() > 1) {
    for (const std::string& mode : modes) {
      RdSeries s{"keys " + mode, {}};
      for (const Total& x : t)
        if (x.keys == mode && x.bytes > 0) s.points.push_back({x.max_percent, x.raw / x.bytes});
      series.push_back(std::move(s));
    }
  }
  std::vector<std::string> paths;
  for (const auto& f : files)
    if (!f.is_null()) paths.push_back(f["file"].get<std::string>());
  const std::vector<std::string> names = short_names(paths);
  for (const auto& f : files) {
    if (f.is_null()) continue;
    if (modes.size() == 1) {
      RdSeries s{names[count], {}};
      for (const auto& r : f["results"]) s.points.push_back({r["max_error_percent"].get<double>(), r["ratio_raw_f32"].get<double>()});
      series.push_back(std::move(s));
    }
    ++count;
  }
  std::string modes_text;
  for (const std::string& m : modes) modes_text += (modes_text.empty() ? "" : ", ") + m;
  const std::string subtitle = std::to_string(count) + (count == 1 ? " file" : " files") + "; keys: " + modes_text +
                               (modes.size() > 1 ? " (a line per key mode over every file)" : " (a line per file)") +
                               "; raw float32 = frames x channels x 4 bytes";
  return rd_plot(series, subtitle);
}

std::string eval_jsonl(const std::vector<nlohmann::json>& files) {
  std::string out;
  for (const auto& f : files) {
    if (f.is_null()) continue;
    for (const auto& r : f["results"]) {
      const double seconds = f["seconds"].get<double>();
      nlohmann::json line = {{"file", f["file"]},
                             {"key_mode", r.value("key_mode", "error")},
                             {"tolerance", setting_of(r)},
                             {"tolerance_units", r.contains("tolerance_units") ? r["tolerance_units"] : r["error_limit_units"]},
                             {"frames", f["frames"]},
                             {"frame_time", f["frame_time"]},
                             {"seconds", seconds},
                             {"size", f["size"]},
                             {"raw_f32_bytes", f["raw_f32_bytes"]},
                             {"bvh_bytes", f["bvh_bytes"]},
                             {"kanim_bytes", r["kanim_bytes"]},
                             {"keys", r["keys"]},
                             {"ratio_raw_f32", r["ratio_raw_f32"]},
                             {"ratio_bvh", r["ratio_bvh"]},
                             {"ratio_bvh_zstd19", r["ratio_bvh_zstd19"]},
                             {"max_error", r["error"]["max"]},
                             {"max_error_percent", r["max_error_percent"]},
                             {"rms_error", r["error"]["rms"]},
                             {"worst_joint", r["error"]["worst_joint"]},
                             {"worst_frame", r["error"]["worst_frame"]},
                             {"bytes_per_second", seconds > 0 ? nlohmann::json(r["kanim_bytes"].get<double>() / seconds) : nullptr},
                             {"encode_ms", r["encode_ms"]},
                             {"decode_ms", r["decode_ms"]}};
      out += json_text(line) + "\n";  // names that are not UTF-8 keep their bytes
    }
  }
  for (const Total& t : totals(files)) {
    const nlohmann::json line = {{"total", true},
                                 {"key_mode", t.keys},
                                 {"tolerance", t.tolerance},
                                 {"files", t.files},
                                 {"frames", t.frames},
                                 {"seconds", t.seconds},
                                 {"raw_f32_bytes", t.raw},
                                 {"kanim_bytes", t.bytes},
                                 {"ratio_raw_f32", t.bytes > 0 ? t.raw / t.bytes : 0.0},
                                 {"bytes_per_second", t.seconds > 0 ? nlohmann::json(t.bytes / t.seconds) : nullptr},
                                 {"max_error_percent", t.max_percent},
                                 {"encode_ms", t.encode_ms}};
    out += json_text(line) + "\n";
  }
  return out;
}

}  // namespace keyanim::cli
