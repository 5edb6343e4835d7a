// keyanim decode to glTF (gltf_output.h).
#include "gltf_output.h"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "escape.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/gltf.h"
#include "keyanim/offline/metrics.h"
#include "progress.h"
#include "keyanim/offline/report.h"
#include "settings.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A file name as a relative URI reference (RFC 3986): bytes other than unreserved ones are
// percent-encoded, so that "my walk.bin" becomes "my%20walk.bin".
std::string uri_of_file_name(const std::string& name) {
  static const char kHex[] = "0123456789ABCDEF";
  std::string o;
  for (unsigned char c : name) {
    const bool unreserved = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                            c == '-' || c == '.' || c == '_' || c == '~';
    if (unreserved) o += char(c);
    else o += {'%', kHex[c >> 4], kHex[c & 15]};
  }
  return o;
}

}  // namespace

bool wants_gltf(const Args& args, const std::string& out) {
  if (auto to = args.get("--to")) {
    if (*to != "bvh" && *to != "gltf") fail(kUsage, "--to expects bvh or gltf, got '" + printable(*to) + "'");
    return *to == "gltf";
  }
  return ends_with(out, ".glb") || ends_with(out, ".gltf");
}

int decode_gltf(Input& input, const std::string& out, const offline::ResampleOptions& opt, const Args& args,
                const Globals& g) {
  if (args.has("--inbetweens")) fail(kUsage, "--inbetweens is for BVH output: a glTF player interpolates itself");
  const std::string& in = input.path();
  offline::GltfOptions o;
  if (auto e = args.get("--error")) {
    offline::EncodeSettings s;
    parse_tolerance(*e, s);
    o.tolerance = s.tolerance;
    o.tolerance_in_percent = s.tolerance_in_percent;
  }
  o.linear_only = args.has("--linear");
  o.fps = opt.fps;
  o.first_frame = opt.first_frame;
  o.last_frame = opt.last_frame;
  if (in != "-") o.name = std::filesystem::path(in).stem().string();
  // A .gltf and its .bin, or one .glb: both checked and opened before the work.
  const bool split = out != "-" && ends_with(out, ".gltf");
  const std::string bin_path = split ? swap_extension(out, ".bin") : "";
  std::optional<Output> bin;
  if (split) {
    o.bin_uri = uri_of_file_name(std::filesystem::path(bin_path).filename().string());
    bin.emplace(bin_path, true, g, ids_of({&input}));
  }
  Output main(out, !split, g, ids_of({&input}));

  const Clip clip = load_kanim(in, input.read(Kind::kanim), g);
  if (args.has("--frames") && o.last_frame >= clip.frame_count())  // as the BVH output (cmd_decode.cpp)
    fail(kUsage, "--frames: the clip has frames 0 to " + std::to_string(int64_t(clip.frame_count()) - 1));
  check_values(clip.frame_count(), clip.channel_count(), "exporting " + in, g);
  Progress bar(g, in);
  EncodeProgress progress(&bar, o.fps == 0.0, false);
  o.progress = progress.encoding();
  const offline::GltfOutput asset = or_fail(kUsage, in + ": glTF export: ", [&] { return offline::export_gltf(clip, o); });
  bar.erase();
  const offline::GltfReport& r = asset.report;
  if (bin && !asset.bin.empty()) {  // a clip without frames has no buffer: no .bin is left
    bin->write(asset.bin);
    bin->commit();
  }
  main.write(asset.main);
  main.commit();
  if (g.verbosity > 0 && out != "-") {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  ": %zu bytes, %u nodes, %u translation tracks (%u keys), %u rotation tracks (%u LINEAR, "
                  "%u CUBICSPLINE, %u keys); error max %s (%s, frame %u), tolerance %s\n",
                  asset.main.size() + asset.bin.size(), r.nodes, r.translation_tracks, r.translation_keys,
                  r.linear_rotation_tracks + r.cubic_rotation_tracks, r.linear_rotation_tracks, r.cubic_rotation_tracks,
                  r.rotation_keys, offline::general_text(r.max_error).c_str(),
                  printable(offline::point_name(clip.skeleton(), r.worst_node, uint32_t(r.worst_axis + 1))).c_str(),
                  r.worst_frame, offline::general_text(r.tolerance).c_str());
    std::cerr << printable(in + " -> " + out) << buf;
  }
  return kOk;
}

}  // namespace keyanim::cli
