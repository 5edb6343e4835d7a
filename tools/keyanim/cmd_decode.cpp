// keyanim decode: .kanim -> BVH, at the source rate or tweened to another one.
#include <iostream>

#include "commands.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/decode.h"

namespace keyanim::cli {

const char* const kDecodeHelp =
    "usage: keyanim decode IN.kanim [-o OUT.bvh] [--fps F | --inbetweens N] [--frames A:B] [-f]\n"
    "Rebuilds every frame from the keyframes by Cardinal interpolation.\n"
    "  -o, --output FILE     output (default: IN with .bvh; '-' = standard output)\n"
    "  --fps F               resample at F frames per second (F > 0; default: the source rate).\n"
    "                        In-between frames come from the curves: motion tweening.\n"
    "  --inbetweens N        N extra frames in every source frame interval (default 0)\n"
    "  --frames A:B          source frames A to B inclusive (default: all; A <= B < frame count)\n";

int cmd_decode(const Argv& argv, Globals& g) {
  const Args args(argv, {"-o", "--output", "--fps", "--inbetweens", "--frames"}, {});
  if (args.positional().size() != 1) fail(kUsage, "decode takes one input file");
  const std::string in = args.positional()[0];
  std::string out = args.get("-o").value_or(args.get("--output").value_or(""));
  if (out.empty()) out = in == "-" ? "-" : swap_extension(in, ".bvh");

  offline::ResampleOptions opt;
  if (args.has("--fps") && args.has("--inbetweens")) fail(kUsage, "--fps and --inbetweens exclude each other");
  opt.fps = args.get_double("--fps", 0.0);
  if (args.has("--fps") && !(opt.fps > 0.0)) fail(kUsage, "--fps must be positive");
  opt.inbetweens = args.get_uint("--inbetweens", 0);
  if (auto r = args.get("--frames")) {
    const size_t colon = r->find(':');
    if (colon == std::string::npos) fail(kUsage, "--frames expects A:B");
    opt.first_frame = parse_uint("--frames", r->substr(0, colon));
    opt.last_frame = parse_uint("--frames", r->substr(colon + 1));
  }

  const Clip clip = load_kanim(in, read_input(in));
  if (opt.last_frame != UINT32_MAX && opt.last_frame >= clip.frame_count())
    fail(kUsage, "--frames: the clip has frames 0 to " + std::to_string(int64_t(clip.frame_count()) - 1));
  offline::Motion m;
  std::string error;
  if (!offline::decode_motion(clip, opt, m, error)) fail(kUsage, error);
  write_output(out, offline::write_bvh(m), false, g);
  if (g.verbosity > 0 && out != "-")
    std::cerr << in << " -> " << out << ": " << m.frame_count << " frames at " << m.frame_time << " s\n";
  return kOk;
}

}  // namespace keyanim::cli
