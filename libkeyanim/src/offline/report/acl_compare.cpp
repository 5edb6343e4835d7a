#include "keyanim/offline/acl_compare.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace keyanim::offline {
namespace {

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, '\t');) out.push_back(f);
  return out;
}

// A number of the table, 0 when there is none. Not strtod: it follows the process's locale, and
// under a comma-decimal one reads "0.5" as 0.
double table_number(const std::string& text) {
  const char* p = text.data();
  const char* end = p + text.size();
  while (p != end && (*p == ' ' || *p == '\t')) ++p;
  if (p != end && *p == '+') ++p;
  double v = 0.0;
  return std::from_chars(p, end, v).ec == std::errc() ? v : 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

std::map<std::string, AclFile> read_acl_table(const std::string& path, std::string& error) {
  std::map<std::string, AclFile> out;
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) {
    error = path + ": cannot read the ACL table";
    return out;
  }
  const std::vector<std::string> head = fields(line);
  auto column = [&](const char* name) {
    return size_t(std::find(head.begin(), head.end(), name) - head.begin());
  };
  const size_t file = column("file"), group = column("group"), fps = column("fps"), bytes = column("acl_bytes"),
               err = column("acl_err_units"), size = column("size");
  if (std::max({file, group, fps, bytes, err}) >= head.size()) {
    error = path + ": not an ACL table (needs file, group, fps, acl_bytes, acl_err_units columns)";
    return out;
  }
  for (size_t number = 2; std::getline(in, line); ++number) {
    const std::vector<std::string> f = fields(line);
    if (f.size() < head.size()) continue;
    AclFile& a = out[f[file]];
    a.group = f[group];
    a.fps = table_number(f[fps]);
    const double b = table_number(f[bytes]), e = table_number(f[err]);
    // A skeleton without extent has no shell and no threshold: no usable row (anchors README).
    const bool sized = size >= head.size() || table_number(f[size]) > 0.0;
    if (sized && e > 0.0 && b > 0.0 && std::isfinite(e) && std::isfinite(b)) a.rows.push_back({b, e});
  }
  for (auto& [name, a] : out) {
    std::sort(a.rows.begin(), a.rows.end(),
              [](const AclRow& x, const AclRow& y) { return x.error < y.error || (x.error == y.error && x.bytes < y.bytes); });
    a.rows.erase(std::unique(a.rows.begin(), a.rows.end(), [](const AclRow& x, const AclRow& y) { return x.error == y.error; }),
                 a.rows.end());
  }
  return out;
}

nlohmann::json acl_at(const AclFile& acl, double e) {
  const std::vector<AclRow>& rows = acl.rows;
  if (rows.empty() || !(e >= 0.0)) return nullptr;
  if (e <= rows.front().error)
    return {{"bytes", rows.front().bytes}, {"interpolated", false}, {"note", "at or below ACL's smallest measured error"}};
  if (e >= rows.back().error)
    return {{"bytes", rows.back().bytes}, {"interpolated", false}, {"note", "at or above ACL's largest measured error"}};
  size_t i = 0;
  while (rows[i + 1].error < e) ++i;
  const AclRow &a = rows[i], &b = rows[i + 1];
  const double t = std::log(e / a.error) / std::log(b.error / a.error);
  return {{"bytes", std::exp(std::log(a.bytes) + t * std::log(b.bytes / a.bytes))}, {"interpolated", true}};
}

std::string comparison_group(const AclFile& acl) {
  if (acl.group == "cmu" && std::fabs(acl.fps - 120.0) < 0.5) return "cmu_120fps";
  if (acl.group == "bandai" && std::fabs(acl.fps - 30.0) < 0.5) return "bandai_30fps";
  return "other";
}

nlohmann::json group_summary(const std::vector<RatioEntry>& entries) {
  nlohmann::json out = nlohmann::json::object();
  for (const char* group : {"cmu_120fps", "bandai_30fps", "other"}) {
    std::vector<double> ratios;
    const RatioEntry* worst = nullptr;
    for (const RatioEntry& e : entries) {
      if (e.group != group) continue;
      ratios.push_back(e.ratio);
      if (!worst || e.ratio > worst->ratio) worst = &e;
    }
    if (!worst) continue;
    out[group] = {{"files", ratios.size()},
                  {"median_ratio", median(ratios)},
                  {"worst_ratio", worst->ratio},
                  {"worst_file", worst->file}};
  }
  return out;
}

}  // namespace keyanim::offline
