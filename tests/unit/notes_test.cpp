// The notes an encoder stores: every key=value line, in order, with the settings and the error.
#include <doctest/doctest.h>

#include <clocale>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "keyanim/offline/number_text.h"
#include "keyanim/version.h"
#include "offline/encode/notes.h"

using namespace keyanim::offline;

TEST_CASE("encoder notes list the settings, the error reached and where") {
  keyanim::Skeleton sk;
  sk.joints = {{"Hips", -1, {0, 0, 0}, {keyanim::ChannelType::z_rotation}}, {"", 0, {0, 1, 0}, {}, true}};
  EncodeSettings s;
  s.tolerance = 0.5;
  ErrorReport e;
  e.max_error = 0.125;
  e.rms_error = 0.0625;
  e.shell = 0.75;
  e.worst_joint = 0;
  e.worst_point = 2;
  e.worst_frame = 9;
  const std::string want = std::string("encoder=keyanim ") + KEYANIM_VERSION_STRING +
                           "\nkeys=error\ntolerance=0.5%\ntolerance_units=0.25\nshell=2%\nshell_units=0.75\n"
                           "readings=replace\ntension=0.000000\ntangent_rule=step_adjusted\nmax_error=0.125\n"
                           "rms_error=0.0625\nworst_point=Hips shell y\nworst_frame=9\nrounds=7\n";
  CHECK(encoder_notes(s, 0.25, sk, e, 7) == want);
  s.key_mode = KeyMode::curvature;
  s.tolerance_in_percent = false;
  s.fit_tension = true;
  s.tangent_rule = keyanim::TangentRule::uniform;
  s.shell = 0.0;
  s.shell_in_percent = false;
  e.both_readings = true;
  e.worst_reading = keyanim::PositionReading::add;
  e.worst_joint = 1;
  e.worst_point = 0;
  const std::string notes = encoder_notes(s, 0.5, sk, e, 1);
  CHECK(notes.find("keys=curvature\ntolerance=0.5\n") != std::string::npos);
  CHECK(notes.find("shell=0\n") != std::string::npos);
  CHECK(notes.find("readings=replace,add\n") != std::string::npos);
  CHECK(notes.find("tension=fit\ntangent_rule=uniform\n") != std::string::npos);
  CHECK(notes.find("worst_point=End Site of Hips\nworst_frame=9\nworst_reading=add\n") != std::string::npos);
}

TEST_CASE("notes read back: a key's value, a number, nothing for a missing or malformed one") {
  const std::string notes = "a=1\nshell_units=0.5\nname=End Site of X\nbad=1.5x\nempty=\nshell_units=9\n";
  CHECK(note(notes, "name") == "End Site of X");
  CHECK(note(notes, "empty") == "");
  CHECK_FALSE(note(notes, "shell").has_value());  // a key is the whole text before '='
  CHECK(note_number(notes, "shell_units") == 0.5);  // the first line with the key
  CHECK_FALSE(note_number(notes, "bad").has_value());
  CHECK_FALSE(note_number(notes, "missing").has_value());
  CHECK_FALSE(note_number("x=nan\n", "x").has_value());
  CHECK(note_number("x=2", "x") == 2.0);  // no final newline
}

// The notes' numbers as printf writes them in the "C" locale (the text earlier versions wrote),
// compared with printf itself while the process's locale is "C".
TEST_CASE("number_text: printf's %f and %g of the C locale, without printf") {
  REQUIRE(std::setlocale(LC_NUMERIC, nullptr) == std::string("C"));
  const double values[] = {0.0, -0.0, 0.5, -0.25, 1.0 / 3.0, 1e-30, 123456789.0, 1e300, -1e-320, 0.0049999999,
                           HUGE_VAL, -HUGE_VAL, std::nan("")};
  char want[400];
  for (double v : values) {
    CAPTURE(v);
    for (int d : {0, 3, 6, 12}) {
      std::snprintf(want, sizeof want, "%.*f", d, v);
      CHECK(fixed_text(v, d) == want);
    }
    for (int d : {1, 3, 6, 9, 17}) {
      std::snprintf(want, sizeof want, "%.*g", d, v);
      CHECK(general_text(v, d) == want);
    }
    std::snprintf(want, sizeof want, "%.17g", v);
    if (std::isfinite(v)) CHECK(std::strtod(shortest_text(v).c_str(), nullptr) == std::strtod(want, nullptr));
  }
}

// Under a comma-decimal locale (when the machine has one: python/tests/test_hostile.py compiles
// one for itself) the notes keep their points.
TEST_CASE("encoder notes do not follow the process's locale") {
  keyanim::Skeleton sk;
  sk.joints = {{"Hips", -1, {0, 0, 0}, {keyanim::ChannelType::z_rotation}}, {"", 0, {0, 1, 0}, {}, true}};
  EncodeSettings s;
  s.tolerance = 0.5;
  s.tension = 0.5f;
  ErrorReport e;
  e.max_error = 0.125;
  const std::string in_c = encoder_notes(s, 0.25, sk, e, 1);
  CHECK(in_c.find("tension=0.500000\n") != std::string::npos);
  const char* comma = nullptr;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "nl_NL.UTF-8"})
    if (std::setlocale(LC_ALL, name) != nullptr && *std::localeconv()->decimal_point == ',') {
      comma = name;
      break;
    }
  const std::string in_comma = encoder_notes(s, 0.25, sk, e, 1);
  std::setlocale(LC_ALL, "C");
  if (comma == nullptr) {
    MESSAGE("no comma-decimal locale installed: checked by python/tests/test_hostile.py instead");
    return;
  }
  CHECK(in_comma == in_c);
}
