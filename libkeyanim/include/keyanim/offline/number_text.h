// Numbers as text, the same under every locale. printf's %f and %g, std::to_string(double) and
// a stream's operator<< follow the process's locale: after Python's
// locale.setlocale(LC_ALL, "de_DE.UTF-8") "%f" writes 0,500000, which put "tension=0,500000"
// into a .kanim's notes. std::to_chars is specified as printf in the "C" locale, whatever the
// process's locale, so every number the library, its Python module and its tools write as text
// goes through these three (and none through printf).
#pragma once
#include <algorithm>
#include <charconv>
#include <string>

namespace keyanim::offline {

namespace number_text_detail {
// The longest %.*f of a double with up to 40 decimals: sign, 309 digits, point, 40 decimals.
constexpr int kMaxDecimals = 40;
constexpr size_t kBufferSize = 1 + 309 + 1 + kMaxDecimals + 8;
}  // namespace number_text_detail

// As printf("%.*f", decimals, v) in the "C" locale; decimals is clamped to 0..40.
inline std::string fixed_text(double v, int decimals) {
  char buf[number_text_detail::kBufferSize];
  const int d = std::clamp(decimals, 0, number_text_detail::kMaxDecimals);
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, d).ptr);
}

// As printf("%.*g", digits, v) in the "C" locale (digits 6 is what a stream writes by default);
// digits is clamped to 1..17.
inline std::string general_text(double v, int digits = 6) {
  char buf[40];
  const int d = std::clamp(digits, 1, 17);
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, d).ptr);
}

// The shortest text that reads back (std::from_chars, strtod in the "C" locale) as the same double.
inline std::string shortest_text(double v) {
  char buf[40];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

}  // namespace keyanim::offline
