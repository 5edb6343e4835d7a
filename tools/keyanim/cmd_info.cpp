// keyanim info: what a BVH or .kanim file holds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <set>
#include <sstream>

#include "commands.h"
#include "escape.h"
#include "io.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/notes.h"
#include "keyanim/version.h"
#include "report.h"

namespace keyanim::cli {

const char* const kInfoHelp =
    "usage: keyanim info IN.bvh|IN.kanim [--json]\n"
    "Describes a BVH or .kanim file (recognised by its first bytes): skeleton, frames, frame time,\n"
    "channels, skeleton size; for .kanim also version, keys per channel, tensions, encoder notes\n"
    "and, from them, what the encoder guaranteed: the tolerance, the shell distance, the readings\n"
    "of position channels, the error reached and its worst point and frame.\n"
    "  --json                one JSON object on standard output\n";

namespace {

// Skeleton facts common to both kinds of file.
nlohmann::json skeleton_json(const Skeleton& s) {
  uint32_t joints = 0, end_sites = 0, roots = 0;
  std::set<std::string> orders;
  for (const Joint& j : s.joints) {
    (j.end_site ? end_sites : joints) += 1;
    roots += j.parent < 0;
    std::string order;
    for (ChannelType t : j.channels)
      if (is_rotation(t)) order += char('X' + channel_axis(t));
    if (!order.empty()) orders.insert(order);
  }
  return {{"joints", joints},
          {"end_sites", end_sites},
          {"roots", roots},
          {"channels", s.channel_count()},
          {"size", offline::skeleton_size(s)},
          {"rotation_orders", std::vector<std::string>(orders.begin(), orders.end())}};
}

std::string number(double v, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, v);
  return text;
}

// The encoder's notes as an indented block, a line each (none for an empty line).
void print_notes(const std::string& notes) {
  std::cout << "encoder_notes:" << (notes.find_first_not_of('\n') == std::string::npos ? " (none)" : "") << "\n";
  std::istringstream lines(notes);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) std::cout << "  " << printable(line) << "\n";
}

// What the encoder notes say was guaranteed (empty for a file without such notes).
nlohmann::json guarantee_json(const std::string& notes) {
  nlohmann::json j = nlohmann::json::object();
  for (const char* key : {"tolerance_units", "shell_units", "max_error"})
    if (auto v = offline::note_number(notes, key)) j[key] = *v;
  if (auto r = offline::note(notes, "readings")) {
    j["readings"] = nlohmann::json::array();
    for (size_t at = 0; at <= r->size();) {
      const size_t comma = std::min(r->find(',', at), r->size());
      j["readings"].push_back(r->substr(at, comma - at));
      at = comma + 1;
    }
  }
  for (const char* key : {"worst_point", "worst_reading"})
    if (auto v = offline::note(notes, key)) j[key] = *v;
  if (auto v = offline::note_number(notes, "worst_frame"); v && *v >= 0.0 && *v <= 4294967295.0 && *v == std::floor(*v))
    j["worst_frame"] = uint32_t(*v);  // notes come from the file: only a frame number is taken as one
  return j;
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
  nlohmann::json j;
  if (!looks_like_kanim(bytes)) {
    const offline::Motion m = load_bvh_bytes(in, bytes, g);
    j = {{"file", in}, {"format", "bvh"}, {"bytes", bytes.size()}};
    j.update(skeleton_json(m.skeleton));
    j["frames"] = m.frame_count;
    j["frame_time"] = m.frame_time;
  } else {
    const Clip clip = load_kanim(in, bytes, g);
    j = {{"file", in},
         {"format", "kanim"},
         {"version", std::to_string(clip.version_major()) + "." + std::to_string(clip.version_minor())},
         {"bytes", bytes.size()},
         {"checksum", "ok"}};
    j.update(skeleton_json(clip.skeleton()));
    j["frames"] = clip.frame_count();
    j["frame_time"] = clip.frame_time();
    j["tangent_rule"] = clip.tangent_rule() == TangentRule::step_adjusted ? "step_adjusted" : "uniform";
    std::vector<uint32_t> keys;
    uint32_t zero = 0, constant = 0, linear = 0;
    float t_min = 1.0f, t_max = -1.0f;
    double t_sum = 0.0;
    uint32_t curved = 0;
    for (uint32_t c = 0; c < clip.channel_count(); ++c) {
      const ChannelInfo t = clip.channel(c);
      keys.push_back(t.key_count);
      zero += t.key_count == 0;
      constant += t.key_count == 1;
      if (t.key_count < 2) continue;
      if (t.interp == Interpolation::linear) { ++linear; continue; }
      const float tension = t.tension;
      t_min = std::min(t_min, tension), t_max = std::max(t_max, tension), t_sum += tension, ++curved;
    }
    std::sort(keys.begin(), keys.end());
    j["keys"] = {{"total", clip.total_keys()},
                 {"per_channel_min", keys.empty() ? 0 : keys.front()},
                 {"per_channel_median", keys.empty() ? 0 : keys[keys.size() / 2]},
                 {"per_channel_max", keys.empty() ? 0 : keys.back()},
                 {"zero_channels", zero},
                 {"constant_channels", constant},
                 {"linear_channels", linear},
                 {"cardinal_channels", curved}};
    if (curved) j["tension"] = {{"min", t_min}, {"mean", t_sum / curved}, {"max", t_max}};
    j["raw_f32_bytes"] = uint64_t(4) * clip.frame_count() * clip.channel_count();
    j["memory_bytes"] = clip.memory_bytes();
    j["encoder_notes"] = clip.encoder_notes();
    if (nlohmann::json noted = guarantee_json(clip.encoder_notes()); !noted.empty()) j["guarantee"] = noted;
  }
  if (args.has("--json")) std::cout << json_text(j) << "\n"; else print_text(j);
  return kOk;
}

}  // namespace keyanim::cli
