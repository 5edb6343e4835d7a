#include "escape.h"

#include <cstdio>

#include "utf8.h"

namespace keyanim::cli {
namespace {

void hex(std::string& out, const char* format, unsigned value) {
  char buf[16];
  std::snprintf(buf, sizeof buf, format, value);
  out += buf;
}

// Code points shown escaped in human-readable text: C0 and C1 controls, DEL, the Unicode
// bidirectional embeddings, overrides and isolates, the line/paragraph separators, and the two
// noncharacters XML does not allow.
bool hidden(int32_t cp) {
  return cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || (cp >= 0x202A && cp <= 0x202E) ||
         (cp >= 0x2066 && cp <= 0x2069) || cp == 0x200E || cp == 0x200F || cp == 0x2028 || cp == 0x2029 ||
         cp == 0xFFFE || cp == 0xFFFF;
}

void json_string(std::string& out, std::string_view s) {
  out += '"';
  for (size_t i = 0; i < s.size();) {
    const utf8::CodePoint cp = utf8::decode(s, i);
    if (cp.value < 0) hex(out, "\\udc%02x", uint8_t(s[i]));
    else if (cp.value == '"') out += "\\\"";
    else if (cp.value == '\\') out += "\\\\";
    else if (cp.value == '\b') out += "\\b";
    else if (cp.value == '\f') out += "\\f";
    else if (cp.value == '\n') out += "\\n";
    else if (cp.value == '\r') out += "\\r";
    else if (cp.value == '\t') out += "\\t";
    else if (cp.value < 0x20) hex(out, "\\u%04x", unsigned(cp.value));
    else out.append(s.substr(i, cp.length));
    i += cp.length;
  }
  out += '"';
}

void json_value(std::string& out, const nlohmann::json& j) {
  if (j.is_string()) {
    json_string(out, j.get_ref<const std::string&>());
  } else if (j.is_array()) {
    out += '[';
    for (size_t k = 0; k < j.size(); ++k) {
      if (k) out += ',';
      json_value(out, j[k]);
    }
    out += ']';
  } else if (j.is_object()) {
    out += '{';
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it, first = false) {
      if (!first) out += ',';
      json_string(out, it.key());
      out += ':';
      json_value(out, it.value());
    }
    out += '}';
  } else {
    out += j.dump();  // numbers, booleans, null: nothing from an input can break these
  }
}

}  // namespace

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const utf8::CodePoint cp = utf8::decode(text, i);
    if (cp.value < 0 || (cp.value < 0x80 && hidden(cp.value))) hex(out, "\\x%02x", uint8_t(text[i]));
    else if (hidden(cp.value)) hex(out, "\\u%04x", unsigned(cp.value));
    else out.append(text.substr(i, cp.length));
    i += cp.length;
  }
  return out;
}

std::string json_text(const nlohmann::json& j) {
  std::string out;
  json_value(out, j);
  return out;
}

std::string count_of(uint64_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

}  // namespace keyanim::cli
