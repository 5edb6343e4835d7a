// Encoder settings written as text, one grammar for every front end (the keyanim tool's
// --error, --shell and --keys, the Python module's encode(error=..., shell=..., keys=...)).
#pragma once
#include <string_view>

#include "keyanim/offline/encode.h"

namespace keyanim::offline {

// "0.05%" (percent of the skeleton size) or "0.1" (file length units) -> settings.tolerance
// and tolerance_in_percent. Throws Error (invalid_argument) unless a positive finite number
// (at most 100 in percent).
void parse_tolerance(std::string_view text, EncodeSettings& settings);

// "2%" (percent of the skeleton size) or "3" (file length units) or "0" (no shell points) ->
// settings.shell and shell_in_percent ("0%" is "0"). Throws Error (invalid_argument) unless a
// finite number, 0 or more (at most 100 in percent).
void parse_shell(std::string_view text, EncodeSettings& settings);

// "error", "uniform:N" (N >= 1), "manual:F1,F2,..." or "curvature" -> settings.key_mode and
// uniform_interval or manual_frames. Throws Error (invalid_argument) otherwise. (Manual frames
// are checked against a motion by encode.)
void parse_key_mode(std::string_view text, EncodeSettings& settings);

}  // namespace keyanim::offline
