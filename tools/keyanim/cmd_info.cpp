// keyanim info: what a BVH or .kanim file holds.
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "escape.h"
#include "io.h"
#include "keyanim/offline/report.h"
#include "keyanim/offline/number_text.h"

namespace keyanim::cli {

const char* const kInfoHelp =
    "usage: keyanim info IN.bvh|IN.kanim [--json]\n"
    "Describes a BVH or .kanim file (recognised by its first bytes): skeleton, frames, frame time,\n"
    "channels, skeleton size; for .kanim also version, keys per channel, tensions, encoder notes\n"
    "and, from them, what the encoder guaranteed: the tolerance, the shell distance, the readings\n"
    "of position channels, the error reached and its worst point and frame.\n"
    "  --json                one JSON object on standard output\n";

namespace {

std::string number(double v, int digits) {
  return offline::general_text(v, digits);
}

// The encoder's notes as an indented block, a line each (none for an empty line).
void print_notes(const std::string& notes) {
  std::cout << "encoder_notes:" << (notes.find_first_not_of('\n') == std::string::npos ? " (none)" : "") << "\n";
  std::istringstream lines(notes);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) std::cout << "  " << printable(line) << "\n";
}

// Names and notes come from the file: printable() keeps their bytes from acting on a terminal.
// Quantities with a unit say it.
void print_text(const nlohmann::json& j) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key() == "encoder_notes") {
      print_notes(it->get<std::string>());
    } else if (it.key() == "size") {
      std::cout << "size: " << number(it->get<double>(), 4)
                << " units (the file's length units; largest side of the rest pose's bounding box)\n";
    } else if (it.key() == "frame_time") {
      const double t = it->get<double>();
      std::cout << "frame_time: " << json_text(*it) << " s" << (t > 0 ? " (" + number(1.0 / t, 6) + " fps)" : "") << "\n";
    } else if (it->is_object()) {
      std::cout << it.key() << ":\n";
      for (auto sub = it->begin(); sub != it->end(); ++sub)
        std::cout << "  " << sub.key() << ": " << printable(json_text(*sub)) << "\n";
    } else {
      std::cout << it.key() << ": " << printable(it->is_string() ? it->get<std::string>() : json_text(*it)) << "\n";
    }
  }
}

}  // namespace

int cmd_info(const Argv& argv, Globals& g) {
  const Args args(argv, {}, {"--json"});
  if (args.positional().size() != 1) fail(kUsage, "info takes one file");
  const std::string in = args.positional()[0];
  const std::vector<uint8_t> bytes = read_input(in, Kind::either, g);
  const nlohmann::json j = looks_like_kanim(bytes) ? offline::kanim_info(in, bytes.size(), load_kanim(in, bytes, g))
                                                  : offline::bvh_info(in, bytes.size(), load_bvh_bytes(in, bytes, g));
  if (args.has("--json")) std::cout << json_text(j) << "\n"; else print_text(j);
  return kOk;
}

}  // namespace keyanim::cli
