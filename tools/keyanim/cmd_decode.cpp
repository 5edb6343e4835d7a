// keyanim decode: .kanim -> BVH, at the source rate or tweened to another one.
#include <cmath>
#include <iostream>

#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "gltf_output.h"
#include "io.h"
#include "progress.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kDecodeHelp =
    "usage: keyanim decode IN.kanim [-o OUT.bvh|OUT.glb|OUT.gltf] [--to bvh|gltf] [--fps F | --inbetweens N]\n"
    "                      [--frames A:B] [--error E|E%] [--linear] [--no-mesh] [-f]\n"
    "Rebuilds every frame from the keyframes by Cardinal interpolation.\n"
    "  -o, --output FILE     output (default: IN with .bvh, or .glb with --to gltf; '-' = standard output)\n"
    "  --fps F               resample at F frames per second (F > 0; default: the source rate).\n"
    "                        In-between frames come from the curves: motion tweening. A rate\n"
    "                        within 0.01% of N times the clip's own (or of it divided by M) gives\n"
    "                        its frames exactly and N-1 in-betweens each (or every M-th frame);\n"
    "                        any other, frames every 1/F s up to the clip's end.\n"
    "  --inbetweens N        N extra frames in every source frame interval (default 0; BVH only)\n"
    "  --frames A:B          source frames A to B inclusive (default: all; A <= B < frame count)\n"
    "  --to bvh|gltf         output format (default: by the output's extension, .glb/.gltf: glTF).\n"
    "                        Without it, a name that says another format (walk.fbx) is refused\n"
    "The BVH is written as it is decoded (memory does not grow with its length); a request for\n"
    "more than --max-values values (frames x channels) is refused before any is made (exit 6).\n"
    "glTF 2.0 output (.gltf writes its buffer to OUT.bin beside it; '-' gets a .glb): one node per\n"
    "joint and End Site, all joints of one skin (an armature in Blender) with a mesh drawing the\n"
    "bones, one animation. Translations are the clip's curves exactly (CUBICSPLINE);\n"
    "rotations are quaternion keys fitted so that every joint, End Site and shell point (2% of\n"
    "the skeleton size along each joint's axes) stays within --error of the clip at every source\n"
    "frame, as a glTF player computes it. With --fps, LINEAR keys every 1/F s instead (the error\n"
    "is reported, not bounded). Time 0 is the first exported frame.\n"
    "  --error E|E%          the fit's world-space tolerance, length units or percent of the skeleton\n"
    "                        size (default: the tolerance the clip was encoded with, else 0.05%)\n"
    "  --linear              LINEAR keys only, translations fitted too: for players that ignore\n"
    "                        CUBICSPLINE tangents (Blender's glTF importer)\n"
    "  --no-mesh             the skin without the mesh that draws the bones (Debian's Blender 3.4\n"
    "                        fails to import any glTF mesh unless Shading is Flat)\n";

int cmd_decode(const Argv& argv, Globals& g) {
  const Args args(argv, {"-o", "--output", "--fps", "--inbetweens", "--frames", "--to", "--error"}, {"--linear", "--no-mesh"});
  if (args.positional().size() != 1) fail(kUsage, "decode takes one input file");
  const std::string in = args.positional()[0];
  std::string out = args.get("-o").value_or("");
  const bool gltf = wants_gltf(args, out);
  if (out.empty()) out = in == "-" ? "-" : swap_extension(in, gltf ? ".glb" : ".bvh");
  if ((args.has("--error") || args.has("--linear") || args.has("--no-mesh")) && !gltf)
    fail(kUsage, "--error, --linear and --no-mesh apply to glTF output");

  offline::ResampleOptions opt;
  if (args.has("--fps") && args.has("--inbetweens")) fail(kUsage, "--fps and --inbetweens exclude each other");
  opt.fps = args.get_double("--fps", 0.0);
  if (args.has("--fps") && !(opt.fps > 0.0)) fail(kUsage, "--fps must be positive");
  if (args.has("--fps") && !std::isfinite(1.0 / opt.fps))  // 1e-309: Frame Time: inf, unreadable
    fail(kUsage, "--fps " + *args.get("--fps") + ": the frame time 1/F is not a finite number");
  opt.inbetweens = args.get_uint("--inbetweens", 0);
  if (auto r = args.get("--frames")) {
    const size_t colon = r->find(':');
    if (colon == std::string::npos) fail(kUsage, "--frames expects A:B");
    opt.first_frame = parse_uint("--frames", r->substr(0, colon));
    opt.last_frame = parse_uint("--frames", r->substr(colon + 1));
  }

  Input input(in, g);
  if (gltf) return decode_gltf(input, out, opt, args, g);
  Output output(out, false, g, ids_of({&input}), bvh_format(args.has("--to")));
  const Clip clip = load_kanim(in, input.read(Kind::kanim), g);
  // (Given, not the UINT32_MAX default: --frames 0:4294967295 was taken for "to the end".)
  if (args.has("--frames") && opt.last_frame >= clip.frame_count())
    fail(kUsage, "--frames: the clip has frames 0 to " + std::to_string(int64_t(clip.frame_count()) - 1));
  offline::FrameDecoder decoder;
  or_fail(kUsage, "", [&] { decoder.start(clip, opt); });
  check_values(decoder.frame_count(), clip.channel_count(), "decoding " + in, g);

  // Frame by frame from the clip to the output: memory does not grow with the frame count.
  offline::BvhWriter writer(clip.skeleton(), decoder.frame_count(), decoder.frame_time(),
                            [&](std::string_view text) { output.write(text); });
  std::vector<double> row(clip.channel_count());
  Progress bar(g, in);
  for (uint64_t i = 0; i < decoder.frame_count(); ++i) {
    if (i % 256 == 0) bar.update("decoding", double(i) / double(decoder.frame_count()));
    decoder.frame(i, row);
    writer.frame(row.data());
  }
  writer.finish();  // (an error here, a frame count other than declared, is a bug: exit 7)
  output.commit();
  bar.erase();
  if (g.verbosity > 0 && out != "-")
    std::cerr << printable(in + " -> " + out) << ": " << count_of(decoder.frame_count(), "frame") << " at " << offline::general_text(decoder.frame_time()) << " s\n";
  return kOk;
}

}  // namespace keyanim::cli
