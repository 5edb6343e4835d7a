#include "eval_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
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

// The directory every path is below, with its trailing '/' ("" when there is none).
std::string common_directory(const std::vector<std::string>& paths) {
  std::string prefix = paths.empty() ? "" : paths[0].substr(0, paths[0].rfind('/') + 1);  // npos + 1: none
  for (const std::string& p : paths) {
    while (!prefix.empty() && p.compare(0, prefix.size(), prefix) != 0) {
      prefix.pop_back();                        // "a/b/" -> "a/b"
      prefix.erase(prefix.rfind('/') + 1);      // -> "a/" (or "" when no '/' is left)
    }
  }
  return prefix;
}

// Legend labels: the paths below the inputs' common directory (short, and still unique); the
// figure shortens a label too long for its legend in the middle (rd_plot.h), keeping its end.
std::vector<std::string> short_names(const std::vector<std::string>& paths) {
  const std::string prefix = common_directory(paths);
  std::vector<std::string> out;
  for (const std::string& p : paths) {
    out.push_back(p.substr(prefix.size()));
  }
  return out;
}

// Width on a terminal: code points (printable() leaves valid UTF-8 and no control bytes).
size_t width(const std::string& s) {
  return size_t(std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}
std::string pad_right(const std::string& s, size_t w) { return s + std::string(w > width(s) ? w - width(s) : 0, ' '); }
std::string pad_left(const std::string& s, size_t w) { return std::string(w > width(s) ? w - width(s) : 0, ' ') + s; }

// One row's numeric columns, after the name, mode and setting.
struct Numbers {
  unsigned long long keys = 0, bytes = 0;
  double raw = 0, bvh = 0, zstd = 0, max_error = 0, rms = 0, enc_ms = 0, dec_ms = 0;
};

std::string number_columns(const Numbers& n) {
  char buf[256];
  std::snprintf(buf, sizeof buf, " %8llu %9llu %7.2f %7.2f %7.2f %10.4g %10.4g %9.1f %9.1f", n.keys, n.bytes, n.raw, n.bvh,
                n.zstd, n.max_error, n.rms, n.enc_ms, n.dec_ms);
  return buf;
}

// " ACL bytes  x ACL" of a result, or nothing without a comparison.
std::string acl_columns(const nlohmann::json& r) {
  if (!r.contains("acl")) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, " %10.0f %7.3f", r["acl"]["bytes"].get<double>(), r["acl"]["ratio"].get<double>());
  return buf;
}

// Sums over the files of one run, for the total row.
struct RunTotal {
  std::string mode, setting;
  size_t files = 0;
  double raw = 0, bvh = 0, zstd = 0, squares = 0, samples = 0;  // squares: rms^2 x samples
  Numbers n;
};

// A result's figures as a row.
Numbers row_numbers(const nlohmann::json& r) {
  Numbers n;
  n.keys = r["keys"].get<unsigned long long>();
  n.bytes = r["kanim_bytes"].get<unsigned long long>();
  n.raw = r["ratio_raw_f32"].get<double>(), n.bvh = r["ratio_bvh"].get<double>(), n.zstd = r["ratio_bvh_zstd19"].get<double>();
  n.max_error = r["error"]["max"].get<double>(), n.rms = r["error"]["rms"].get<double>();
  n.enc_ms = r["encode_ms"].get<double>(), n.dec_ms = r["decode_ms"].get<double>();
  return n;
}

// Per run (key mode and setting), in the order first met: the sums over the files, then the
// total row's figures from them.
std::vector<RunTotal> run_totals(const std::vector<nlohmann::json>& files) {
  std::vector<RunTotal> totals;
  for (const auto& f : files) {
    if (f.is_null()) continue;
    for (const auto& r : f["results"]) {
      const std::string mode = r.value("key_mode", "error"), setting = setting_of(r);
      auto it = std::find_if(totals.begin(), totals.end(), [&](const RunTotal& t) { return t.mode == mode && t.setting == setting; });
      if (it == totals.end()) it = totals.insert(totals.end(), RunTotal{mode, setting, 0, 0, 0, 0, 0, 0, Numbers{}});
      RunTotal& t = *it;
      const Numbers n = row_numbers(r);
      ++t.files;
      t.raw += f["raw_f32_bytes"].get<double>();
      t.bvh += f["bvh_bytes"].get<double>();
      t.zstd += f["bvh_zstd19_bytes"].get<double>();
      const double samples = f["frames"].get<double>() * f.value("nodes", 0.0);  // what each RMS is over
      t.squares += n.rms * n.rms * samples;
      t.samples += samples;
      t.n.keys += n.keys, t.n.bytes += n.bytes;
      t.n.max_error = std::max(t.n.max_error, n.max_error);
      t.n.enc_ms += n.enc_ms, t.n.dec_ms += n.dec_ms;
    }
  }
  for (RunTotal& t : totals) {
    const double bytes = double(t.n.bytes);
    t.n.raw = bytes > 0 ? t.raw / bytes : 0.0, t.n.bvh = bytes > 0 ? t.bvh / bytes : 0.0;
    t.n.zstd = bytes > 0 ? t.zstd / bytes : 0.0;
    t.n.rms = t.samples > 0 ? std::sqrt(t.squares / t.samples) : 0.0;
  }
  return totals;
}

}  // namespace

std::string eval_table(const std::vector<nlohmann::json>& files, bool acl) {
  std::vector<std::string> paths, modes;
  bool all_error_mode = true;
  size_t mode_w = width("keys mode"), setting_w = 0;
  for (const auto& f : files) {
    if (f.is_null()) continue;
    paths.push_back(f["file"].get<std::string>());
    for (const auto& r : f["results"]) {
      const std::string mode = r.value("key_mode", "error");
      if (std::find(modes.begin(), modes.end(), mode) == modes.end()) modes.push_back(mode);
      all_error_mode = all_error_mode && r.contains("tolerance");
      mode_w = std::max(mode_w, width(printable(mode)));
      setting_w = std::max(setting_w, width(printable(setting_of(r))));
    }
  }
  const std::string prefix = common_directory(paths);
  const std::string file_head = prefix.empty() ? "file" : "file, below " + printable(prefix);
  const std::string setting_head = all_error_mode ? "tolerance" : "--error";
  const std::string total_label = "total (" + std::to_string(paths.size()) + (paths.size() == 1 ? " file)" : " files)");
  const bool mode_column = modes.size() > 1, with_totals = paths.size() > 1;  // one file's total is its row again
  size_t name_w = std::max(width(file_head), with_totals ? width(total_label) : 0);
  for (const std::string& p : paths) name_w = std::max(name_w, width(printable(p.substr(prefix.size()))));
  setting_w = std::max(setting_w, width(setting_head));
  auto lead = [&](const std::string& name, const std::string& mode, const std::string& setting) {
    return pad_right(name, name_w) + (mode_column ? " " + pad_right(mode, mode_w) : std::string()) + " " +
           pad_left(setting, setting_w);
  };
  char head[256];
  std::snprintf(head, sizeof head, " %8s %9s %7s %7s %7s %10s %10s %9s %9s%s", "keys", "bytes", "x raw", "x bvh", "x zstd",
                "max error", "rms error", "enc ms", "dec ms", acl ? "  ACL bytes   x ACL" : "");
  std::string out = lead(file_head, "keys mode", setting_head) + head + "\n";
  for (const auto& f : files) {
    if (f.is_null()) continue;
    const std::string name = printable(f["file"].get<std::string>().substr(prefix.size()));
    for (const auto& r : f["results"])
      out += lead(name, printable(r.value("key_mode", "error")), printable(setting_of(r))) + number_columns(row_numbers(r)) +
             (acl ? acl_columns(r) : "") + "\n";
  }
  if (with_totals)
    for (const RunTotal& t : run_totals(files))
      out += lead(total_label, printable(t.mode), printable(t.setting)) + number_columns(t.n) + "\n";
  return out;
}

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
