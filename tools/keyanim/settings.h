// Encoder options shared by `encode`, `eval`, `pack`, `render` and `plot`: --error, --shell,
// --keys, --tension, --rotations, --level.
#pragma once
#include <string>

#include "cli.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/motion.h"

namespace keyanim::cli {

// Options that take a value, to declare in Args.
inline const char* const kEncodeValuedOptions[] = {"--error", "--shell", "--keys", "--tension", "--rotations", "--level"};

// Reads the options (with their documented defaults) and validates them: usage error if wrong.
// read_error = false leaves --error to the caller (eval takes a list), read_keys = false
// --keys (eval takes several modes).
// `rotations`: the default of --rotations (plot's is euler: it draws a channel's own keys).
offline::EncodeSettings encode_settings(const Args& args, bool read_error = true, bool read_keys = true,
                                        offline::Rotations rotations = offline::Rotations::quaternion);
// "0.05%" or "0.1" -> settings.tolerance / tolerance_in_percent; usage error if malformed.
void parse_tolerance(const std::string& text, offline::EncodeSettings& s, const std::string& option = "--error");
// "2%" or "3" or "0" -> settings.shell / shell_in_percent; usage error if malformed or negative.
void parse_shell(const std::string& text, offline::EncodeSettings& s, const std::string& option = "--shell");
// "error", "uniform:N", "manual:F1,F2,...", "curvature".
void parse_key_mode(const std::string& text, offline::EncodeSettings& s);

// Usage error (exit 1) when `s` asks for what `motion` (read from `path`) does not have: a
// --keys manual frame past its last frame. Checked before encoding.
void check_settings_for(const offline::EncodeSettings& s, const offline::Motion& motion, const std::string& path);

// The help lines for these options (defaults and ranges); without --error for a command that
// describes its own (eval takes a list).
std::string encoder_options_help(bool with_error);

}  // namespace keyanim::cli
