// The notes an encoder stores: every key=value line, in order, with the settings and the error.
#include <doctest/doctest.h>

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
