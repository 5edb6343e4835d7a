// keyanim sample: one pose from a .kanim, at a frame or a time, as channel values or positions.
#include <cstdio>
#include <iostream>

#include "commands.h"
#include "escape.h"
#include "io.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/report.h"
#include "suggest.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kSampleHelp =
    "usage: keyanim sample IN.kanim (--frame N | --time S) [--joint NAME] [--world]\n"
    "                      [--position-channels replace|add] [--json]\n"
    "One pose, decoded on the fly (fractional frames and times between frames are in-betweens).\n"
    "  --frame N             frame position, 0 .. frames-1, may be fractional\n"
    "  --time S              time in seconds, 0 .. the clip's duration (frame position =\n"
    "                        S / frame time); a frame or time the clip does not have is exit 1\n"
    "  --joint NAME          only this joint (default: all)\n"
    "  --world               world positions by forward kinematics instead of channel values\n"
    "  --position-channels replace|add\n"
    "                        with --world, how position channels below the root combine with\n"
    "                        OFFSET: replace it (Blender; default) or add to it (three.js)\n"
    "  --json                one JSON object on standard output\n";

namespace {

// A frame or time the clip does not have is a usage error (exit 1), as in render: positions are
// not clamped. A time may exceed the duration by rounding (duration = (frames - 1) frame time).
void check_position(const std::string& in, const Clip& clip, const char* option, double given, double pos) {
  const double last = double(clip.frame_count() - 1);
  if (pos >= 0.0 && (pos <= last || (option[2] == 't' && pos <= last * (1.0 + 1e-12)))) return;
  const std::string has = option[2] == 'f' ? "frames 0 to " + std::to_string(clip.frame_count() - 1)
                                            : "times 0 to " + offline::general_text(clip.duration(), 9) + " s";
  fail(kUsage, in + ": " + option + " " + offline::general_text(given, 9) + " is not in the clip (it has " + has + ")");
}

}  // namespace

int cmd_sample(const Argv& argv, Globals& g) {
  const Args args(argv, {"--frame", "--time", "--joint", "--position-channels"}, {"--world", "--json"});
  if (args.positional().size() != 1) fail(kUsage, "sample takes one .kanim file");
  if (args.has("--frame") == args.has("--time")) fail(kUsage, "sample needs exactly one of --frame and --time");
  const std::string in = args.positional()[0];
  const double frame = args.get_double("--frame", 0.0), time = args.get_double("--time", 0.0);
  const PositionReading reading = position_reading(args);
  if (args.has("--position-channels") && !args.has("--world")) fail(kUsage, "--position-channels goes with --world");
  const Clip clip = load_kanim(in, read_input(in, Kind::kanim, g), g);
  // A clip without frames, or without a frame time for --time, cannot give what was asked.
  if (clip.frame_count() == 0) fail(kBadInput, in + ": the clip has no frames to sample");
  if (args.has("--time") && !(clip.frame_time() > 0.0)) fail(kBadInput, in + ": the clip has no frame time; use --frame");
  const double pos = args.has("--frame") ? frame : time / clip.frame_time();
  check_position(in, clip, args.has("--frame") ? "--frame" : "--time", args.has("--frame") ? frame : time, pos);
  std::vector<float> row(clip.channel_count());
  if (const Status s = clip.sample(pos, row); s != Status::ok) fail(kUsage, std::string("cannot sample: ") + status_string(s));

  const Skeleton& sk = clip.skeleton();
  int32_t only = -1;
  if (auto name = args.get("--joint")) {
    for (uint32_t i = 0; i < sk.joints.size() && only < 0; ++i)
      if (sk.joints[i].name == *name && !sk.joints[i].end_site) only = int32_t(i);
    if (only < 0) fail(kUsage, in + ": " + no_joint_message(sk, *name));
  }
  std::vector<double> values(row.begin(), row.end());
  std::vector<offline::Vec3> world;
  if (args.has("--world")) offline::world_positions(sk, values.data(), world, reading);

  nlohmann::json joints = nlohmann::json::array();
  std::vector<uint32_t> row_node;  // the node of each entry of joints
  for (uint32_t i = 0; i < sk.joints.size(); ++i) {
    const Joint& j = sk.joints[i];
    if (only >= 0 && int32_t(i) != only) continue;
    nlohmann::json e = {{"name", offline::node_name(sk, i)}};
    if (args.has("--world")) {
      e["position"] = {world[i][0], world[i][1], world[i][2]};
    } else {
      if (j.end_site) continue;
      for (size_t k = 0; k < j.channels.size(); ++k) e[channel_name(j.channels[k])] = values[j.first_channel + k];
    }
    joints.push_back(e);
    row_node.push_back(i);
  }
  if (args.has("--json")) {
    std::cout << json_text({{"file", in}, {"frame_position", pos}, {"time", pos * clip.frame_time()}, {"joints", joints}}) << "\n";
    return kOk;
  }
  // Text: the channels in the file's order (a JSON object's keys come out sorted).
  for (size_t r = 0; r < joints.size(); ++r) {
    const nlohmann::json& e = joints[r];
    std::cout << printable(e["name"].get<std::string>());
    if (e.contains("position"))
      std::cout << " position=" << e["position"].dump();
    else
      for (ChannelType t : sk.joints[row_node[r]].channels) std::cout << " " << channel_name(t) << "=" << e[channel_name(t)].dump();
    std::cout << "\n";
  }
  return kOk;
}

}  // namespace keyanim::cli
