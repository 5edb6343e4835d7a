#include "settings.h"

#include "keyanim/offline/error.h"
#include "keyanim/offline/keyframes.h"
#include "keyanim/offline/settings_text.h"

namespace keyanim::cli {

std::string encoder_options_help(bool with_error) {
  const char* const error =
      "  --error E|E%          tolerance: max world-space error of every joint, End Site and shell\n"
      "                        point, in file length units, or in percent of the skeleton size\n"
      "                        (largest side of the rest-pose box). Default 0.05%. Range: > 0\n"
      "                        (percent: at most 100).\n";
  const char* const others =
      "  --shell D|D%          shell points: three per joint at distance D along its local x, y\n"
      "                        and z axes, what a mesh skinned to it sees (file units, or percent\n"
      "                        of the skeleton size). Default 2%. 0: joints and End Sites only.\n"
      "                        Files with position channels below the root are kept within\n"
      "                        --error under both readings of them (replace and add).\n"
      "  --keys MODE           error (default): fewest keys within --error;\n"
      "                        uniform:N every N-th frame (N >= 1); manual:F1,F2,... those frames;\n"
      "                        curvature: curvature feature points. First and last frame always.\n"
      "                        Only error mode applies --error as a tolerance; the others report\n"
      "                        the error reached (and warn when it exceeds a given --error).\n"
      "  --tension T|fit       Cardinal tension in [-1, 1] (0 = Catmull-Rom, default), or 'fit':\n"
      "                        least squares per channel, kept where it saves keys.\n"
      "  --rotations FORM      quaternion (default): each joint with three rotation channels whose\n"
      "                        rotation stays within 145 degrees of one reference is stored as the\n"
      "                        x, y, z curves of its rotation on key frames shared by the three\n"
      "                        (format 5: fewer bytes, poses without trigonometry); euler: every\n"
      "                        rotation as its Euler channels (format 3, which decoders of\n"
      "                        versions 3 and 4 read). Decoded BVH channels are Euler angles either\n"
      "                        way.\n"
      "  --level N             zstd level of every section, 1..22 (19: what keyanim 0.2 wrote).\n"
      "                        Default: each section at the zstd parameters measured for it,\n"
      "                        within 0.3% of -19's bytes for a quarter of its instructions.\n";
  return std::string(with_error ? error : "") + others;
}

// The library's grammar (settings_text.h); its errors are usage errors naming the option.
void parse_tolerance(const std::string& text, offline::EncodeSettings& s, const std::string& option) {
  try {
    offline::parse_tolerance(text, s);
  } catch (const offline::Error& e) {
    fail(kUsage, option + ": " + e.message());
  }
}

void parse_shell(const std::string& text, offline::EncodeSettings& s, const std::string& option) {
  try {
    offline::parse_shell(text, s);
  } catch (const offline::Error& e) {
    fail(kUsage, option + ": " + e.message());
  }
}

void parse_key_mode(const std::string& text, offline::EncodeSettings& s) {
  try {
    offline::parse_key_mode(text, s);
  } catch (const offline::Error& e) {
    fail(kUsage, "--keys: " + e.message());
  }
}

void check_settings_for(const offline::EncodeSettings& s, const offline::Motion& motion, const std::string& path) {
  if (s.key_mode == offline::KeyMode::manual)
    or_fail(kUsage, path + ": --keys manual: ", [&] { return offline::manual_keys(s.manual_frames, motion.frame_count); });
}

offline::EncodeSettings encode_settings(const Args& args, bool read_error, bool read_keys, offline::Rotations rotations) {
  offline::EncodeSettings s;
  if (auto e = args.get("--error"); e && read_error) parse_tolerance(*e, s);
  if (auto d = args.get("--shell")) parse_shell(*d, s);
  if (auto k = args.get("--keys"); k && read_keys) parse_key_mode(*k, s);
  if (auto t = args.get("--tension")) {
    if (*t == "fit") {
      s.fit_tension = true;
    } else {
      s.tension = static_cast<float>(parse_double("--tension", *t));
    }
  }
  s.rotations = rotations;
  if (auto r = args.get("--rotations")) {
    if (*r == "quaternion") s.rotations = offline::Rotations::quaternion;
    else if (*r == "euler") s.rotations = offline::Rotations::euler;
    else fail(kUsage, "--rotations: expected quaternion or euler, got '" + *r + "'");
  }
  if (auto l = args.get("--level")) s.zstd_level = static_cast<int>(parse_uint("--level", *l));
  or_fail(kUsage, "", [&] { s.validate(); });
  return s;
}

}  // namespace keyanim::cli
