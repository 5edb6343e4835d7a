// The spec's test vectors (spec/test-vectors/): each loads and equals its hand-built clip, and
// matches the values of reference_decoder.py, an independent Python implementation: its stored
// values (Appendix A) bit for bit, and in version 5 its quaternion nodes' rotations (4.7).
#include <doctest/doctest.h>
#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "clip_reference.h"
#include "keyanim/version.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"

#include "crafted.h"

using namespace container_test;

namespace {

// ---------------------------------------------------------------------------------------------
// A minimal JSON reader for the test vectors' expected values.

struct Json {
  enum Kind { null, boolean, number, string, array, object } kind = null;
  double num = 0;
  bool b = false;
  std::string str;
  std::vector<Json> arr;
  std::map<std::string, Json> obj;
  const Json& operator[](const std::string& k) const {
    static const Json none;
    auto it = obj.find(k);
    return it == obj.end() ? none : it->second;
  }
};

struct JsonParser {
  const std::string& s;
  size_t i = 0;
  bool ok = true;
  void ws() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\r' || s[i] == '\t')) ++i;
  }
  Json value() {
    ws();
    Json j;
    if (i >= s.size()) {
      ok = false;
      return j;
    }
    const char c = s[i];
    if (c == '{') {
      j.kind = Json::object;
      ++i;
      ws();
      if (s[i] == '}') return ++i, j;
      while (ok) {
        ws();
        const std::string k = value().str;
        ws();
        if (s[i++] != ':') ok = false;
        j.obj[k] = value();
        ws();
        if (s[i] == ',') ++i;
        else if (s[i] == '}') return ++i, j;
        else ok = false;
      }
    } else if (c == '[') {
      j.kind = Json::array;
      ++i;
      ws();
      if (s[i] == ']') return ++i, j;
      while (ok) {
        j.arr.push_back(value());
        ws();
        if (s[i] == ',') ++i;
        else if (s[i] == ']') return ++i, j;
        else ok = false;
      }
    } else if (c == '"') {
      j.kind = Json::string;
      ++i;
      while (i < s.size() && s[i] != '"') {
        if (s[i] == '\\') {
          ++i;
          const char e = s[i];
          j.str += e == 'n' ? '\n' : e == 't' ? '\t' : e;  // \uXXXX is not used by the vectors
        } else {
          j.str += s[i];
        }
        ++i;
      }
      ++i;
    } else if (s.compare(i, 4, "true") == 0 || s.compare(i, 5, "false") == 0) {
      j.kind = Json::boolean;
      j.b = s[i] == 't';
      i += j.b ? 4 : 5;
    } else if (s.compare(i, 4, "null") == 0) {
      i += 4;
    } else {
      j.kind = Json::number;
      char* end = nullptr;
      j.num = std::strtod(s.c_str() + i, &end);
      if (end == s.c_str() + i) ok = false;
      i = size_t(end - s.c_str());
    }
    return j;
  }
};

}  // namespace

TEST_SUITE("container") {

TEST_CASE("test vectors load and equal their hand-built clips") {
  // KEYANIM_WRITE_TEST_VECTORS=1 (re)writes the files: only for adding new vectors.
  const bool write = std::getenv("KEYANIM_WRITE_TEST_VECTORS") != nullptr;
  for (const std::string name : kVectorNames) {
    CAPTURE(name);
    const EncodedClip e = vector_clip(name);
    if (write && name.starts_with("v" + std::to_string(keyanim::kQuatFormatVersionMajor) + "_")) {
      // Archive files at level 19; their runtime profiles as keyanim convert --runtime writes them.
      const auto archive = keyanim::offline::write_kanim(e, 19);
      Clip loaded;
      REQUIRE(Clip::load(archive, loaded) == Status::ok);
      const auto bytes = name.ends_with("_runtime") ? keyanim::offline::write_kanim_runtime(loaded) : archive;
      std::ofstream(vector_path(name, ".kanim"), std::ios::binary)
          .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    const Loaded l = load(read_file(vector_path(name, ".kanim")));
    REQUIRE_MESSAGE(l.status == Status::ok, l.err.detail);
    const Clip ref = keyanim::offline::to_clip(e);
    check_same_clip(l.clip, ref);
    check_same_samples(l.clip, ref);
  }
}

TEST_CASE("the predict vectors hold both value codings and the long ones extrapolate") {
  for (const char* name : {"v2_predict", "v2_long", "v3_predict", "v3_long"}) {
    CAPTURE(name);
    const std::vector<uint8_t> bytes = read_file(vector_path(name, ".kanim"));
    REQUIRE(bytes.size() > 12);
    CHECK(bytes[8] == name[1] - '0');
    CHECK(bytes[9] == 0);
    const Loaded l = load(bytes);
    REQUIRE(l.status == Status::ok);
    const size_t C = l.clip.channel_count();
    std::vector<uint8_t> chan;
    RawFile r = split(bytes);
    chan = r.get("CHAN").stored;
    if (r.get("CHAN").flags & 1) {
      chan.assign(size_t(ZSTD_getFrameContentSize(chan.data(), chan.size())), 0);
      const auto& z = r.get("CHAN").stored;
      REQUIRE(ZSTD_decompress(chan.data(), chan.size(), z.data(), z.size()) == chan.size());
    }
    REQUIRE(chan.size() == (bytes[8] == 3 ? 19 : 18) * C);
    const std::vector<uint8_t> codings(chan.begin() + 17 * C, chan.begin() + 18 * C);
    CHECK(std::count(codings.begin(), codings.end(), 1) >= 1);
    if (std::string(name).ends_with("predict")) CHECK(std::count(codings.begin(), codings.end(), 0) >= 1);
    if (bytes[8] == 3) {  // Residual_Bytes: v3_predict's deltas of 2^41 and more need 7 bytes
      const std::vector<uint8_t> widths(chan.begin() + 18 * C, chan.end());
      CHECK(*std::max_element(widths.begin(), widths.end()) == (std::string(name) == "v3_predict" ? 7 : 3));
    }
  }
}

TEST_CASE("test vectors match the independent reference decoder") {
  double max_rel = 0.0;
  uint64_t values = 0, exact = 0;
  for (const std::string name : kVectorNames) {
    CAPTURE(name);
    std::ifstream in(vector_path(name, ".json"));
    REQUIRE(in.good());
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    JsonParser p{text};
    const Json j = p.value();
    REQUIRE(p.ok);
    const Loaded l = load(read_file(vector_path(name, ".kanim")));
    REQUIRE(l.status == Status::ok);
    const Clip& clip = l.clip;
    CHECK(j["format_version"].str ==
          std::to_string(clip.version_major()) + "." + std::to_string(clip.version_minor()));
    CHECK(j["format_version"].str.substr(0, 1) == name.substr(1, 1));  // v1_* files are 1.x
    CHECK(j["frame_count"].num == clip.frame_count());
    CHECK(j["frame_time"].num == clip.frame_time());
    CHECK(j["tangent_rule"].num == double(static_cast<int>(clip.tangent_rule())));
    CHECK(j["notes"].str == clip.encoder_notes());
    const auto& nodes = j["nodes"].arr;
    REQUIRE(nodes.size() == clip.skeleton().joints.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
      const Joint& jt = clip.skeleton().joints[i];
      CHECK(nodes[i]["name"].str == jt.name);
      CHECK(nodes[i]["parent"].num == jt.parent);
      CHECK(nodes[i]["end_site"].b == jt.end_site);
      for (size_t k = 0; k < 3; ++k) CHECK(nodes[i]["offset"].arr[k].num == jt.offset[k]);
      REQUIRE(nodes[i]["channels"].arr.size() == jt.channels.size());
      for (size_t k = 0; k < jt.channels.size(); ++k)
        CHECK(nodes[i]["channels"].arr[k].str == keyanim::channel_name(jt.channels[k]));
    }
    // Version 5: the quaternion nodes, and at each position their rotations (section 4.7, in
    // binary64) beside the stored values (Appendix A).
    const auto& quats = j["quat_nodes"].arr;
    REQUIRE(quats.size() == clip.quat_node_count());
    for (uint32_t q = 0; q < quats.size(); ++q) {
      CHECK(quats[q]["node"].num == clip.quat_node(q).node);
      for (size_t k = 0; k < 3; ++k) CHECK(quats[q]["reference"].arr[k].num == clip.quat_node(q).reference[k]);
    }
    const auto& samples = j["samples"].arr;
    REQUIRE(samples.size() >= 8);
    std::vector<float> out(clip.channel_count());
    std::vector<keyanim::Transform> pose(clip.skeleton().joints.size());
    for (const Json& s : samples) {
      REQUIRE(clip.sample_stored(s["position"].num, out) == Status::ok);
      REQUIRE(clip.sample_local(s["position"].num, pose) == Status::ok);
      const auto& rotations = s["rotations"].arr;
      REQUIRE(rotations.size() == quats.size());
      for (uint32_t q = 0; q < quats.size(); ++q) {  // q and -q are one rotation
        const float* got = pose[clip.quat_node(q).node].rotation;
        double same = 0.0, opposite = 0.0;
        for (size_t k = 0; k < 4; ++k) {
          const double e = rotations[q].arr[k].num;
          same = std::max(same, std::fabs(got[k] - e)), opposite = std::max(opposite, std::fabs(got[k] + e));
        }
        CHECK_MESSAGE(std::min(same, opposite) <= 2e-6, "position " << s["position"].num << " quaternion node " << q);
      }
      const auto& expected = s["values"].arr;
      REQUIRE(expected.size() == out.size());
      for (size_t c = 0; c < out.size(); ++c) {
        const double e = expected[c].num;
        const double rel = std::fabs(double(out[c]) - e) / std::max(std::fabs(e), 1.0);
        max_rel = std::max(max_rel, rel);
        exact += double(out[c]) == e;
        ++values;
        CHECK_MESSAGE(rel <= 1e-6, "position " << s["position"].num << " channel " << c);
      }
    }
  }
  MESSAGE("test vectors: " << values << " values, " << exact << " bit-exact, max relative difference " << max_rel);
  CHECK(values > 500);
}

}  // TEST_SUITE("container")
