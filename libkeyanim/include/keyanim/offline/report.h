// JSON and one-line text renderings of what the library measured, shared by the commands and
// the Python module (python/: its encode report and Clip.info are these very objects).
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "keyanim/clip.h"
#include "keyanim/offline/encode.h"
#include "keyanim/skeleton.h"

namespace keyanim::offline {

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

// What `keyanim encode --json` prints for one input: sizes, keys, the error reached and the
// tolerance (error mode) or error_limit and error_limit_met (the other key modes).
nlohmann::json encode_summary(const std::string& input, const std::string& output, const offline::Motion& motion,
                              uint64_t bvh_bytes, const offline::EncodeSettings& settings,
                              const offline::EncodeResult& result, uint64_t kanim_bytes, double encode_ms);

// What `keyanim info --json` prints for a BVH file and for a .kanim file of `bytes` bytes.
nlohmann::json bvh_info(const std::string& file, uint64_t bytes, const offline::Motion& motion);
nlohmann::json kanim_info(const std::string& file, uint64_t bytes, const Clip& clip);

}  // namespace keyanim::offline
