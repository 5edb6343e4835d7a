// keyanim plot: one channel's original curve against its reconstruction, keys marked, as SVG.
#include <cctype>
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "figures.h"
#include "settings.h"

namespace keyanim::cli {

const char* const kPlotHelp =
    "usage: keyanim plot IN.bvh --channel JOINT:CHANNEL [-o CURVE.svg] [--to svg] [--frames A:B]\n"
    "                    [--error E|E%] [--shell D|D%] [--keys MODE] [--tension T|fit]\n"
    "                    [--rotations euler|quaternion] [--level N] [-f]\n"
    "Encodes IN with the given settings and draws one channel over the frames: the original curve\n"
    "(rotations unwrapped), the decoder's reconstruction and one dot per key. Values in degrees for\n"
    "rotations, in file length units for positions. Rotations are encoded as Euler channels here\n"
    "(--rotations euler, this command's default), so that a rotation channel's keys are its own.\n"
    "  --channel JOINT:CHANNEL  required; CHANNEL is Xposition, Yposition, Zposition, Xrotation,\n"
    "                        Yrotation or Zrotation (e.g. RightArm:Zrotation)\n"
    "  --frames A:B          draw frames A..B only, inclusive (default: all; A: or :B leave one\n"
    "                        end open). The whole clip is encoded either way.\n"
    "  -o, --output FILE     SVG output (default: IN without extension + -JOINT-CHANNEL.svg;\n"
    "                        '-' = standard output)\n"
    "  --to svg              write the SVG under a name that does not end in .svg (without it,\n"
    "                        a name that says another format, curve.png, is refused)\n";

namespace {

// A joint name made safe for a file name: anything but letters, digits, '-', '_' becomes '_'.
std::string file_safe(const std::string& s) {
  std::string out = s;
  for (char& c : out)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')) c = '_';
  return out;
}

}  // namespace

int cmd_plot(const Argv& argv, Globals& g) {
  std::set<std::string> valued{"-o", "--output", "--channel", "--frames", "--to"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  const Args args(argv, valued, {});
  if (args.positional().size() != 1) fail(kUsage, "plot takes one BVH file");
  const auto spec = args.get("--channel");
  if (!spec) fail(kUsage, "plot needs --channel JOINT:CHANNEL");
  // A channel's own keys are drawn: Euler rotations unless asked otherwise (a quaternion node's
  // keys hold its x, y, z; its channel is then drawn from them, with a dot per shared key).
  const offline::EncodeSettings settings = encode_settings(args, true, true, offline::Rotations::euler);
  const std::string in = args.positional()[0];
  const bool to_svg = stated_format(args, "svg");

  std::string out = args.get("-o").value_or("");
  if (out.empty()) {
    const size_t colon = spec->rfind(':');
    out = in == "-" ? "-"
                    : swap_extension(in, "") + "-" + file_safe(spec->substr(0, colon)) + "-" +
                          file_safe(spec->substr(colon == std::string::npos ? spec->size() : colon + 1)) + ".svg";
  }
  FrameRange range;
  const std::optional<std::string> frames = args.get("--frames");
  if (frames) {
    const size_t colon = frames->find(':');
    if (colon == std::string::npos) fail(kUsage, "--frames expects A:B, got '" + *frames + "'");
    if (colon > 0) range.first = parse_uint("--frames", frames->substr(0, colon));
    if (colon + 1 < frames->size()) range.last = parse_uint("--frames", frames->substr(colon + 1));
  }

  Input input(in, g);
  Output output(out, false, g, ids_of({&input}), svg_format(to_svg));
  const offline::Motion motion = load_bvh_bytes(in, input.read(Kind::bvh), g);
  std::string error;
  const std::optional<uint32_t> channel = find_channel(motion.skeleton, *spec, error);
  if (!channel) fail(kUsage, in + ": " + error);
  if (motion.frame_count == 0) fail(kBadInput, in + ": no frames to plot");
  check_settings_for(settings, motion, in);
  if (frames && (range.first > range.last || range.first >= motion.frame_count))
    fail(kUsage, "--frames " + *frames + " holds no frame of " + in + " (frames 0.." +
                     std::to_string(motion.frame_count - 1) + ")");
  const std::string label = in == "-" ? "(stdin)" : std::filesystem::path(in).filename().string();
  ChannelPlot plot;
  if (!plot_channel(motion, settings, *channel, label, plot, error, range)) fail(kBadInput, in + ": " + error);
  output.write(plot.svg);
  output.commit();
  if (g.verbosity > 0)
    std::cerr << printable(in + " -> " + out + ": " + *spec) << ", " << count_of(plot.key_count, "key") << " shown of "
              << plot.channel_keys << ", max channel error " << plot.max_channel_error << "; alone, it moves a point by "
              << plot.channel_world_error << " at most ("
              << printable(plot.channel_world_point) << ", frame " << plot.channel_world_frame << "), "
              << (plot.tolerance_units > 0 ? plot.channel_world_error / plot.tolerance_units : 0.0) << "x the "
              << (settings.key_mode == offline::KeyMode::error ? "tolerance " : "--error ") << plot.tolerance_units << "\n";
  return kOk;
}

}  // namespace keyanim::cli
