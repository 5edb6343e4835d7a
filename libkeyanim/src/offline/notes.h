// The encoder's notes stored in the file: informative key=value lines (settings, the error
// reached). Internal to the encoder.
#pragma once
#include <cstdint>
#include <string>

#include "keyanim/offline/encode.h"

namespace keyanim::offline {

// encoder, keys, tolerance, tolerance_units, tension, tangent_rule, max_error, rms_error, rounds.
std::string encoder_notes(const EncodeSettings& settings, double tolerance_units, const ErrorReport& error,
                          uint32_t rounds);

}  // namespace keyanim::offline
