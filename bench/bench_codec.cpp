// Codec benchmark over the corpus: size against error, Cardinal against linear, keyanim against
// ACL at equal error, and encode time against BVH parse time. Prints one JSON object.
//
//   bench_codec [--tolerance 0.05%,0.5%] [--filter SUBSTRING] [--no-linear] [--fit]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/metrics.h"

namespace fs = std::filesystem;
using namespace keyanim;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

struct AclRow {
  double threshold, bytes, max_err;
};

// acl.tsv: file, frames, fps, acl_threshold, acl_bytes, acl_max_err, ...
std::map<std::string, std::vector<AclRow>> read_acl(const fs::path& path) {
  std::map<std::string, std::vector<AclRow>> out;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string file, frames, fps, thr, bytes, err;
    std::getline(s, file, '\t'), std::getline(s, frames, '\t'), std::getline(s, fps, '\t');
    std::getline(s, thr, '\t'), std::getline(s, bytes, '\t'), std::getline(s, err, '\t');
    out[file].push_back({std::stod(thr), std::stod(bytes), std::stod(err)});
  }
  for (auto& [k, v] : out) std::sort(v.begin(), v.end(), [](auto& a, auto& b) { return a.max_err < b.max_err; });
  return out;
}

// ACL's size at error e, interpolated log-log between the rows that bracket e (anchors README);
// outside the measured range: the nearest row (a bound, flagged).
nlohmann::json acl_at(const std::vector<AclRow>& rows, double e) {
  if (rows.empty()) return nullptr;
  if (e <= rows.front().max_err) return {{"bytes", rows.front().bytes}, {"interpolated", false}, {"note", "below ACL's smallest measured error"}};
  if (e >= rows.back().max_err) return {{"bytes", rows.back().bytes}, {"interpolated", false}, {"note", "above ACL's largest measured error"}};
  for (size_t i = 0; i + 1 < rows.size(); ++i) {
    const AclRow& a = rows[i];
    const AclRow& b = rows[i + 1];
    if (e < a.max_err || e > b.max_err) continue;
    const double t = std::log(e / a.max_err) / std::log(b.max_err / a.max_err);
    return {{"bytes", std::exp(std::log(a.bytes) + t * std::log(b.bytes / a.bytes))}, {"interpolated", true}};
  }
  return nullptr;
}

struct RunResult {
  size_t bytes = 0;
  uint64_t keys = 0;
  double max_error = 0, rms_error = 0, tolerance = 0, encode_ms = 0;
  bool ok = false;
  std::string error;
};

RunResult run(const offline::Motion& m, offline::EncodeSettings s) {
  RunResult r;
  const auto t0 = Clock::now();
  offline::EncodeResult enc;
  if (!offline::encode(m, s, enc, r.error)) return r;
  const std::vector<uint8_t> bytes = offline::write_kanim(enc.clip, s.zstd_level);
  r.encode_ms = ms_since(t0);
  // Measure on what a decoder makes of the bytes, not on the encoder's own view.
  Clip clip;
  ErrorInfo info;
  if (Clip::load(bytes, clip, &info) != Status::ok) {
    r.error = "load failed: " + info.detail;
    return r;
  }
  offline::Motion decoded;
  if (!offline::decode_motion(clip, {}, decoded, r.error)) return r;
  const offline::ErrorReport e = offline::measure_error(m, decoded);
  r.bytes = bytes.size(), r.keys = enc.total_keys, r.max_error = e.max_error, r.rms_error = e.rms_error;
  r.tolerance = enc.tolerance_units;
  r.ok = true;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> tolerances{"0.05%", "0.5%"};
  std::string filter;
  bool linear = true, fit = false;
  uint32_t threads = 1;  // EncodeSettings' default; 0 = one per core, as the CLI does
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--tolerance" && i + 1 < argc) {
      tolerances.clear();
      std::stringstream ss(argv[++i]);
      for (std::string t; std::getline(ss, t, ',');) tolerances.push_back(t);
    } else if (a == "--filter" && i + 1 < argc) {
      filter = argv[++i];
    } else if (a == "--no-linear") {
      linear = false;
    } else if (a == "--fit") {
      fit = true;
    } else if (a == "--threads" && i + 1 < argc) {
      threads = uint32_t(std::stoul(argv[++i]));
    } else {
      std::cerr << "usage: bench_codec [--tolerance 0.05%,0.5%] [--filter S] [--no-linear] [--fit] [--threads N]\n";
      return 1;
    }
  }
  const fs::path corpus = KEYANIM_CORPUS_DIR;
  if (!fs::is_directory(corpus)) {
    std::cerr << "bench_codec: corpus not found at " << corpus << "\n";
    return 1;
  }
  const auto acl = read_acl(corpus.parent_path() / "anchors" / "acl.tsv");
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(corpus))
    if (e.path().extension() == ".bvh" && e.path().string().find(filter) != std::string::npos) files.push_back(e.path());
  std::sort(files.begin(), files.end());

  nlohmann::json out = {{"tolerances", tolerances}, {"threads", threads}, {"files", nlohmann::json::array()}};
  std::map<std::string, std::vector<double>> speed;  // tolerance -> encode/parse of each CMU file
  std::map<std::string, std::map<std::string, double>> totals;  // tolerance -> sums
  for (const fs::path& p : files) {
    std::ifstream in(p, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    offline::Motion m;
    offline::BvhError err;
    std::vector<double> parse_ms;
    for (int rep = 0; rep < 3; ++rep) {
      const auto t0 = Clock::now();
      if (!offline::read_bvh(text, p.string(), m, err)) break;
      parse_ms.push_back(ms_since(t0));
    }
    if (parse_ms.size() != 3) {
      out["files"].push_back({{"file", p.filename().string()}, {"error", err.to_string()}});
      continue;
    }
    std::sort(parse_ms.begin(), parse_ms.end());
    const bool cmu120 = p.parent_path().filename() == "cmu" && m.frame_time < 0.01;
    const double raw = 4.0 * m.frame_count * m.channel_count();
    nlohmann::json f = {{"file", p.filename().string()},
                        {"group", p.parent_path().filename().string()},
                        {"cmu_120fps", cmu120},
                        {"frames", m.frame_count},
                        {"channels", m.channel_count()},
                        {"raw_f32_bytes", raw},
                        {"bvh_bytes", text.size()},
                        {"parse_ms", parse_ms[1]},
                        {"results", nlohmann::json::array()}};
    for (const std::string& tol : tolerances) {
      offline::EncodeSettings s;
      s.tolerance_in_percent = tol.back() == '%';
      s.tolerance = std::stod(s.tolerance_in_percent ? tol.substr(0, tol.size() - 1) : tol);
      s.fit_tension = fit;
      s.threads = threads;
      const RunResult c = run(m, s);
      nlohmann::json r = {{"tolerance", tol}, {"ok", c.ok}};
      if (!c.ok) {
        r["error"] = c.error;
        f["results"].push_back(r);
        continue;
      }
      r.update({{"tolerance_units", c.tolerance},
                {"kanim_bytes", c.bytes},
                {"keys", c.keys},
                {"ratio_raw_f32", raw / double(c.bytes)},
                {"max_error", c.max_error},
                {"rms_error", c.rms_error},
                {"within_tolerance", c.max_error <= c.tolerance},
                {"encode_ms", c.encode_ms},
                {"encode_over_parse", c.encode_ms / parse_ms[1]}});
      const auto it = acl.find(p.filename().string());
      if (it != acl.end()) {
        nlohmann::json a = acl_at(it->second, c.max_error);
        r["acl_at_equal_error"] = a;
        if (a.is_object()) r["smaller_than_acl"] = double(c.bytes) < a["bytes"].get<double>();
      }
      if (linear) {
        offline::EncodeSettings ls = s;
        ls.force_linear = true;
        const RunResult l = run(m, ls);
        if (l.ok) r["linear"] = {{"kanim_bytes", l.bytes}, {"keys", l.keys}, {"max_error", l.max_error},
                                 {"ratio_raw_f32", raw / double(l.bytes)}};
      }
      if (cmu120) {
        auto& t = totals[tol];
        t["raw"] += raw, t["bytes"] += double(c.bytes), t["files"] += 1;
        if (r.contains("smaller_than_acl") && r["smaller_than_acl"].get<bool>()) t["smaller_than_acl"] += 1;
        if (r.contains("acl_at_equal_error") && r["acl_at_equal_error"].is_object()) t["acl_bytes"] += r["acl_at_equal_error"]["bytes"].get<double>();
        if (r.contains("linear")) t["linear_bytes"] += r["linear"]["kanim_bytes"].get<double>();
        t["max_encode_over_parse"] = std::max(t["max_encode_over_parse"], c.encode_ms / parse_ms[1]);
        speed[tol].push_back(c.encode_ms / parse_ms[1]);
      }
      f["results"].push_back(r);
    }
    std::cerr << p.filename().string() << " done\n";
    out["files"].push_back(f);
  }
  nlohmann::json summary = nlohmann::json::object();
  for (auto& [tol, t] : totals) {
    std::vector<double>& v = speed[tol];
    std::sort(v.begin(), v.end());
    const double median = v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    summary[tol] = {{"median_encode_over_parse", median},
                    {"cmu_120fps_files", t["files"]},
                    {"ratio_raw_f32", t["raw"] / t["bytes"]},
                    {"acl_ratio_raw_f32_at_equal_error", t["acl_bytes"] > 0 ? t["raw"] / t["acl_bytes"] : 0.0},
                    {"files_smaller_than_acl", t["smaller_than_acl"]},
                    {"linear_ratio_raw_f32", t["linear_bytes"] > 0 ? t["raw"] / t["linear_bytes"] : 0.0},
                    {"max_encode_over_parse", t["max_encode_over_parse"]}};
  }
  out["summary_cmu_120fps"] = summary;
  std::cout << out.dump(1) << "\n";
  return 0;
}
