#include "offline/encode/notes.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "keyanim/offline/number_text.h"
#include "keyanim/version.h"

namespace keyanim::offline {

std::string encoder_notes(const EncodeSettings& s, double tol_units, const Skeleton& skeleton, const ErrorReport& e,
                          uint32_t rounds) {
  // The same text as the stream and std::to_string of earlier versions wrote in the "C" locale
  // (%g, and %f for the tension), in any locale: the bytes of a .kanim do not depend on it.
  static const char* kModes[] = {"error", "uniform", "manual", "curvature"};
  const char* reading = e.worst_reading == PositionReading::add ? "add" : "replace";
  std::string o;
  auto line = [&o](const char* key, const std::string& value) { o.append(key).append("=").append(value).append("\n"); };
  line("encoder", std::string("keyanim ") + KEYANIM_VERSION_STRING);
  line("keys", kModes[int(s.key_mode)]);
  line("tolerance", general_text(s.tolerance) + (s.tolerance_in_percent ? "%" : ""));
  line("tolerance_units", general_text(tol_units));
  line("shell", general_text(s.shell) + (s.shell_in_percent ? "%" : ""));
  line("shell_units", shortest_text(e.shell));  // read back to measure as the encoder did
  line("readings", e.both_readings ? "replace,add" : "replace");
  line("tension", s.fit_tension ? std::string("fit") : fixed_text(s.tension, 6));
  line("tangent_rule", s.tangent_rule == TangentRule::step_adjusted ? "step_adjusted" : "uniform");
  line("max_error", general_text(e.max_error));
  line("rms_error", general_text(e.rms_error));
  line("worst_point", point_name(skeleton, e.worst_joint, e.worst_point));
  line("worst_frame", std::to_string(e.worst_frame));
  if (e.both_readings) line("worst_reading", reading);
  line("rounds", std::to_string(rounds));
  return o;
}

std::optional<std::string> note(const std::string& notes, std::string_view key) {
  size_t at = 0;
  while (at < notes.size()) {
    const size_t end = std::min(notes.find('\n', at), notes.size());
    const std::string_view line(notes.data() + at, end - at);
    if (line.size() > key.size() && line.substr(0, key.size()) == key && line[key.size()] == '=')
      return std::string(line.substr(key.size() + 1));
    at = end + 1;
  }
  return std::nullopt;
}

std::optional<double> note_number(const std::string& notes, std::string_view key) {
  const std::optional<std::string> text = note(notes, key);
  if (!text) return std::nullopt;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text->data(), text->data() + text->size(), v);
  if (ec != std::errc() || end != text->data() + text->size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::vector<std::pair<std::string, std::string>> note_lines(const std::string& notes) {
  std::vector<std::pair<std::string, std::string>> out;
  for (size_t at = 0; at < notes.size();) {
    const size_t end = std::min(notes.find('\n', at), notes.size());
    const std::string_view line(notes.data() + at, end - at);
    at = end + 1;
    const size_t eq = line.find('=');
    if (eq == std::string_view::npos || eq == 0) continue;
    std::string key(line.substr(0, eq));
    if (std::none_of(out.begin(), out.end(), [&](const auto& kv) { return kv.first == key; }))
      out.emplace_back(std::move(key), std::string(line.substr(eq + 1)));
  }
  return out;
}

}  // namespace keyanim::offline
