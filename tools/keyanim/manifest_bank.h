// encode --manifest LIST -o LIB.kbank --bank [--shard I/N]: a shard's inputs encoded in
// parallel into one bank (spec/FORMAT.md section 10) instead of one file each; `keyanim pack`
// merges the shards' banks. Each clip is named as its .kanim would be below OUTDIR, without the
// extension, so that `keyanim unpack LIB -o OUTDIR` gives the files a run without --bank does.
#pragma once
#include <set>
#include <string>
#include <vector>

#include "cli.h"
#include "keyanim/offline/encode.h"
#include "manifest_report.h"

namespace keyanim::cli {

// The clip name of a manifest entry: its mirrored path (manifest.h) without root or extension.
std::string manifest_clip_name(const std::string& input);

// Over the whole list, before any work (so that every shard refuses it alike): exit 2 if an
// entry's name cannot name a clip, or two entries share one (m.bvh and m.BVH).
void check_manifest_names(const std::vector<std::string>& all);

// Encodes `inputs` (the shard's) into the bank at -o; failed inputs are reported and left out.
// With --skip-existing, a bank at -o that opens and holds exactly the shard's clips is kept.
// Returns 0, or the first failure's exit code.
int encode_shard_bank(const Args& args, const offline::EncodeSettings& settings, const Globals& g,
                      const std::vector<std::string>& inputs, const std::set<std::string>& done, Report& report);

}  // namespace keyanim::cli
