// `keyanim encode --manifest LIST -o OUTDIR [--shard I/N] [--skip-existing] [--report R.jsonl]`:
// batch runs that survive being killed and split across machines with no coordination but the
// number of shards. README "Converting a library of millions of clips" shows it under GNU
// parallel and Slurm (scripts/slurm_encode.sh).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "cli.h"
#include "keyanim/offline/encode.h"

namespace keyanim::cli {

// The manifest options, to declare in encode's Args.
inline const char* const kManifestValuedOptions[] = {"--manifest", "--shard", "--report"};
inline const char* const kManifestFlags[] = {"--skip-existing", "--bank"};

// Shard I of N: entries I, I + N, I + 2N, ... of the list (0 <= I < N).
struct Shard {
  uint64_t index = 0, count = 1;
};
// "I/N"; usage error if malformed.
Shard parse_shard(const std::string& text);

// The list's entries: one path per line (a trailing CR dropped), empty lines skipped.
std::vector<std::string> manifest_entries(const std::string& text);
// The list's text ('-': standard input); exit 2 if it cannot be opened.
std::string read_manifest(const std::string& list);

// Where an input's output goes: its path, made relative (an absolute path loses its root, a
// path climbing out of the current directory is made absolute first), below `outdir`, with
// the extension .kanim. Different inputs never share an output.
std::string mirrored_output(const std::string& input, const std::string& outdir);

// Runs the manifest mode of `encode` (args hold --manifest); returns the exit code: 0 when
// every input of the shard was encoded or skipped, else the first failure's.
int encode_manifest(const Args& args, const offline::EncodeSettings& settings, Globals& g);

}  // namespace keyanim::cli
