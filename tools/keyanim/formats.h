// The formats keyanim writes, each with the names that say it (io.h, check_output_name), so
// that every command refuses a misleading name alike. `stated`: the user gave the format with
// --to, and any name goes.
#pragma once
#include "escape.h"
#include "io.h"

namespace keyanim::cli {

inline OutputFormat bvh_format(bool stated) {
  return {"BVH text", {".bvh"}, "--to bvh", stated, "; .glb and .gltf names (or --to gltf) get glTF"};
}
inline OutputFormat glb_format(bool stated) { return {"binary glTF", {".glb"}, "--to gltf", stated, ""}; }
inline OutputFormat gltf_json_format() { return {"glTF JSON", {".gltf"}, "", false, ""}; }
inline OutputFormat gltf_buffer_format() { return {"a glTF buffer", {".bin"}, "", false, ""}; }
inline OutputFormat kanim_format(bool stated) { return {"a .kanim file", {".kanim"}, "--to kanim", stated, ""}; }
inline OutputFormat svg_format(bool stated, bool to_option = true) {
  return {"SVG", {".svg"}, to_option ? "--to svg" : "", stated, ""};
}
inline OutputFormat html_format(bool stated) { return {"an HTML page", {".html", ".htm"}, "--to html", stated, ""}; }
inline OutputFormat bank_format() { return {"a bank", {".kbank"}, "", false, ""}; }
inline OutputFormat json_lines_format() { return {"JSON lines", {".jsonl", ".ndjson", ".json"}, "", false, ""}; }

// --to of a command that writes one format, `name`: stated when given, a usage error if it
// names another.
inline bool stated_format(const Args& args, const std::string& name) {
  const std::optional<std::string> to = args.get("--to");
  if (to && *to != name) fail(kUsage, "--to expects " + name + " (the one format this command writes), got '" + printable(*to) + "'");
  return to.has_value();
}

}  // namespace keyanim::cli
