// The notes an encoder stores: every key=value line, in order, with the settings and the error.
#include <doctest/doctest.h>

#include "keyanim/version.h"
#include "offline/notes.h"

using namespace keyanim::offline;

TEST_CASE("encoder notes list the settings and the error reached") {
  EncodeSettings s;
  s.tolerance = 0.5;
  ErrorReport e;
  e.max_error = 0.125;
  e.rms_error = 0.0625;
  const std::string want = std::string("encoder=keyanim ") + KEYANIM_VERSION_STRING +
                           "\nkeys=error\ntolerance=0.5%\ntolerance_units=0.25\ntension=0.000000\n"
                           "tangent_rule=step_adjusted\nmax_error=0.125\nrms_error=0.0625\nrounds=7\n";
  CHECK(encoder_notes(s, 0.25, e, 7) == want);
  s.key_mode = KeyMode::curvature;
  s.tolerance_in_percent = false;
  s.fit_tension = true;
  s.tangent_rule = keyanim::TangentRule::uniform;
  const std::string notes = encoder_notes(s, 0.5, e, 1);
  CHECK(notes.find("keys=curvature\ntolerance=0.5\n") != std::string::npos);
  CHECK(notes.find("tension=fit\ntangent_rule=uniform\n") != std::string::npos);
}
