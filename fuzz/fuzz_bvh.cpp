// Fuzz target: the BVH reader on arbitrary text.
// Checks: no crash, hang or huge allocation; a failure names a line and column inside the text
// and leaves the motion empty; a success gives a consistent motion (parents first, channel
// columns, finite values, values = frames x channels) that write_bvh writes back to text which
// reads back bit for bit (bvh.h promises read(write(m)) == m).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_common.h"
#include "keyanim/offline/bvh.h"

namespace {

using keyanim::Joint;
using keyanim::offline::Error;
using keyanim::offline::ErrorKind;
using keyanim::offline::Motion;
using keyanim::offline::read_bvh;

// Byte length of every line of `text`, split as the reader splits (\n, \r\n, lone \r); line 1
// starts after a UTF-8 byte order mark.
std::vector<size_t> line_lengths(std::string_view text) {
  std::vector<size_t> lengths;
  size_t i = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  size_t start = i;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '\n' || c == '\r') {
      lengths.push_back(i - start);
      i += (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ? 2 : 1;
      start = i;
    } else {
      ++i;
    }
  }
  lengths.push_back(text.size() - start);
  return lengths;
}

void check_consistent(const Motion& m) {
  const auto& joints = m.skeleton.joints;
  FUZZ_CHECK(!joints.empty());
  uint32_t column = 0;
  for (size_t i = 0; i < joints.size(); ++i) {
    const Joint& j = joints[i];
    FUZZ_CHECK(j.parent >= -1 && j.parent < static_cast<int32_t>(i));
    if (j.parent >= 0) FUZZ_CHECK(!joints[static_cast<size_t>(j.parent)].end_site);
    if (j.end_site) FUZZ_CHECK(j.parent >= 0 && j.channels.empty());
    FUZZ_CHECK(j.channels.size() <= 6);
    for (size_t a = 0; a < j.channels.size(); ++a)
      for (size_t b = a + 1; b < j.channels.size(); ++b) FUZZ_CHECK(j.channels[a] != j.channels[b]);
    FUZZ_CHECK(j.first_channel == column);
    column += static_cast<uint32_t>(j.channels.size());
    for (double o : j.offset) FUZZ_CHECK(std::isfinite(o));
    FUZZ_CHECK(j.name.find('\n') == std::string::npos && j.name.find('\r') == std::string::npos);
  }
  FUZZ_CHECK(m.channel_count() == column);
  FUZZ_CHECK(m.values.size() == static_cast<size_t>(m.frame_count) * column);
  FUZZ_CHECK(std::isfinite(m.frame_time) && !(m.frame_time < 0.0));
  for (double v : m.values) FUZZ_CHECK(std::isfinite(v));
}

void check_same(const Motion& a, const Motion& b) {
  FUZZ_CHECK(a.skeleton.joints.size() == b.skeleton.joints.size());
  for (size_t i = 0; i < a.skeleton.joints.size(); ++i) {
    const Joint& x = a.skeleton.joints[i];
    const Joint& y = b.skeleton.joints[i];
    FUZZ_CHECK(x.name == y.name);
    FUZZ_CHECK(x.parent == y.parent);
    FUZZ_CHECK(x.end_site == y.end_site);
    FUZZ_CHECK(x.channels == y.channels);
    for (size_t k = 0; k < 3; ++k) FUZZ_CHECK(keyanim::fuzz::same_double(x.offset[k], y.offset[k]));
  }
  FUZZ_CHECK(a.frame_count == b.frame_count);
  FUZZ_CHECK(keyanim::fuzz::same_double(a.frame_time, b.frame_time));
  FUZZ_CHECK(a.values.size() == b.values.size());
  for (size_t i = 0; i < a.values.size(); ++i) FUZZ_CHECK(keyanim::fuzz::same_double(a.values[i], b.values[i]));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Motion m;
  std::vector<std::string> warnings;
  try {
    m = read_bvh(text, "fuzz.bvh", &warnings);
  } catch (const Error& err) {
    const std::vector<size_t> lengths = line_lengths(text);
    FUZZ_CHECK(err.file() == "fuzz.bvh");
    FUZZ_CHECK(!err.message().empty());
    FUZZ_CHECK(err.kind() == ErrorKind::malformed || err.kind() == ErrorKind::limit);
    FUZZ_CHECK(err.line() >= 1 && err.line() <= lengths.size());
    FUZZ_CHECK(err.column() >= 1 && err.column() <= lengths[err.line() - 1] + 1);
    return 0;
  }
  check_consistent(m);
  // The text the writer makes for a channel-less motion has one empty line per frame: skip
  // the round trip when that would be large (it is linear, just slow for a fuzzer).
  if (uint64_t(m.frame_count) * (m.channel_count() + 1) > 200000) return 0;
  const std::string written = keyanim::offline::write_bvh(m);
  Motion back;
  try {
    back = read_bvh(written, "written.bvh");
  } catch (const Error& err) {
    std::fprintf(stderr, "written BVH does not read back: %s\n", err.what());
    FUZZ_CHECK(false);
  }
  check_same(m, back);
  return 0;
}
