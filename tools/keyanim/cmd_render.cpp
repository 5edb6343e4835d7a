// keyanim render: one frame of a skeleton as a stick figure (front and side view), as SVG; by
// default the original beside (overlaid on) its reconstruction.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "conventions.h"
#include "figures.h"
#include "keyanim/clip.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/report.h"
#include "settings.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kRenderHelp =
    "usage: keyanim render IN.bvh|IN.kanim [--frame N] [--against OTHER] [-o FRAME.svg] [--to svg]\n"
    "                      [--position-channels replace|add] [--up y|z|auto] [--error E|E%]\n"
    "                      [--shell D|D%] [--keys MODE] [--tension T|fit] [--rotations quaternion|euler]\n"
    "                      [--level N] [-f]\n"
    "Draws one frame as a stick figure, front view (x-y) and side view (z-y) at one scale, in\n"
    "file length units (x-z and y-z for a z-up file). Two poses are overlaid and the joint\n"
    "farthest apart is labelled:\n"
    "  - with --against OTHER (BVH or .kanim with the same skeleton): IN and OTHER;\n"
    "  - else, for a BVH: the original and its reconstruction, encoded with the encoder options\n"
    "    below and decoded;\n"
    "  - else (a .kanim alone): its decoded pose only.\n"
    "  --frame N             frame number, 0 .. frames-1 (default: the middle frame)\n"
    "  --against OTHER       a second file to compare with\n"
    "  -o, --output FILE     SVG output (default: IN without extension + -frameN.svg;\n"
    "                        '-' = standard output)\n"
    "  --to svg              write the SVG under a name that does not end in .svg (without it,\n"
    "                        a name that says another format, frame.png, is refused)\n"
    "  --position-channels replace|add\n"
    "                        how position channels below the root combine with OFFSET: replace\n"
    "                        it (Blender; default) or add to it (three.js). When the file has\n"
    "                        such channels and the option is not given, render says which\n"
    "                        reading it used and under which the bones keep their lengths\n"
    "  --up y|z|auto         the file's up axis (default auto: of y and z, the one along which\n"
    "                        the rest pose spans more; y when neither spans 1.5 times the other).\n"
    "                        render says which it used when it detected z or could not tell\n";

namespace {

std::optional<UpAxis> up_axis_option(const Args& args) {
  const std::optional<std::string> v = args.get("--up");
  if (!v || *v == "auto") return std::nullopt;
  if (*v == "y") return UpAxis::y;
  if (*v == "z") return UpAxis::z;
  fail(kUsage, "--up expects y, z or auto, got '" + *v + "'");
}

// Three significant digits: "16.6", "4", "0.0123".
std::string short_length(double v) {
  std::ostringstream o;
  o << std::setprecision(3) << v;
  return o.str();
}

std::string up_note(const UpGuess& g) {
  const std::string spans = "the rest pose spans " + short_length(g.extents[2]) + " along z and " + short_length(g.extents[1]) + " along y";
  if (g.ambiguous) return "up axis y, taken: " + spans + ", too close to tell which is up (--up z for the other)";
  return "up axis z, detected: " + spans + " (--up y to override)";
}

// Which reading render used (the default: it was not given) and which keeps the bones rigid.
std::string reading_note(const offline::Motion& one_frame) {
  std::string note = "position channels below the root read as replace (Blender's reading, the default)";
  const std::optional<PositionReading> rigid = rigid_reading(one_frame, 0);
  if (rigid == PositionReading::add)
    return note + "; its bones keep their lengths under add (three.js's reading): --position-channels add";
  if (rigid == PositionReading::replace) return note + ", under which its bones keep their lengths";
  return note + "; add (three.js's reading) poses it differently: --position-channels add";
}

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
  std::set<std::string> valued{"-o", "--output", "--frame", "--against", "--position-channels", "--up", "--to"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  const Args args(argv, valued, {});
  if (args.positional().size() != 1) fail(kUsage, "render takes one input file");
  const offline::EncodeSettings settings = encode_settings(args);
  const std::string in = args.positional()[0];
  const auto against = args.get("--against");
  if (against && *against == "-" && in == "-") fail(kUsage, "only one input can be standard input");
  const uint32_t frame_option = args.get_uint("--frame", 0);  // parsed before any work
  const PositionReading reading = position_reading(args);
  const std::optional<UpAxis> up_option = up_axis_option(args);
  const bool to_svg = stated_format(args, "svg");
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
  Output output(out, false, g, ids_of(other ? std::vector<const Input*>{&input, &*other} : std::vector<const Input*>{&input}),
                svg_format(to_svg));

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

  const UpGuess guess = detect_up_axis(first.skeleton);
  const UpAxis up = up_option.value_or(guess.axis);
  const PoseFigure fig = render_pose(series, 0, title, reading, up);
  output.write(fig.svg);
  output.commit();
  if (g.verbosity > 0) {
    std::cerr << printable(in + " -> " + out) << ": frame " << frame;
    if (series.size() == 2)
      std::cerr << ", largest distance " << offline::general_text(fig.worst_distance) << " ("
                << printable(offline::node_name(first.skeleton, fig.worst_node)) << ")";
    std::cerr << "\n";
    // What the file leaves open, when render chose it.
    if (!up_option && (guess.ambiguous || guess.axis == UpAxis::z)) std::cerr << printable(in) << ": " << up_note(guess) << "\n";
    if (!args.has("--position-channels") && offline::has_position_channels_below_root(first.skeleton))
      std::cerr << printable(in) << ": " << reading_note(first) << "\n";
  }
  return kOk;
}

}  // namespace keyanim::cli
