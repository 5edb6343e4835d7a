#include "offline/notes.h"

#include <sstream>

#include "keyanim/version.h"

namespace keyanim::offline {

std::string encoder_notes(const EncodeSettings& s, double tol_units, const ErrorReport& e, uint32_t rounds) {
  std::ostringstream o;
  static const char* kModes[] = {"error", "uniform", "manual", "curvature"};
  o << "encoder=keyanim " << KEYANIM_VERSION_STRING << "\n"
    << "keys=" << kModes[int(s.key_mode)] << "\n"
    << "tolerance=" << s.tolerance << (s.tolerance_in_percent ? "%" : "") << "\n"
    << "tolerance_units=" << tol_units << "\n"
    << "tension=" << (s.fit_tension ? std::string("fit") : std::to_string(s.tension)) << "\n"
    << "tangent_rule=" << (s.tangent_rule == TangentRule::step_adjusted ? "step_adjusted" : "uniform") << "\n"
    << "max_error=" << e.max_error << "\n"
    << "rms_error=" << e.rms_error << "\n"
    << "rounds=" << rounds << "\n";
  return o.str();
}

}  // namespace keyanim::offline
