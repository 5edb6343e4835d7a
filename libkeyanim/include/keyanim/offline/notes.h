// Reading the encoder notes a clip carries (Clip::encoder_notes): informative key=value lines,
// one per line, such as tolerance_units=, shell_units= (the shell distance the error covers),
// readings= (replace, or replace,add), max_error=, worst_point= and worst_frame=.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace keyanim::offline {

// The value after `key=` on the first line that starts with it, or nullopt.
std::optional<std::string> note(const std::string& notes, std::string_view key);
// The same read as a finite number, or nullopt.
std::optional<double> note_number(const std::string& notes, std::string_view key);
// Every key=value line, in order, the first of a repeated key only (as note() reads them);
// lines without '=' or with an empty key are not notes and are left out.
std::vector<std::pair<std::string, std::string>> note_lines(const std::string& notes);

}  // namespace keyanim::offline
