#include "report.h"

#include <cstdio>

namespace keyanim::cli {

std::string node_name(const Skeleton& s, uint32_t node) {
  if (node >= s.joints.size()) return "?";
  const Joint& j = s.joints[node];
  if (!j.end_site || !j.name.empty()) return j.name;
  return j.parent >= 0 ? "End Site of " + s.joints[size_t(j.parent)].name : "End Site";
}

nlohmann::json error_json(const Skeleton& s, const offline::ErrorReport& e) {
  return {{"max", e.max_error},
          {"rms", e.rms_error},
          {"worst_joint", node_name(s, e.worst_joint)},
          {"worst_frame", e.worst_frame},
          {"max_leaf_rotation_deg", e.max_leaf_rotation}};
}

std::string error_text(const Skeleton& s, const offline::ErrorReport& e) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "max %.6g (%s, frame %u), rms %.3g", e.max_error,
                node_name(s, e.worst_joint).c_str(), e.worst_frame, e.rms_error);
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
