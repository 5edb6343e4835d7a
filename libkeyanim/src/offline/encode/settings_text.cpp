#include "keyanim/offline/settings_text.h"

#include <charconv>
#include <cmath>
#include <string>
#include <utility>

#include "keyanim/offline/error.h"

namespace keyanim::offline {
namespace {

[[noreturn]] void invalid(const std::string& message) { throw Error(ErrorKind::invalid_argument, message); }

// The whole of `text` as a non-negative integer, or an error naming `what`.
uint32_t whole_uint(std::string_view text, const char* what) {
  uint32_t v = 0;
  const char* end = text.data() + text.size();
  const auto [p, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || p != end)
    invalid(std::string(what) + " expects a non-negative integer, got '" + std::string(text) + "'");
  return v;
}

// "N" or "N%" as a finite number and whether it is a percentage; `what` names it in errors.
std::pair<double, bool> number_or_percent(std::string_view text, const char* what, const char* example) {
  std::string_view number = text;
  const bool percent = !number.empty() && number.back() == '%';
  if (percent) number.remove_suffix(1);
  double v = 0.0;
  const char* end = number.data() + number.size();
  const auto [p, ec] = std::from_chars(number.data(), end, v);
  if (number.empty() || ec != std::errc() || p != end || !std::isfinite(v))
    invalid(std::string(what) + " expects a number (units) or a percentage such as " + example + ", got '" +
            std::string(text) + "'");
  if (percent && v > 100.0)
    invalid(std::string(what) + " in percent must be at most 100, got '" + std::string(text) + "'");
  return {v, percent};
}

}  // namespace

void parse_tolerance(std::string_view text, EncodeSettings& settings) {
  const auto [v, percent] = number_or_percent(text, "the tolerance", "0.05%");
  if (!(v > 0.0)) invalid("the tolerance must be positive, got '" + std::string(text) + "'");
  settings.tolerance = v;
  settings.tolerance_in_percent = percent;
}

void parse_shell(std::string_view text, EncodeSettings& settings) {
  const auto [v, percent] = number_or_percent(text, "the shell distance", "2%");
  if (!(v >= 0.0)) invalid("the shell distance must be 0 or more, got '" + std::string(text) + "'");
  settings.shell = v;
  settings.shell_in_percent = percent && v > 0.0;  // "0" and "0%" alike
}

void parse_key_mode(std::string_view text, EncodeSettings& settings) {
  const size_t colon = text.find(':');
  const std::string_view mode = text.substr(0, colon);
  const std::string_view arg = colon == std::string_view::npos ? std::string_view() : text.substr(colon + 1);
  if (mode == "error" && colon == std::string_view::npos) {
    settings.key_mode = KeyMode::error;
  } else if (mode == "curvature" && colon == std::string_view::npos) {
    settings.key_mode = KeyMode::curvature;
  } else if (mode == "uniform" && !arg.empty()) {
    settings.key_mode = KeyMode::uniform;
    settings.uniform_interval = whole_uint(arg, "uniform:N");
    if (settings.uniform_interval < 1) invalid("uniform:N needs N >= 1");
  } else if (mode == "manual" && !arg.empty()) {
    settings.key_mode = KeyMode::manual;
    settings.manual_frames.clear();
    for (size_t start = 0; start <= arg.size();) {
      const size_t comma = std::min(arg.find(',', start), arg.size());
      settings.manual_frames.push_back(whole_uint(arg.substr(start, comma - start), "manual:F1,F2,..."));
      start = comma + 1;
    }
  } else {
    invalid("expected error, uniform:N, manual:F1,F2,... or curvature, got '" + std::string(text) + "'");
  }
}

}  // namespace keyanim::offline
