// Reading the encoder notes a clip carries (Clip::encoder_notes): informative key=value lines,
// one per line, such as tolerance_units=, shell_units= (the shell distance the error covers),
// readings= (replace, or replace,add), max_error=, worst_point= and worst_frame=.
#pragma once
#include <optional>
#include <string>
#include <string_view>

namespace keyanim::offline {

// The value after `key=` on the first line that starts with it, or nullopt.
std::optional<std::string> note(const std::string& notes, std::string_view key);
// The same read as a finite number, or nullopt.
std::optional<double> note_number(const std::string& notes, std::string_view key);

}  // namespace keyanim::offline
