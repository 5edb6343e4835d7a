// The encoder's notes stored in the file: informative key=value lines (settings, the error
// reached and where). Internal to the encoder; reading them back: keyanim/offline/notes.h.
#pragma once
#include <cstdint>
#include <string>

#include "keyanim/offline/encode.h"
#include "keyanim/offline/notes.h"

namespace keyanim::offline {

// encoder, keys, tolerance, tolerance_units, shell, shell_units, readings, tension,
// tangent_rule, max_error, rms_error, worst_point, worst_frame (and worst_reading when both
// readings were measured), rounds.
std::string encoder_notes(const EncodeSettings& settings, double tolerance_units, const Skeleton& skeleton,
                          const ErrorReport& error, uint32_t rounds);

}  // namespace keyanim::offline
