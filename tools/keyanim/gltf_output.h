// keyanim decode to glTF 2.0 (.glb, or .gltf with its .bin): the branch of `decode` that
// calls the library's export (keyanim/offline/gltf.h).
#pragma once
#include <string>

#include "cli.h"
#include "io.h"
#include "keyanim/offline/decode.h"

namespace keyanim::cli {

// True for --to gltf, or (without --to) an output named *.glb or *.gltf; usage error for a
// --to other than bvh or gltf.
bool wants_gltf(const Args& args, const std::string& out);
// Opens `out` (and its .bin for a .gltf; standard output gets a .glb) before the work, then
// loads the clip from `input` and writes the asset.
int decode_gltf(Input& input, const std::string& out, const offline::ResampleOptions& opt, const Args& args,
                const Globals& g);

}  // namespace keyanim::cli
