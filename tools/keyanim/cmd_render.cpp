// keyanim render: one frame of a skeleton as a stick figure (front and side view), as SVG; by
// default the original beside (overlaid on) its reconstruction.
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "figures.h"
#include "keyanim/clip.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "settings.h"

namespace keyanim::cli {

const char* const kRenderHelp =
    "usage: keyanim render IN.bvh|IN.kanim [--frame N] [--against OTHER] [-o FRAME.svg]\n"
    "                      [--error E|E%] [--keys MODE] [--tension T|fit] [-f]\n"
    "Draws one frame as a stick figure, front view (x-y) and side view (z-y) at one scale, in\n"
    "file length units. Two poses are overlaid and the joint farthest apart is labelled:\n"
    "  - with --against OTHER (BVH or .kanim with the same skeleton): IN and OTHER;\n"
    "  - else, for a BVH: the original and its reconstruction, encoded with the encoder options\n"
    "    below and decoded;\n"
    "  - else (a .kanim alone): its decoded pose only.\n"
    "  --frame N             frame number, 0 .. frames-1 (default: the middle frame)\n"
    "  --against OTHER       a second file to compare with\n"
    "  -o, --output FILE     SVG output (default: IN without extension + -frameN.svg;\n"
    "                        '-' = standard output)\n";

int cmd_render(const Argv& argv, Globals& g) {
  std::set<std::string> valued{"-o", "--output", "--frame", "--against"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  const Args args(argv, valued, {});
  if (args.positional().size() != 1) fail(kUsage, "render takes one input file");
  const offline::EncodeSettings settings = encode_settings(args);
  const std::string in = args.positional()[0];
  const auto against = args.get("--against");
  if (against && *against == "-" && in == "-") fail(kUsage, "only one input can be standard input");
  auto name_of = [](const std::string& p) {
    return p == "-" ? std::string("(stdin)") : std::filesystem::path(p).filename().string();
  };

  const std::vector<uint8_t> bytes = read_input(in);
  const bool in_is_kanim = looks_like_kanim(bytes);
  offline::Motion first;
  if (in_is_kanim) {
    std::string error;
    if (!offline::decode_motion(load_kanim(in, bytes), {}, first, error)) fail(kBadInput, in + ": " + error);
  } else {
    first = load_bvh_bytes(in, bytes, g);
  }
  if (first.frame_count == 0) fail(kBadInput, in + ": no frames to render");
  const uint32_t frame = args.get_uint("--frame", first.frame_count / 2);
  if (frame >= first.frame_count)
    fail(kUsage, "--frame " + std::to_string(frame) + " is past the last frame (" + std::to_string(first.frame_count - 1) + ")");

  offline::Motion second;
  std::vector<PoseSeries> series{{&first, name_of(in)}};
  std::string title = name_of(in) + ", frame " + std::to_string(frame);
  if (against) {
    second = load_motion(*against, g);
    if (!same_skeleton(first.skeleton, second.skeleton))
      fail(kBadInput, *against + ": not the same skeleton as " + in);
    if (frame >= second.frame_count)
      fail(kUsage, *against + " has no frame " + std::to_string(frame) + " (" + std::to_string(second.frame_count) + " frames)");
    series.push_back({&second, name_of(*against)});
    title += " against " + name_of(*against);
  } else if (!in_is_kanim) {
    offline::EncodeResult result;
    std::string error;
    if (!offline::encode(first, settings, result, error)) fail(kBadInput, in + ": " + error);
    if (!offline::decode_motion(offline::to_clip(result.clip), {}, second, error)) fail(kBadInput, in + ": " + error);
    series.front().label = "original";
    series.push_back({&second, "reconstruction (" + std::to_string(result.total_keys) + " keys, " +
                                   settings_text(settings, result.tolerance_units) + ")"});
    title += ": original and reconstruction";
  }

  std::string out = args.get("-o").value_or(args.get("--output").value_or(""));
  if (out.empty()) out = in == "-" ? "-" : swap_extension(in, "") + "-frame" + std::to_string(frame) + ".svg";
  const PoseFigure fig = render_pose(series, frame, title);
  write_output(out, fig.svg, false, g);
  if (g.verbosity > 0) {
    std::cerr << in << " -> " << out << ": frame " << frame;
    if (series.size() == 2)
      std::cerr << ", largest distance " << fig.worst_distance << " ("
                << figure_node_name(first.skeleton, fig.worst_node) << ")";
    std::cerr << "\n";
  }
  return kOk;
}

}  // namespace keyanim::cli
