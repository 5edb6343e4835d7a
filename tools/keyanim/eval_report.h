// What `keyanim eval` runs, and its figures as a rate-distortion SVG (--svg) and as JSON lines
// with totals over the inputs (--report).
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli.h"
#include "keyanim/offline/encode.h"

namespace keyanim::cli {

// One encoding setting of an eval: a key mode at a tolerance (its results carry both, as
// "tolerance" and "key_mode").
struct EvalRun {
  std::string tolerance;  // as given: "0.05%" or "0.1"
  std::string keys;       // as given: "error", "uniform:10", ...
  offline::EncodeSettings settings;
};

// Every tolerance of --error (comma-separated, default 0.05%,0.5%) for every key mode of
// --keys (several joined by '+', default error), modes first; usage error if one is wrong.
std::vector<EvalRun> eval_runs(const Args& args);

// The per-file results of eval (as --json prints them) as the RD figure: one line per file,
// or, with several key modes, one line per mode over every file (its largest error and its
// total ratio at each tolerance).
std::string eval_svg(const std::vector<nlohmann::json>& files);

// The table `eval` prints: a row per file and run, names relative to the inputs' common
// directory (the header says which), a key-mode column when several modes ran, columns as wide
// as their content, then (for two files or more) a total row per run over every file (keys and bytes summed, ratios of
// the sums, the largest max error, the RMS error pooled over every file's nodes and frames, in
// the files' length units). With `acl`, the ACL columns of results that have them.
std::string eval_table(const std::vector<nlohmann::json>& files, bool acl);

// The same figures as JSON lines: one per file and run, then one total per run ("total":
// true) with the bytes per second of motion over every file (seconds = frames x frame time).
std::string eval_jsonl(const std::vector<nlohmann::json>& files);

}  // namespace keyanim::cli
