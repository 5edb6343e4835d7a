// BVH reader: a hand-written scanner over the whole text. The header is small and parsed token by
// token; the motion section is the hot loop (pointer scanning + std::from_chars, no allocation per
// value). Every error carries the 1-based line and byte column of the offending token.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <cerrno>
#include <string>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "keyanim/offline/bvh.h"

namespace keyanim::offline {

namespace {

// Where and why parsing stopped; read_bvh throws it as an Error.
struct BvhError {
  uint32_t line = 0, column = 0;
  std::string message;
  ErrorKind kind = ErrorKind::malformed;
};

// Character classes. Blank: separates tokens within a line. Eol: ends a line (\n, \r, \r\n).
constexpr uint8_t kOther = 0;
constexpr uint8_t kBlank = 1;
constexpr uint8_t kEol = 2;

constexpr std::array<uint8_t, 256> make_class_table() {
  std::array<uint8_t, 256> t{};
  t[uint8_t(' ')] = kBlank;
  t[uint8_t('\t')] = kBlank;
  t[uint8_t('\v')] = kBlank;
  t[uint8_t('\f')] = kBlank;
  t[uint8_t('\n')] = kEol;
  t[uint8_t('\r')] = kEol;
  return t;
}
constexpr std::array<uint8_t, 256> kClass = make_class_table();

inline bool is_blank(char c) noexcept { return kClass[uint8_t(c)] == kBlank; }
inline bool is_eol(char c) noexcept { return kClass[uint8_t(c)] == kEol; }
inline bool is_space(char c) noexcept { return kClass[uint8_t(c)] != kOther; }
inline bool is_brace(char c) noexcept { return c == '{' || c == '}'; }
inline bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }
inline bool is_alpha(char c) noexcept { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
inline char lower(char c) noexcept { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; }

bool iequals(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

// Which way a from_chars range error went, judged from the decimal exponent of the leading
// significant digit: positive means overflow (an error), otherwise underflow (rounds to zero).
bool range_error_is_overflow(std::string_view tok) noexcept {
  size_t i = 0;
  if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) ++i;
  bool seen = false;
  int64_t int_digits = 0, frac_zeros = 0, exp = 0;
  for (; i < tok.size() && is_digit(tok[i]); ++i)
    if (seen || tok[i] != '0') { seen = true; ++int_digits; }
  if (i < tok.size() && tok[i] == '.') {
    for (++i; i < tok.size() && is_digit(tok[i]); ++i)
      if (!seen) {
        if (tok[i] == '0') ++frac_zeros; else seen = true;
      }
  }
  if (i < tok.size() && (tok[i] == 'e' || tok[i] == 'E')) {
    ++i;
    bool neg = false;
    if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) neg = tok[i++] == '-';
    for (; i < tok.size() && is_digit(tok[i]); ++i)
      if (exp < 1000000) exp = exp * 10 + (tok[i] - '0');
    if (neg) exp = -exp;
  }
  if (!seen) return false;
  return (int_digits > 0 ? int_digits + exp : exp - frac_zeros) > 0;
}

enum class NumberStatus { ok, not_a_number, not_finite };

// Strict parse of [p, end): the whole range must be one number. Accepts a leading '+', ".5" and
// exponents; rejects nan/inf. Values too small for a double round to a signed zero, as strtod does.
inline NumberStatus parse_double(const char* p, const char* end, double& v) noexcept {
  const char* start = p;
  if (p != end && *p == '+') {
    ++p;
    if (p == end || !(is_digit(*p) || *p == '.')) return NumberStatus::not_a_number;
  }
  const auto r = std::from_chars(p, end, v);
  if (r.ptr != end) return NumberStatus::not_a_number;
  if (r.ec == std::errc::result_out_of_range) {
    if (range_error_is_overflow(std::string_view(start, size_t(end - start)))) return NumberStatus::not_finite;
    v = (*p == '-') ? -0.0 : 0.0;
    return NumberStatus::ok;
  }
  if (r.ec != std::errc()) return NumberStatus::not_a_number;
  if (!std::isfinite(v)) return NumberStatus::not_finite;
  return NumberStatus::ok;
}

// A token of the header: its text and where it starts. Empty text means end of line or file.
struct Token {
  std::string_view text;
  uint32_t line = 0;
  uint32_t column = 0;
};

std::string quote(std::string_view s) {
  constexpr size_t kMax = 40;  // long tokens (a glued motion line) would drown the message
  const bool cut = s.size() > kMax;
  std::string q;  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on operator+ chains here
  q.reserve(kMax + 5);
  q.push_back('\'');
  q.append(cut ? s.substr(0, kMax) : s);
  if (cut) q.append("...");
  q.push_back('\'');
  return q;
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& file, const BvhReadOptions& options, BvhError& err,
         std::vector<std::string>* warnings)
      : p_(text.data()), end_(text.data() + text.size()), line_start_(text.data()),
        file_(file), options_(options), err_(err), warnings_(warnings) {}

  bool parse(Motion& m);

 private:
  // --- cursor ---
  uint32_t column_of(const char* q) const noexcept { return uint32_t(q - line_start_) + 1; }
  void consume_eol() noexcept {
    if (*p_ == '\r' && p_ + 1 != end_ && p_[1] == '\n') ++p_;
    ++p_;
    ++line_;
    line_start_ = p_;
  }
  void skip_blanks() noexcept {
    while (p_ != end_ && is_blank(*p_)) ++p_;
  }
  // Skips blanks and line ends.
  void skip_space() noexcept {
    while (p_ != end_) {
      if (is_blank(*p_)) ++p_;
      else if (is_eol(*p_)) consume_eol();
      else break;
    }
  }
  Token here() const noexcept { return Token{{}, line_, column_of(p_)}; }
  // The next header token on this line (braces are tokens of their own); empty at a line end.
  Token next_token_on_line() noexcept {
    skip_blanks();
    Token t = here();
    const char* s = p_;
    if (p_ != end_ && is_brace(*p_)) {
      ++p_;
    } else {
      while (p_ != end_ && !is_space(*p_) && !is_brace(*p_)) ++p_;
    }
    t.text = std::string_view(s, size_t(p_ - s));
    return t;
  }
  Token next_token() noexcept {
    skip_space();
    return next_token_on_line();
  }
  // Case-insensitive keyword at the cursor, not followed by a letter; consumes it on a match.
  bool match_word(std::string_view kw) noexcept {
    if (size_t(end_ - p_) < kw.size() || !iequals(std::string_view(p_, kw.size()), kw)) return false;
    if (p_ + kw.size() != end_ && is_alpha(p_[kw.size()])) return false;
    p_ += kw.size();
    return true;
  }
  // Raw text of a non-empty run up to the next space, for messages.
  std::string_view word_at(const char* q) const noexcept {
    const char* e = q;
    while (e != end_ && !is_space(*e)) ++e;
    return std::string_view(q, size_t(e - q));
  }
  // What lies at the cursor when something else was expected there.
  std::string describe_cursor() const {
    if (p_ == end_) return "end of file";
    if (is_eol(*p_)) return "end of line";
    return quote(word_at(p_));
  }
  // An empty token was taken at the cursor, which still points at the line or file end.
  std::string describe(const Token& t) const { return t.text.empty() ? describe_cursor() : quote(t.text); }

  bool fail(uint32_t line, uint32_t column, std::string message, ErrorKind kind = ErrorKind::malformed) {
    err_ = {line, column, std::move(message), kind};
    return false;
  }
  bool fail(const Token& t, std::string message) { return fail(t.line, t.column, std::move(message)); }
  bool expected(const Token& t, std::string_view what) {
    return fail(t, "expected " + std::string(what) + ", found " + describe(t));
  }
  void warn(uint32_t line, uint32_t column, const std::string& message) {
    if (warnings_)
      warnings_->push_back(file_ + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message);
  }

  // --- header ---
  bool parse_number(double& v, Token& t);
  bool parse_number(double& v) {
    Token t;
    return parse_number(v, t);
  }
  bool parse_count(uint64_t max, const char* what, uint64_t& v, Token& tok);
  bool parse_hierarchy(Skeleton& s);
  bool begin_node(Skeleton& s, int32_t parent, bool end_site, const Token& keyword);
  bool parse_offset(Joint& j);
  bool parse_channels(Joint& j);
  bool parse_motion_header(uint64_t& declared, Token& declared_tok, double& frame_time);
  bool parse_frames(Motion& m, uint64_t declared, const Token& declared_tok);

  const char* p_;
  const char* end_;
  const char* line_start_;
  uint32_t line_ = 1;
  const std::string& file_;
  const BvhReadOptions& options_;
  BvhError& err_;
  std::vector<std::string>* warnings_;
};

bool Parser::parse_number(double& v, Token& t) {
  t = next_token();
  if (t.text.empty() || is_brace(t.text[0])) return expected(t, "a number");
  switch (parse_double(t.text.data(), t.text.data() + t.text.size(), v)) {
    case NumberStatus::ok: return true;
    case NumberStatus::not_finite: return expected(t, "a finite number");
    case NumberStatus::not_a_number: break;
  }
  return expected(t, "a number");
}

bool Parser::parse_count(uint64_t max, const char* what, uint64_t& v, Token& t) {
  t = next_token();
  const char* s = t.text.data();
  const char* e = s + t.text.size();
  if (s != e && *s == '+') ++s;
  const auto r = std::from_chars(s, e, v);
  if (t.text.empty() || s == e || r.ptr != e || r.ec != std::errc() || v > max)
    return expected(t, std::string(what));
  return true;
}

bool Parser::parse_offset(Joint& j) {
  for (double& d : j.offset)
    if (!parse_number(d)) return false;
  return true;
}

bool Parser::parse_channels(Joint& j) {
  static constexpr std::array<std::string_view, 6> kNames = {"xposition", "yposition", "zposition",
                                                             "xrotation", "yrotation", "zrotation"};
  uint64_t n = 0;
  Token count_tok;
  if (!parse_count(6, "a channel count from 0 to 6", n, count_tok)) return false;
  j.channels.reserve(n);
  for (uint64_t i = 0; i < n; ++i) {
    const Token t = next_token();
    size_t k = 0;
    while (k < kNames.size() && !iequals(t.text, kNames[k])) ++k;
    if (k == kNames.size())
      return expected(t, "a channel name (Xposition ... Zrotation, " + std::to_string(n) + " in all)");
    const auto type = ChannelType(k);
    for (ChannelType c : j.channels)
      if (c == type) return fail(t, "expected each channel once, found " + quote(t.text) + " twice");
    j.channels.push_back(type);
  }
  return true;
}

// After ROOT/JOINT/End Site: the name is the rest of the line, trimmed. A '{' ending that line
// after a blank is the block's opening brace, not part of the name; so a name may not itself end
// that way (the writer could not write it back unambiguously).
bool Parser::begin_node(Skeleton& s, int32_t parent, bool end_site, const Token& keyword) {
  if (s.joints.size() >= options_.max_joints)
    return fail(keyword.line, keyword.column,
                "expected at most " + std::to_string(options_.max_joints) + " nodes (max_joints), found more",
                ErrorKind::limit);
  skip_blanks();
  const char* name_begin = p_;
  while (p_ != end_ && !is_eol(*p_)) ++p_;
  const char* name_end = p_;
  auto trim = [&] {
    while (name_end != name_begin && is_blank(name_end[-1])) --name_end;
  };
  auto ends_with_brace = [&] {
    return name_end != name_begin && name_end[-1] == '{' && (name_end - 1 == name_begin || is_blank(name_end[-2]));
  };
  trim();
  const bool brace_done = ends_with_brace();
  if (brace_done) {
    --name_end;
    trim();
    if (ends_with_brace())
      return fail(line_, column_of(name_end - 1), "expected one '{' after the name, found another '{'");
  }
  if (!end_site && name_end == name_begin) {
    Token t{{}, line_, column_of(name_begin)};
    p_ = name_begin;  // so the message describes what follows the keyword
    return expected(t, "a joint name");
  }
  Joint j;
  j.name.assign(name_begin, name_end);
  j.parent = parent;
  j.end_site = end_site;
  s.joints.push_back(std::move(j));
  if (!brace_done) {
    const Token t = next_token();
    if (t.text != "{") return expected(t, "'{'");
  }
  return true;
}

bool Parser::parse_hierarchy(Skeleton& s) {
  Token t = next_token();
  if (!iequals(t.text, "HIERARCHY")) return expected(t, "HIERARCHY");

  struct Open {
    int32_t index;
    bool end_site;
    bool has_offset = false;
    bool has_channels = false;
    bool has_children = false;
  };
  std::vector<Open> stack;
  std::unordered_map<std::string, uint32_t> names;  // ROOT/JOINT names, for duplicate warnings
  bool have_root = false;

  auto note_name = [&](const Token& kw) {
    const std::string& name = s.joints.back().name;
    auto [it, inserted] = names.emplace(name, uint32_t(s.joints.size() - 1));
    if (!inserted) warn(kw.line, kw.column, "duplicate joint name " + quote(name) + " (also node " +
                                                std::to_string(it->second) + "); both are kept");
  };

  for (;;) {
    // Between root blocks: another ROOT, or MOTION.
    t = next_token();
    if (iequals(t.text, "ROOT")) {
      if (!begin_node(s, -1, false, t)) return false;
      stack.push_back(Open{int32_t(s.joints.size() - 1), false});
      have_root = true;
    } else if (have_root && iequals(t.text, "MOTION")) {
      break;
    } else {
      return expected(t, have_root ? "ROOT or MOTION" : "ROOT");
    }
    note_name(t);

    while (!stack.empty()) {
      Open& top = stack.back();
      t = next_token();
      if (iequals(t.text, "OFFSET") && !top.has_offset && !top.has_children) {
        if (!parse_offset(s.joints[top.index])) return false;
        top.has_offset = true;
      } else if (iequals(t.text, "CHANNELS") && !top.end_site && !top.has_channels && !top.has_children) {
        if (!parse_channels(s.joints[top.index])) return false;
        top.has_channels = true;
      } else if (iequals(t.text, "JOINT") && !top.end_site && top.has_offset) {
        top.has_children = true;
        const int32_t parent = top.index;
        if (!begin_node(s, parent, false, t)) return false;
        note_name(t);
        stack.push_back(Open{int32_t(s.joints.size() - 1), false});
      } else if (iequals(t.text, "End") && !top.end_site && top.has_offset) {
        const Token site = next_token_on_line();
        if (!iequals(site.text, "Site")) return expected(site, "'Site' after 'End'");
        top.has_children = true;
        const int32_t parent = top.index;
        if (!begin_node(s, parent, true, t)) return false;
        stack.push_back(Open{int32_t(s.joints.size() - 1), true});
      } else if (t.text == "}" && top.has_offset) {
        stack.pop_back();
      } else {
        std::string what;
        if (!top.has_offset) {
          what = (top.end_site || top.has_channels) ? "OFFSET" : "OFFSET or CHANNELS";
        } else if (top.end_site) {
          what = "'}'";
        } else {
          what = (top.has_channels || top.has_children) ? "" : "CHANNELS, ";
          what += "JOINT, End Site or '}'";
        }
        return expected(t, what);
      }
    }
  }
  s.assign_channel_columns();
  return true;
}

bool Parser::parse_motion_header(uint64_t& declared, Token& declared_tok, double& frame_time) {
  skip_space();
  Token t = here();
  if (!match_word("Frames")) return fail(t, "expected 'Frames:', found " + describe_cursor());
  skip_blanks();
  t = here();
  if (p_ == end_ || *p_ != ':') return fail(t, "expected ':' after 'Frames', found " + describe_cursor());
  ++p_;
  skip_blanks();
  if (!parse_count(UINT64_MAX, "a frame count", declared, declared_tok)) return false;
  if (declared > options_.max_frames)
    return fail(declared_tok.line, declared_tok.column,
                "expected at most " + std::to_string(options_.max_frames) + " frames (max_frames), found " +
                    std::to_string(declared),
                ErrorKind::limit);

  skip_space();
  t = here();
  bool ok = match_word("Frame");
  if (ok) {
    skip_blanks();
    ok = match_word("Time");
  }
  if (!ok) return fail(t, "expected 'Frame Time:', found " + describe_cursor());
  skip_blanks();
  t = here();
  if (p_ == end_ || *p_ != ':') return fail(t, "expected ':' after 'Frame Time', found " + describe_cursor());
  ++p_;
  skip_blanks();
  t = here();
  if (p_ == end_ || is_eol(*p_)) return fail(t, "expected a frame time, found " + describe_cursor());
  if (!parse_number(frame_time, t)) return false;
  if (frame_time < 0.0) return expected(t, "a frame time >= 0");
  skip_blanks();
  if (p_ != end_ && !is_eol(*p_)) {
    const Token x = here();
    return fail(x, "expected end of line after the frame time, found " + quote(word_at(p_)));
  }
  if (p_ != end_) consume_eol();
  return true;
}

// The hot loop: one motion line = one frame of `channels` values.
bool Parser::parse_frames(Motion& m, uint64_t declared, const Token& declared_tok) {
  const uint32_t channels = m.skeleton.channel_count();
  std::vector<double>& values = m.values;
  uint64_t lines = 0;
  size_t n = 0;  // values written; values.size() runs ahead as capacity
  if (channels > 0) {
    // Each value takes at least two bytes ("0 "), so the text bounds what the declared count may
    // reserve: a lying Frames: cannot make us allocate more than the input justifies.
    const uint64_t bound = uint64_t(end_ - p_) / (2 * uint64_t(channels)) + 1;
    values.resize(size_t(std::min(declared, bound)) * channels);
  }

  const char* const first = p_;
  auto progress = [&] {
    if (options_.progress) options_.progress(end_ == first ? 1.0 : double(p_ - first) / double(end_ - first));
  };
  while (p_ != end_) {
    if (lines % 1024 == 0) progress();
    skip_blanks();
    if (p_ == end_) break;
    if (is_eol(*p_)) {  // blank line
      consume_eol();
      continue;
    }
    if (channels == 0)
      return fail(line_, column_of(p_), "expected an empty line (the skeleton has no channels), found " +
                                            quote(word_at(p_)));
    if (lines >= options_.max_frames)
      return fail(line_, column_of(p_),
                  "expected at most " + std::to_string(options_.max_frames) + " motion lines (max_frames), found more",
                  ErrorKind::limit);
    if (values.size() - n < channels) values.resize(std::max(n + channels, values.size() + values.size() / 2));
    double* out = values.data() + n;
    const char* p = p_;
    for (uint32_t c = 0; c < channels; ++c) {
      while (p != end_ && is_blank(*p)) ++p;
      if (p == end_ || is_eol(*p)) {
        p_ = p;
        return fail(line_, column_of(p), "expected " + std::to_string(channels) + " values on this motion line, found " +
                                             std::to_string(c) + " (" + (p == end_ ? "end of file" : "end of line") + ")");
      }
      const char* tok = p;
      if (*p == '+') ++p;
      auto r = std::from_chars(p, end_, out[c]);
      if (r.ec != std::errc() || (r.ptr != end_ && !is_space(*r.ptr)) || (p != tok && !(is_digit(*p) || *p == '.')) ||
          !std::isfinite(out[c])) {
        // Rare path: find the whole token and classify it.
        const std::string_view word = word_at(tok);
        p_ = tok;
        switch (parse_double(word.data(), word.data() + word.size(), out[c])) {
          case NumberStatus::ok: r.ptr = word.data() + word.size(); break;
          case NumberStatus::not_finite:
            return fail(line_, column_of(tok), "expected a finite number, found " + quote(word));
          case NumberStatus::not_a_number:
            return fail(line_, column_of(tok), "expected a number, found " + quote(word));
        }
      }
      p = r.ptr;
    }
    while (p != end_ && is_blank(*p)) ++p;
    p_ = p;
    if (p != end_ && !is_eol(*p))
      return fail(line_, column_of(p), "expected end of line after " + std::to_string(channels) +
                                           " values, found " + quote(word_at(p)));
    if (p != end_) consume_eol();
    n += channels;
    ++lines;
  }
  progress();

  if (channels == 0) {
    lines = declared;  // no value can confirm or deny the count; nothing is allocated for it
  } else if (lines < declared) {
    return fail(declared_tok, "expected " + std::to_string(declared) + " motion lines (Frames: " +
                                  std::to_string(declared) + "), found " + std::to_string(lines));
  } else if (lines > declared) {
    warn(declared_tok.line, declared_tok.column,
         "Frames: declares " + std::to_string(declared) + " frames, but " + std::to_string(lines) +
             " motion lines follow; all " + std::to_string(lines) + " are kept");
  }
  values.resize(n);
  if (values.capacity() - n > n / 8) values.shrink_to_fit();
  m.frame_count = uint32_t(lines);
  return true;
}

bool Parser::parse(Motion& m) {
  if (end_ - p_ >= 3 && std::memcmp(p_, "\xEF\xBB\xBF", 3) == 0) {
    p_ += 3;
    line_start_ = p_;
  }
  uint64_t declared = 0;
  Token declared_tok;
  return parse_hierarchy(m.skeleton) && parse_motion_header(declared, declared_tok, m.frame_time) &&
         parse_frames(m, declared, declared_tok);
}

}  // namespace

Motion read_bvh(std::string_view text, const std::string& file_name, std::vector<std::string>* warnings,
                const BvhReadOptions& options) {
  Motion m;
  BvhError err;
  std::vector<std::string> local_warnings;
  Parser parser(text, file_name, options, err, warnings ? &local_warnings : nullptr);
  if (!parser.parse(m)) throw Error::bvh(file_name, err.line, err.column, std::move(err.message), err.kind);
  if (warnings) warnings->insert(warnings->end(), local_warnings.begin(), local_warnings.end());
  return m;
}

Motion read_bvh_file(const std::string& path, std::vector<std::string>* warnings, const BvhReadOptions& options) {
  // The size is only a hint for one allocation; pipes and the like just grow.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::is_directory(status)) throw Error::io(path, "cannot read file", EISDIR);
  size_t hint = size_t(1) << 16;
  if (!ec && std::filesystem::is_regular_file(status)) {
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec) hint = size_t(size) + 1;  // +1: the last read sees EOF without growing
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw Error::io(path, "cannot open file", errno);
  std::string text;
  size_t used = 0;
  text.resize(hint);
  errno = 0;
  for (;;) {
    used += std::fread(text.data() + used, 1, text.size() - used, f);
    if (used < text.size()) break;
    text.resize(text.size() * 2);
  }
  text.resize(used);
  const bool bad = std::ferror(f) != 0;
  const int code = errno;
  std::fclose(f);
  if (bad) throw Error::io(path, "cannot read file", code ? code : EIO);
  return read_bvh(text, path, warnings, options);
}

}  // namespace keyanim::offline
