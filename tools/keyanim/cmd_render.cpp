// keyanim render: one frame of a skeleton as a stick figure (front and side view), as SVG; by
// default the original beside (overlaid on) its reconstruction.
#include <filesystem>
#include <iostream>
#include <optional>

#include "commands.h"
#include "escape.h"
#include "io.h"
#include "figures.h"
#include "keyanim/clip.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/report.h"
#include "settings.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kRenderHelp =
    "usage: keyanim render IN.bvh|IN.kanim [--frame N] [--against OTHER] [-o FRAME.svg]\n"
    "                      [--position-channels replace|add] [--error E|E%] [--shell D|D%]\n"
    "                      [--keys MODE] [--tension T|fit] [--level N] [-f]\n"
    "Draws one frame as a stick figure, front view (x-y) and side view (z-y) at one scale, in\n"
    "file length units. Two poses are overlaid and the joint farthest apart is labelled:\n"
    "  - with --against OTHER (BVH or .kanim with the same skeleton): IN and OTHER;\n"
    "  - else, for a BVH: the original and its reconstruction, encoded with the encoder options\n"
    "    below and decoded;\n"
    "  - else (a .kanim alone): its decoded pose only.\n"
    "  --frame N             frame number, 0 .. frames-1 (default: the middle frame)\n"
    "  --against OTHER       a second file to compare with\n"
    "  -o, --output FILE     SVG output (default: IN without extension + -frameN.svg;\n"
    "                        '-' = standard output)\n"
    "  --position-channels replace|add\n"
    "                        how position channels below the root combine with OFFSET: replace\n"
    "                        it (Blender; default) or add to it (three.js)\n";

namespace {

// One input's poses: a BVH's motion (all of it: it is no larger than the file), or a clip, of
// which only the frame drawn is decoded, whatever frame count it declares.
struct Poses {
  std::optional<offline::Motion> motion;
  std::optional<Clip> clip;

  Poses(const std::string& path, Input& input, const Globals& g) {
    const std::vector<uint8_t> bytes = input.read(Kind::either);
    if (looks_like_kanim(bytes)) clip = load_kanim(path, bytes, g);
    else motion = load_bvh_bytes(path, bytes, g);
  }
  uint32_t frame_count() const { return clip ? clip->frame_count() : motion->frame_count; }
  // Frame `frame` (< frame_count()) alone, as a one-frame motion.
  offline::Motion one_frame(uint32_t frame) const {
    if (clip) {
      offline::ResampleOptions o;
      o.first_frame = o.last_frame = frame;
      return or_fail(kBadInput, "", [&] { return offline::decode_motion(*clip, o); });
    }
    offline::Motion m;
    m.skeleton = motion->skeleton;
    m.frame_count = 1;
    m.frame_time = motion->frame_time;
    m.values.assign(motion->frame(frame), motion->frame(frame) + motion->channel_count());
    return m;
  }
};

}  // namespace

int cmd_render(const Argv& argv, Globals& g) {
  std::set<std::string> valued{"-o", "--output", "--frame", "--against", "--position-channels"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  const Args args(argv, valued, {});
  if (args.positional().size() != 1) fail(kUsage, "render takes one input file");
  const offline::EncodeSettings settings = encode_settings(args);
  const std::string in = args.positional()[0];
  const auto against = args.get("--against");
  if (against && *against == "-" && in == "-") fail(kUsage, "only one input can be standard input");
  const uint32_t frame_option = args.get_uint("--frame", 0);  // parsed before any work
  const PositionReading reading = position_reading(args);
  auto name_of = [](const std::string& p) {
    return p == "-" ? std::string("(stdin)") : std::filesystem::path(p).filename().string();
  };

  Input input(in, g);
  std::optional<Input> other;
  if (against) other.emplace(*against, g);
  const Poses poses(in, input, g);
  if (poses.frame_count() == 0) fail(kBadInput, in + ": no frames to render");
  const uint32_t frame = args.has("--frame") ? frame_option : poses.frame_count() / 2;
  if (frame >= poses.frame_count())
    fail(kUsage, "--frame " + std::to_string(frame) + " is past the last frame (" + std::to_string(poses.frame_count() - 1) + ")");
  std::string out = args.get("-o").value_or("");
  if (out.empty()) out = in == "-" ? "-" : swap_extension(in, "") + "-frame" + std::to_string(frame) + ".svg";
  Output output(out, false, g, ids_of(other ? std::vector<const Input*>{&input, &*other} : std::vector<const Input*>{&input}));

  const offline::Motion first = poses.one_frame(frame);
  offline::Motion second;
  std::vector<PoseSeries> series{{&first, name_of(in)}};
  std::string title = name_of(in) + ", frame " + std::to_string(frame);
  if (against) {
    const Poses theirs(*against, *other, g);
    const Skeleton& skeleton = theirs.clip ? theirs.clip->skeleton() : theirs.motion->skeleton;
    if (!same_skeleton(first.skeleton, skeleton)) fail(kBadInput, *against + ": not the same skeleton as " + in);
    if (frame >= theirs.frame_count())
      fail(kUsage, *against + " has no frame " + std::to_string(frame) + " (" + count_of(theirs.frame_count(), "frame") + ")");
    second = theirs.one_frame(frame);
    series.push_back({&second, name_of(*against)});
    title += " against " + name_of(*against);
  } else if (poses.motion) {
    check_settings_for(settings, *poses.motion, in);
    const offline::EncodeResult result =
        or_fail(kBadInput, in + ": ", [&] { return offline::encode(*poses.motion, settings); });
    const Clip clip = offline::to_clip(result.clip);
    offline::ResampleOptions o;
    o.first_frame = o.last_frame = frame;
    second = or_fail(kBadInput, in + ": ", [&] { return offline::decode_motion(clip, o); });
    series.front().label = "original";
    series.push_back({&second, "reconstruction (" + std::to_string(result.total_keys) + " keys, " +
                                   settings_text(settings, result.tolerance_units) + ")"});
    title += ": original and reconstruction";
  }

  const PoseFigure fig = render_pose(series, 0, title, reading);
  output.write(fig.svg);
  output.commit();
  if (g.verbosity > 0) {
    std::cerr << printable(in + " -> " + out) << ": frame " << frame;
    if (series.size() == 2)
      std::cerr << ", largest distance " << offline::general_text(fig.worst_distance) << " ("
                << printable(offline::node_name(first.skeleton, fig.worst_node)) << ")";
    std::cerr << "\n";
  }
  return kOk;
}

}  // namespace keyanim::cli
