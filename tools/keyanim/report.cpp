#include "report.h"

#include <cstdio>

#include "keyanim/offline/metrics.h"

namespace keyanim::cli {

std::string node_name(const Skeleton& s, uint32_t node) { return offline::point_name(s, node, 0); }

const char* reading_name(PositionReading r) { return r == PositionReading::add ? "add" : "replace"; }

nlohmann::json error_json(const Skeleton& s, const offline::ErrorReport& e) {
  nlohmann::json j = {{"max", e.max_error},
                      {"rms", e.rms_error},
                      {"worst_joint", node_name(s, e.worst_joint)},
                      {"worst_point", offline::point_name(s, e.worst_joint, e.worst_point)},
                      {"worst_shell_axis", nullptr},
                      {"worst_frame", e.worst_frame},
                      {"shell", e.shell},
                      {"readings", e.both_readings ? nlohmann::json{"replace", "add"} : nlohmann::json{"replace"}}};
  if (e.worst_point >= 1 && e.worst_point <= 3) j["worst_shell_axis"] = std::string(1, char('x' + e.worst_point - 1));
  if (e.both_readings) {
    j["worst_reading"] = reading_name(e.worst_reading);
    j["max_by_reading"] = {{"replace", e.reading_max[size_t(PositionReading::replace)]},
                           {"add", e.reading_max[size_t(PositionReading::add)]}};
  }
  return j;
}

std::string error_text(const Skeleton& s, const offline::ErrorReport& e) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "max %.6g (%s, frame %u%s), rms %.3g", e.max_error,
                offline::point_name(s, e.worst_joint, e.worst_point).c_str(), e.worst_frame,
                !e.both_readings ? "" : e.worst_reading == PositionReading::add ? ", add reading" : ", replace reading",
                e.rms_error);
  return buf;
}
std::string tolerance_warning(const offline::EncodeSettings& s, double tolerance_units, double max_error) {
  if (s.key_mode == offline::KeyMode::error || max_error <= tolerance_units) return {};
  const std::string mode = s.key_mode == offline::KeyMode::uniform ? "uniform:" + std::to_string(s.uniform_interval)
                           : s.key_mode == offline::KeyMode::manual  ? "manual"
                                                                     : "curvature";
  char buf[200];
  std::snprintf(buf, sizeof buf, "error max %.6g exceeds --error %.6g%s (%.6g units), which --keys %s does not enforce",
                max_error, s.tolerance, s.tolerance_in_percent ? "%" : "", tolerance_units, mode.c_str());
  return buf;
}

}  // namespace keyanim::cli
