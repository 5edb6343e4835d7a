#include "offline/encode/notes.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "keyanim/version.h"

namespace keyanim::offline {

namespace {

// The shortest text that reads back as the same double.
std::string round_trip(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, end) : std::to_string(v);
}

}  // namespace

std::string encoder_notes(const EncodeSettings& s, double tol_units, const Skeleton& skeleton, const ErrorReport& e,
                          uint32_t rounds) {
  std::ostringstream o;
  static const char* kModes[] = {"error", "uniform", "manual", "curvature"};
  const char* reading = e.worst_reading == PositionReading::add ? "add" : "replace";
  o << "encoder=keyanim " << KEYANIM_VERSION_STRING << "\n"
    << "keys=" << kModes[int(s.key_mode)] << "\n"
    << "tolerance=" << s.tolerance << (s.tolerance_in_percent ? "%" : "") << "\n"
    << "tolerance_units=" << tol_units << "\n"
    << "shell=" << s.shell << (s.shell_in_percent ? "%" : "") << "\n"
    << "shell_units=" << round_trip(e.shell) << "\n"  // read back to measure as the encoder did
    << "readings=" << (e.both_readings ? "replace,add" : "replace") << "\n"
    << "tension=" << (s.fit_tension ? std::string("fit") : std::to_string(s.tension)) << "\n"
    << "tangent_rule=" << (s.tangent_rule == TangentRule::step_adjusted ? "step_adjusted" : "uniform") << "\n"
    << "max_error=" << e.max_error << "\n"
    << "rms_error=" << e.rms_error << "\n"
    << "worst_point=" << point_name(skeleton, e.worst_joint, e.worst_point) << "\n"
    << "worst_frame=" << e.worst_frame << "\n";
  if (e.both_readings) o << "worst_reading=" << reading << "\n";
  o << "rounds=" << rounds << "\n";
  return o.str();
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
