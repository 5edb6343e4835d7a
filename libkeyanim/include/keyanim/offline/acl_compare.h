// keyanim against ACL at equal error: ACL's bytes read from an anchors table measured on the
// corpus (../shared/anchors/acl_shell.tsv: ACL's bytes and measured error under the shell
// metric at several thresholds per file), interpolated log-log at keyanim's measured error, and
// the ratios summarised per group of clips. Shared by `keyanim eval --acl` and bench_codec.
#pragma once
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace keyanim::offline {

struct AclRow {
  double bytes = 0.0, error = 0.0;  // ACL's bytes and its measured error (file units)
};

struct AclFile {
  std::string group;  // "cmu", "bandai", "misc" as the table says
  double fps = 0.0;
  std::vector<AclRow> rows;  // increasing error; one row per error (the fewest bytes)
};

// The table by file name (without directories). Empty if it cannot be read; rows whose error
// is not positive (a skeleton without extent) are left out.
std::map<std::string, AclFile> read_acl_table(const std::string& path, std::string& error);

// ACL's bytes at error e: log-log between the two rows that bracket e; outside the measured
// range, the nearest row (then `interpolated` is false). Null without rows.
nlohmann::json acl_at(const AclFile& acl, double e);

// The group a clip is judged in: "cmu_120fps", "bandai_30fps" or "other".
std::string comparison_group(const AclFile& acl);

// Median and worst of keyanim/ACL per group: entries are {group, file, ratio}.
struct RatioEntry {
  std::string group, file;
  double ratio = 0.0;
};
nlohmann::json group_summary(const std::vector<RatioEntry>& entries);

}  // namespace keyanim::offline
