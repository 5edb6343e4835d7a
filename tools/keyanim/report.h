// JSON and one-line text renderings of what the library measured, shared by the commands.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "keyanim/offline/encode.h"
#include "keyanim/skeleton.h"

namespace keyanim::cli {

// Display name of a node: its name, or "End Site of PARENT".
std::string node_name(const Skeleton& s, uint32_t node);
// "replace" or "add".
const char* reading_name(PositionReading r);
// max, rms, worst_joint (the node), worst_point (the node, or "NODE shell x|y|z"),
// worst_shell_axis (x, y, z or null), worst_frame, shell (distance, file units), readings, and
// worst_reading when both readings were measured.
nlohmann::json error_json(const Skeleton& s, const offline::ErrorReport& e);
// "max 0.081 (LeftHand shell y, frame 713), rms 0.012"
std::string error_text(const Skeleton& s, const offline::ErrorReport& e);

// Empty, or a warning when --error was given with a key mode that does not apply it (uniform,
// manual, curvature) and the error reached exceeds it.
std::string tolerance_warning(const offline::EncodeSettings& s, double tolerance_units, double max_error);

}  // namespace keyanim::cli
