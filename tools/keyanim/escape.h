// Text from inputs (joint names, file names, encoder notes: BVH allows any bytes) made safe for
// where it goes: a terminal or log, and JSON. (SVG: svg::escape, built on printable().)
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace keyanim::cli {

// For a terminal or a log: valid UTF-8 stays as it is, except control characters (C0, DEL, C1)
// and bidirectional-text controls; those, and every byte that is not part of valid UTF-8, are
// written as \xHH (a byte) or \uHHHH (a code point). Nothing an input holds can move the
// cursor, change colours or reorder what is shown.
std::string printable(std::string_view text);

// `j` as JSON text, like j.dump(), except that a string which is not valid UTF-8 (nlohmann's
// dump throws on those) is kept losslessly: each byte that is not part of a valid UTF-8
// sequence is written as \udcHH, HH being the byte (PEP 383's "surrogateescape"; Python gets
// the bytes back with s.encode("utf-8", "surrogateescape")). Strings that are valid UTF-8 are
// written exactly as dump() writes them.
std::string json_text(const nlohmann::json& j);

// "1 frame", "2 frames": n and the word, plural unless n is 1 ("key" -> "keys").
std::string count_of(uint64_t n, const std::string& word);

}  // namespace keyanim::cli
