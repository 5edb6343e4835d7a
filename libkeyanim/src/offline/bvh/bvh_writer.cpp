// BVH writer: text built in place in one reused buffer and handed on in chunks (write_bvh
// collects them into one string), numbers in std::to_chars' shortest round-trip form (with a
// faster path that gives the same text), so that reading back gives bit-identical doubles.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "keyanim/offline/bvh.h"

namespace keyanim::offline {

namespace {

// Longest shortest-form double, e.g. "-2.2250738585072014e-308" (24 chars), plus a separator.
constexpr size_t kMaxNumber = 25;

// Fast path for the common mocap value: a decimal with at most 9 decimals and |v| < 2^22. Writes
// exactly what std::to_chars(p, end, v) writes, or returns nullptr to let it do so (libstdc++'s
// shortest form costs ~80 ns a value, this a fraction of that). Why it is exact:
//  - n ~ |v| * 1e9, then the check n / 1e9 == |v|: both operands are exact doubles and IEEE
//    division rounds correctly, so the decimal n * 10^-9 reads back as |v|. (The check alone
//    carries correctness; a badly rounded n only sends the value to the slow path.)
//  - |v| < 2^22 makes an ulp of v (<= 2^-31) smaller than 1e-9, so no other decimal with at most
//    9 decimals reads back as v, and any with more decimals has more significant digits: n with
//    trailing zeros dropped is the shortest form, the one to_chars picks.
//  - to_chars prints it fixed unless scientific is strictly shorter; then we defer to it.
inline char* write_decimal(char* p, double v) noexcept {
  constexpr double kLimit = 4194304.0;  // 2^22
  constexpr double kScale = 1e9;
  constexpr int kDecimals = 9;
  const double a = std::fabs(v);
  if (!(a < kLimit)) return nullptr;  // also rejects NaN
  const uint64_t n = uint64_t(a * kScale + 0.5);
  if (double(n) / kScale != a) return nullptr;

  uint32_t ip = uint32_t(n / 1000000000u);
  uint32_t fp = uint32_t(n % 1000000000u);
  char frac[kDecimals];
  for (int i = kDecimals - 1; i >= 0; --i) {
    frac[i] = char('0' + fp % 10);
    fp /= 10;
  }
  int f = kDecimals;  // decimals left after dropping trailing zeros
  while (f > 0 && frac[f - 1] == '0') --f;
  char digits[8];  // the integer part, least significant first; ip < 2^22 has at most 7 digits
  int ni = 0;
  do {
    digits[ni++] = char('0' + ip % 10);
    ip /= 10;
  } while (ip != 0);

  // Significant digits, to choose fixed or scientific as to_chars does. The decimal exponent
  // lies in [-9, 6], so scientific spends 4 characters on "e+XX".
  int significant;
  if (ni > 1 || digits[0] != '0') {
    significant = ni + f;
    if (f == 0) {
      int tz = 0;
      while (digits[tz] == '0') ++tz;
      significant = ni - tz;
    }
  } else {
    int lz = 0;
    while (lz < f && frac[lz] == '0') ++lz;
    significant = f - lz;  // 0 for zero itself
  }
  const int fixed_len = ni + (f > 0 ? 1 + f : 0);
  const int sci_len = significant == 0 ? 5 : significant + (significant > 1 ? 1 : 0) + 4;
  if (sci_len < fixed_len) return nullptr;

  if (std::signbit(v)) *p++ = '-';  // "-0" too, as to_chars writes it
  while (ni > 0) *p++ = digits[--ni];
  if (f > 0) {
    *p++ = '.';
    std::memcpy(p, frac, size_t(f));
    p += f;
  }
  return p;
}

inline char* write_number(char* p, char* end, double v) noexcept {
  if (char* q = write_decimal(p, v)) return q;
  return std::to_chars(p, end, v).ptr;
}

// Appends to a caller's buffer, whose first `used` bytes are text: the buffer grows by
// doubling and is never shrunk, so a streaming writer reuses one allocation.
class Text {
 public:
  Text(std::string& s, size_t& used) : s_(s), n_(used) {}
  // Guarantees room for k more bytes and returns where they go.
  char* room(size_t k) {
    if (s_.size() - n_ < k) s_.resize(std::max(s_.size() * 2, n_ + k));
    return s_.data() + n_;
  }
  void commit(const char* end) noexcept { n_ = size_t(end - s_.data()); }
  void put(std::string_view v) {
    std::memcpy(room(v.size()), v.data(), v.size());
    n_ += v.size();
  }
  void put(char c) {
    *room(1) = c;
    ++n_;
  }
  void put_number(double d) {
    char* p = room(kMaxNumber);
    commit(write_number(p, p + kMaxNumber, d));
  }
  void put_count(uint64_t n) {
    char* p = room(24);
    commit(std::to_chars(p, p + 24, n).ptr);
  }
  // Indentation stops growing at kMaxIndent: a deep chain would otherwise make the text
  // quadratic in its depth.
  void indent(size_t depth) {
    depth = std::min(depth, kMaxIndent);
    char* p = room(depth);
    std::memset(p, '\t', depth);
    commit(p + depth);
  }

 private:
  std::string& s_;
  size_t& n_;
};

// About this much text is handed to the sink at a time.
constexpr size_t kChunk = size_t(1) << 20;

// The hierarchy, depth-first with children in index order, which is the order the reader
// stores nodes in. A node whose parent is not an earlier node is written as a ROOT; a node is
// written as an End Site only if it is flagged so and has neither channels nor children (else
// as a JOINT), so no value column is ever dropped. Returns the nodes in written order.
std::vector<uint32_t> write_hierarchy(const std::vector<Joint>& joints, Text& out) {
  const size_t node_count = joints.size();

  // Children as a compact list per node (CSR), in index order; roots separately.
  std::vector<uint32_t> first_child(node_count + 1, 0);
  std::vector<uint32_t> roots;
  auto parent_of = [&](size_t i) -> int64_t {
    const int64_t p = joints[i].parent;
    return (p >= 0 && p < int64_t(i)) ? p : -1;
  };
  for (size_t i = 0; i < node_count; ++i) {
    const int64_t p = parent_of(i);
    if (p < 0) roots.push_back(uint32_t(i));
    else ++first_child[size_t(p) + 1];
  }
  for (size_t i = 0; i < node_count; ++i) first_child[i + 1] += first_child[i];
  std::vector<uint32_t> children(first_child[node_count]);
  {
    std::vector<uint32_t> fill(first_child.begin(), first_child.end() - 1);
    for (size_t i = 0; i < node_count; ++i)
      if (const int64_t p = parent_of(i); p >= 0) children[fill[size_t(p)]++] = uint32_t(i);
  }

  out.put("HIERARCHY\n");
  std::vector<uint32_t> order;  // nodes in written order
  order.reserve(node_count);
  struct Open {
    uint32_t node;
    uint32_t next_child;
  };
  std::vector<Open> stack;
  auto open = [&](uint32_t i, bool root) {
    const Joint& j = joints[i];
    const size_t depth = stack.size();
    const bool no_children = first_child[i] == first_child[i + 1];
    const bool end_site = !root && j.end_site && j.channels.empty() && no_children;
    out.indent(depth);
    if (end_site) {
      out.put("End Site");
      if (!j.name.empty()) {
        out.put(' ');
        out.put(j.name);
      }
    } else {
      out.put(root ? "ROOT " : "JOINT ");
      out.put(j.name);
    }
    out.put('\n');
    out.indent(depth);
    out.put("{\n");
    out.indent(depth + 1);
    out.put("OFFSET");
    for (double d : j.offset) {
      out.put(' ');
      out.put_number(d);
    }
    out.put('\n');
    if (!end_site) {
      out.indent(depth + 1);
      out.put("CHANNELS ");
      out.put_count(j.channels.size());
      for (ChannelType c : j.channels) {
        out.put(' ');
        out.put(channel_name(c));
      }
      out.put('\n');
    }
    order.push_back(i);
    stack.push_back(Open{i, first_child[i]});
  };
  for (uint32_t r : roots) {
    open(r, true);
    while (!stack.empty()) {
      Open& top = stack.back();
      if (top.next_child < first_child[top.node + 1]) {
        open(children[top.next_child++], false);
      } else {
        stack.pop_back();
        out.indent(stack.size());
        out.put("}\n");
      }
    }
  }
  return order;
}

}  // namespace

BvhWriter::BvhWriter(const Skeleton& skeleton, uint64_t frame_count, double frame_time, Sink sink)
    : sink_(std::move(sink)), declared_(frame_count) {
  const std::vector<Joint>& joints = skeleton.joints;
  size_t header_estimate = 64;
  for (const Joint& j : joints) header_estimate += j.name.size() + 160;
  buffer_.resize(std::min(header_estimate, kChunk));
  Text out(buffer_, used_);
  const std::vector<uint32_t> order = write_hierarchy(joints, out);
  out.put("MOTION\nFrames: ");
  out.put_count(frame_count);
  out.put("\nFrame Time: ");
  out.put_number(frame_time);
  out.put('\n');

  // Column of each node's first channel, from the channel lists (first_channel may be stale),
  // and the source column of each written column: identity for anything the reader produced.
  std::vector<uint32_t> column(joints.size() + 1, 0);
  for (size_t i = 0; i < joints.size(); ++i) column[i + 1] = column[i] + uint32_t(joints[i].channels.size());
  source_.reserve(column.back());
  for (uint32_t i : order)
    for (uint32_t c = column[i]; c < column[i + 1]; ++c) source_.push_back(c);
  for (uint32_t c = 0; c < source_.size(); ++c) identity_ = identity_ && source_[c] == c;
  if (used_ >= kChunk) flush();
}

void BvhWriter::frame(const double* row) {
  const size_t channels = source_.size();
  Text out(buffer_, used_);
  char* p = out.room(channels * kMaxNumber + 1);
  char* const limit = p + channels * kMaxNumber + 1;
  for (size_t c = 0; c < channels; ++c) {
    p = write_number(p, limit, identity_ ? row[c] : row[source_[c]]);
    *p++ = ' ';
  }
  if (channels > 0) --p;  // the last separator becomes the line end
  *p++ = '\n';
  out.commit(p);
  ++written_;
  if (used_ >= kChunk) flush();
}

void BvhWriter::flush() {
  if (used_ > 0) sink_(std::string_view(buffer_.data(), used_));
  used_ = 0;
}

void BvhWriter::finish() {
  flush();
  if (written_ != declared_)
    throw Error(ErrorKind::invalid_argument, "BVH writer: " + std::to_string(written_) + " frames given, " +
                                                 std::to_string(declared_) + " declared");
}

std::string write_bvh(const Motion& motion) {
  size_t channels = 0;
  for (const Joint& j : motion.skeleton.joints) channels += j.channels.size();
  size_t frames = motion.frame_count;
  if (channels > 0) frames = std::min(frames, motion.values.size() / channels);
  std::string text;
  text.reserve(motion.skeleton.joints.size() * 100 + frames * channels * 12 + frames + 64);
  BvhWriter writer(motion.skeleton, frames, motion.frame_time, [&](std::string_view chunk) { text.append(chunk); });
  for (size_t f = 0; f < frames; ++f) writer.frame(motion.values.data() + f * channels);
  writer.finish();
  return text;
}

}  // namespace keyanim::offline
