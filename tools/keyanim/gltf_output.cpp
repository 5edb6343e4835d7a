// keyanim decode to glTF (gltf_output.h).
#include "gltf_output.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "escape.h"
#include "formats.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/gltf.h"
#include "keyanim/offline/metrics.h"
#include "progress.h"
#include "keyanim/offline/report.h"
#include "settings.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {
namespace {

// Ignoring ASCII case: WALK.GLB is a glTF name too.
bool ends_with(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.begin(), suffix.end(), s.end() - std::ptrdiff_t(suffix.size()),
                    [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b)); });
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

// With --fps the keys are samples, not fitted: the error is measured, not bounded. When it is
// past the tolerance the user is told by how much and why (issue 28, item 17): a player
// interpolates linearly between keys 1/F s apart, so at a rate below the clip's the motion
// between two samples (at the worst frame: between which keys) is lost.
std::string resampled_warning(const Clip& clip, const offline::GltfOptions& o, const offline::GltfReport& r) {
  if (o.fps <= 0.0 || !(r.max_error > r.tolerance) || !(r.tolerance > 0.0)) return {};
  const double ft = clip.frame_time();
  const double t = (double(r.worst_frame) - double(o.first_frame)) * ft;  // time 0 at the first exported frame
  const double before = std::floor(t * o.fps) / o.fps, after = before + 1.0 / o.fps;
  if (!(ft > 0.0)) return {};  // one frame: no motion between keys to lose
  char buf[768];
  std::snprintf(buf, sizeof buf,
                "with --fps %g the export is %.3g from the clip (%s, frame %u), %.0fx its tolerance %.6g: a player "
                "interpolates linearly between keys 1/%g s apart, so the motion between two keys is lost (at frame %u, "
                "between the keys at %.4g s and %.4g s, source frames %.4g and %.4g; the clip has a frame every %.4g s, "
                "%.4g fps). The error is "
                "measured at every source frame of the export against the clip; without --fps the keys are fitted "
                "within the tolerance",
                o.fps, r.max_error, offline::point_name(clip.skeleton(), r.worst_node, uint32_t(r.worst_axis + 1)).c_str(),
                r.worst_frame, r.max_error / r.tolerance, r.tolerance, o.fps, r.worst_frame, before, after,
                o.first_frame + before / ft, o.first_frame + after / ft, ft,
                ft > 0.0 ? 1.0 / ft : 0.0);
  return buf;
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
  o.bone_mesh = !args.has("--no-mesh");
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
    bin.emplace(bin_path, true, g, ids_of({&input}), gltf_buffer_format());
  }
  Output main(out, !split, g, ids_of({&input}), split ? gltf_json_format() : glb_format(args.has("--to")));

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
  if (bin && !asset.bin.empty()) {  // an asset without a buffer leaves no .bin
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
  const std::string warning = resampled_warning(clip, o, r);
  if (!warning.empty() && g.verbosity > 0) std::cerr << "keyanim: warning: " << printable(in + ": " + warning) << "\n";
  return kOk;
}

}  // namespace keyanim::cli
