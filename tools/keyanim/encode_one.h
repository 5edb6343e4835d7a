// Encoding one BVH file into one .kanim file (cmd_encode.cpp), for `encode` on a file, on a
// directory and on a manifest (manifest.cpp).
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "cli.h"
#include "keyanim/offline/encode.h"

namespace keyanim::cli {

struct Encoded {
  nlohmann::json summary;  // also what the human line says
  std::string warning;     // --error exceeded in a key mode that does not apply it
};

class Progress;

// Checks the input and the output first (io.h), then encodes, writes atomically and returns
// the summary printed by --json; fails (cli::Failure) otherwise. `to_given`: --to kanim, so
// that `out` may have any name (formats.h). `runtime`: --runtime, the runtime profile (spec
// section 9) instead of the archive. With `bar`, its stages show on it (progress.h).
Encoded encode_one(const std::string& in, const std::string& out, offline::EncodeSettings settings,
                   bool error_given, bool to_given, bool runtime, const Globals& g, Progress* bar = nullptr);

}  // namespace keyanim::cli
