// glTF export (keyanim/offline/gltf.h), read back here with nlohmann::json and evaluated by this
// file's own glTF interpolation (written from the glTF 2.0 specification, appendix C) and its own
// quaternion forward kinematics: translations must be the clip's curves between frames too,
// rotations within the tolerance at every frame, the container well formed. The node tests
// (tests/gltf) play every corpus export in three.js and run the Khronos validator.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "keyanim/cardinal.h"
#include "keyanim/clip.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/fk.h"
#include "keyanim/offline/gltf.h"

namespace {

using keyanim::ChannelType;
using keyanim::Clip;
using keyanim::Interpolation;
using keyanim::TangentRule;
using keyanim::offline::EncodedChannel;
using keyanim::offline::EncodedClip;
using keyanim::offline::GltfOptions;
using keyanim::offline::GltfOutput;
using keyanim::offline::GltfReport;
using CT = ChannelType;
using nlohmann::json;

// A channel whose keys sample f(frame) at `frames`, quantized at `step`.
template <typename F>
EncodedChannel chan(Interpolation interp, float tension, double step, std::vector<uint32_t> frames, F f) {
  EncodedChannel c;
  c.interp = interp;
  c.tension = tension;
  c.step = step;
  for (uint32_t k : frames) c.q.push_back(std::llround(f(double(k)) / step));
  c.frames = std::move(frames);
  return c;
}

// Hips (positions on staggered keys: cardinal, cardinal with tension, linear) -> Spine -> Head
// and an End Site, plus an arm with a ZXY then YXZ order, over 61 frames at 30 fps.
EncodedClip test_clip(TangentRule rule, bool linear_positions = false) {
  EncodedClip c;
  const auto rot_zxy = std::vector<ChannelType>{CT::z_rotation, CT::x_rotation, CT::y_rotation};
  c.skeleton.joints = {
      {.name = "Hips", .parent = -1, .offset = {0, 90, 0},
       .channels = {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation, CT::x_rotation, CT::y_rotation}},
      {.name = "Spine", .parent = 0, .offset = {0, 20, 0}, .channels = rot_zxy},
      {.name = "Head", .parent = 1, .offset = {0, 30, 2}, .channels = rot_zxy},
      {.name = "", .parent = 2, .offset = {0, 12, 0}, .channels = {}, .end_site = true},
      {.name = "Arm", .parent = 1, .offset = {15, 25, 0}, .channels = {CT::y_rotation, CT::x_rotation, CT::z_rotation}},
      {.name = "Hand", .parent = 4, .offset = {28, 0, 0}, .channels = rot_zxy},
      {.name = "", .parent = 5, .offset = {8, 0, 0}, .channels = {}, .end_site = true},
  };
  c.skeleton.assign_channel_columns();
  c.frame_count = 61;
  c.frame_time = 1.0 / 30.0;
  c.tangent_rule = rule;
  const auto lin = Interpolation::linear, card = Interpolation::cardinal;
  const auto pos = linear_positions ? lin : card;
  auto wave = [](double a, double w, double p) { return [=](double f) { return a * std::sin(w * f + p); }; };
  c.channels = {
      chan(pos, 0.0f, 0.001, {0, 3, 7, 12, 20, 33, 47, 60}, [](double f) { return 2.0 * f + 5 * std::sin(f / 7); }),
      chan(pos, 0.4f, 0.001, {0, 5, 6, 21, 40, 60}, wave(3, 0.3, 0.5)),
      chan(lin, 0.0f, 0.001, {0, 10, 30, 60}, [](double f) { return -0.5 * f; }),
      chan(card, 0.0f, 0.01, {0, 8, 15, 30, 45, 60}, wave(20, 0.1, 0)),
      chan(card, 0.2f, 0.01, {0, 4, 9, 25, 60}, wave(10, 0.2, 1)),
      chan(card, 0.0f, 0.01, {0, 20, 40, 60}, [](double f) { return 3 * f; }),  // a full turn and more
      chan(card, 0.0f, 0.01, {0, 12, 24, 36, 48, 60}, wave(8, 0.15, 0.3)),
      chan(card, 0.0f, 0.01, {0, 60}, [](double) { return 0.0; }),  // at rest: no track
      chan(card, 0.0f, 0.01, {0, 6, 18, 30, 60}, wave(5, 0.25, 2)),
      chan(card, 0.0f, 0.01, {0, 10, 20, 30, 40, 50, 60}, wave(30, 0.12, 0)),
      chan(lin, 0.0f, 0.01, {0, 30, 60}, wave(15, 0.05, 0)),
      chan(card, -0.3f, 0.01, {0, 2, 5, 30, 59, 60}, wave(12, 0.3, 0)),
      chan(card, 0.0f, 0.01, {0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 50, 55, 60}, wave(60, 0.2, 0)),
      chan(card, 0.0f, 0.01, {0, 15, 30, 45, 60}, wave(45, 0.1, 1)),
      chan(card, 0.0f, 0.01, {0, 10, 60}, wave(20, 0.05, 0)),
      chan(card, 0.0f, 0.01, {0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 60}, wave(25, 0.4, 0)),
      chan(card, 0.6f, 0.01, {0, 30, 60}, wave(10, 0.1, 0)),
      chan(card, 0.0f, 0.01, {0, 60}, [](double f) { return 0.5 * f; }),
  };
  REQUIRE(c.channels.size() == c.skeleton.channel_count());
  c.notes = "tolerance_units=0.05\n";
  return c;
}

struct Glb {
  json doc;
  std::string bin;
};

uint32_t u32(const std::string& s, size_t at) {
  uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

// The GLB container per the glTF 2.0 specification, section 4.4.
Glb parse_glb(const std::string& glb) {
  REQUIRE(glb.size() >= 20);
  CHECK(u32(glb, 0) == 0x46546C67);
  CHECK(u32(glb, 4) == 2);
  CHECK(u32(glb, 8) == glb.size());
  const uint32_t json_len = u32(glb, 12);
  CHECK(json_len % 4 == 0);
  CHECK(u32(glb, 16) == 0x4E4F534A);
  Glb g;
  g.doc = json::parse(glb.substr(20, json_len));  // trailing padding spaces are JSON whitespace
  const size_t bin_at = 20 + size_t(json_len);
  if (bin_at < glb.size()) {
    const uint32_t bin_len = u32(glb, bin_at);
    CHECK(bin_len % 4 == 0);
    CHECK(u32(glb, bin_at + 4) == 0x004E4942);
    CHECK(bin_at + 8 + bin_len == glb.size());
    g.bin = glb.substr(bin_at + 8, bin_len);
  }
  return g;
}

std::vector<float> accessor(const Glb& g, int index, int* components = nullptr) {
  const json& a = g.doc["accessors"][index];
  const json& view = g.doc["bufferViews"][a["bufferView"].get<int>()];
  const std::string type = a["type"];
  const int k = type == "SCALAR" ? 1 : type == "VEC3" ? 3 : 4;
  if (components) *components = k;
  CHECK(a["componentType"] == 5126);
  const size_t count = a["count"].get<size_t>() * size_t(k);
  const size_t at = view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
  REQUIRE(at + 4 * count <= g.bin.size());
  std::vector<float> v(count);
  std::memcpy(v.data(), g.bin.data() + at, 4 * count);
  for (int c = 0; c < k; ++c) {  // min and max are those of the data
    float lo = v[size_t(c)], hi = lo;
    for (size_t i = size_t(c); i < count; i += size_t(k)) lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
    CHECK(a["min"][c].get<double>() == double(lo));
    CHECK(a["max"][c].get<double>() == double(hi));
  }
  return v;
}

// One animation sampler as the glTF 2.0 specification (appendix C) defines it.
struct Track {
  std::string interp;
  int k = 3;
  std::vector<float> t, v;

  // Value at time s; LINEAR rotations by slerp (nlerp: normalised lerp, as some players do).
  std::vector<double> at(double s, bool nlerp = false) const {
    const size_t n = t.size();
    const bool cubic = interp == "CUBICSPLINE";
    auto value = [&](size_t i, int c) { return double(v[(cubic ? 3 * i + 1 : i) * size_t(k) + size_t(c)]); };
    std::vector<double> out(static_cast<size_t>(k), 0.0);
    size_t i = 0;
    while (i + 1 < n && double(t[i + 1]) <= s) ++i;
    if (i + 1 >= n || s <= double(t[0])) {
      const size_t key = s <= double(t[0]) ? 0 : n - 1;
      for (int c = 0; c < k; ++c) out[size_t(c)] = value(key, c);
      return out;
    }
    const double td = double(t[i + 1]) - double(t[i]), u = (s - double(t[i])) / td;
    if (cubic) {
      for (int c = 0; c < k; ++c) {
        const double b = v[(3 * i + 2) * size_t(k) + size_t(c)], a = v[(3 * (i + 1)) * size_t(k) + size_t(c)];
        out[size_t(c)] = (2 * u * u * u - 3 * u * u + 1) * value(i, c) + td * (u * u * u - 2 * u * u + u) * b +
                         (-2 * u * u * u + 3 * u * u) * value(i + 1, c) + td * (u * u * u - u * u) * a;
      }
    } else if (k == 4 && !nlerp) {
      double d = 0;
      for (int c = 0; c < 4; ++c) d += value(i, c) * value(i + 1, c);
      const double sign = d < 0 ? -1 : 1, a = std::acos(std::min(1.0, std::fabs(d)));
      for (int c = 0; c < 4; ++c)
        out[size_t(c)] = a < 1e-12 ? value(i, c)
                                   : (std::sin(a * (1 - u)) * value(i, c) + sign * std::sin(a * u) * value(i + 1, c)) /
                                         std::sin(a);
    } else {
      for (int c = 0; c < k; ++c) out[size_t(c)] = (1 - u) * value(i, c) + u * value(i + 1, c);
    }
    if (k == 4) {
      const double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
      for (double& x : out) x /= len;
    }
    return out;
  }
};

// Tracks by node and path ("translation", "rotation").
std::map<std::pair<int, std::string>, Track> tracks(const Glb& g) {
  std::map<std::pair<int, std::string>, Track> out;
  REQUIRE(g.doc["animations"].size() == 1);
  const json& anim = g.doc["animations"][0];
  for (const json& ch : anim["channels"]) {
    const json& s = anim["samplers"][ch["sampler"].get<int>()];
    Track t;
    t.interp = s["interpolation"];
    t.t = accessor(g, s["input"], nullptr);
    t.v = accessor(g, s["output"], &t.k);
    CHECK(t.v.size() == t.t.size() * size_t(t.k) * (t.interp == "CUBICSPLINE" ? 3 : 1));
    out[{ch["target"]["node"].get<int>(), ch["target"]["path"].get<std::string>()}] = std::move(t);
  }
  return out;
}

Glb export_glb(const Clip& clip, const GltfOptions& o, GltfReport* report = nullptr) {
  const GltfOutput out = keyanim::offline::export_gltf(clip, o);
  if (report) *report = out.report;
  CHECK(out.bin.empty());
  return parse_glb(out.main);
}

// World positions of the nodes and the joints' shell points, glTF side: node TRS composed here.
std::vector<std::array<double, 3>> gltf_points(const Glb& g, const std::map<std::pair<int, std::string>, Track>& tr,
                                               double s, bool nlerp, double shell) {
  const json& nodes = g.doc["nodes"];
  const size_t n = g.doc["skins"][0]["joints"].size();  // the joints' nodes come first, the mesh node after
  std::vector<int> parent(n, -1);
  for (size_t j = 0; j < n; ++j)
    for (const json& c : nodes[j].value("children", json::array())) parent[c.get<size_t>()] = int(j);
  std::vector<std::array<double, 3>> pos(n);
  std::vector<std::array<double, 9>> rot(n);
  for (size_t j = 0; j < n; ++j) {
    std::vector<double> t = nodes[j].value("translation", std::vector<double>{0, 0, 0});
    std::vector<double> q{0, 0, 0, 1};
    if (auto it = tr.find({int(j), "translation"}); it != tr.end()) t = it->second.at(s, nlerp);
    if (auto it = tr.find({int(j), "rotation"}); it != tr.end()) q = it->second.at(s, nlerp);
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const std::array<double, 9> r{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                                  2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                                  2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    if (parent[j] < 0) {
      pos[j] = {t[0], t[1], t[2]};
      rot[j] = r;
      continue;
    }
    const auto& m = rot[size_t(parent[j])];
    const auto& p = pos[size_t(parent[j])];
    for (int a = 0; a < 3; ++a) pos[j][a] = p[a] + m[3 * a] * t[0] + m[3 * a + 1] * t[1] + m[3 * a + 2] * t[2];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) rot[j][3 * a + b] = m[3 * a] * r[b] + m[3 * a + 1] * r[3 + b] + m[3 * a + 2] * r[6 + b];
  }
  std::vector<std::array<double, 3>> out(pos);
  for (size_t j = 0; j < n; ++j)
    if (nodes[j].contains("children"))  // a joint (End Sites have no children here)
      for (int a = 0; a < 3; ++a) out.push_back({pos[j][0] + shell * rot[j][a], pos[j][1] + shell * rot[j][3 + a],
                                                 pos[j][2] + shell * rot[j][6 + a]});
  return out;
}

// The same points from the clip by keyanim's forward kinematics of its samples.
std::vector<std::array<double, 3>> clip_points(const Clip& clip, uint32_t f, double shell) {
  std::vector<float> row(clip.channel_count());
  REQUIRE(clip.sample(f, row) == keyanim::Status::ok);
  const std::vector<double> values(row.begin(), row.end());
  std::vector<keyanim::offline::Vec3> pos;
  std::vector<keyanim::offline::Mat3> rot;
  keyanim::offline::world_pose(clip.skeleton(), values.data(), pos, rot);
  std::vector<std::array<double, 3>> out(pos.begin(), pos.end());
  const auto& joints = clip.skeleton().joints;
  for (size_t j = 0; j < joints.size(); ++j)
    if (!joints[j].end_site)
      for (int a = 0; a < 3; ++a) out.push_back({pos[j][0] + shell * rot[j][a], pos[j][1] + shell * rot[j][3 + a],
                                                 pos[j][2] + shell * rot[j][6 + a]});
  return out;
}

}  // namespace

TEST_CASE("glTF translations are the clip's curves, between frames too") {
  for (TangentRule rule : {TangentRule::step_adjusted, TangentRule::uniform})
    for (bool linear : {false, true}) {
      CAPTURE(int(rule));
      CAPTURE(linear);
      const Clip clip = keyanim::offline::to_clip(test_clip(rule, linear));
      const Glb g = export_glb(clip, {});
      const auto tr = tracks(g);
      const Track& hips = tr.at({0, "translation"});
      CHECK(hips.interp == (linear ? "LINEAR" : "CUBICSPLINE"));
      // Keys: the union of the three axes' key frames, values bit for bit the decoder's.
      CHECK(hips.t.size() == 14);
      std::vector<float> row(clip.channel_count());
      for (size_t i = 0; i < hips.t.size(); ++i) {
        const double frame = double(hips.t[i]) * 30.0;
        REQUIRE(clip.sample(std::round(frame), row) == keyanim::Status::ok);
        for (int a = 0; a < 3; ++a) CHECK(hips.v[((linear ? 1 : 3) * i + (linear ? 0 : 1)) * 3 + size_t(a)] == row[size_t(a)]);
      }
      // Anywhere in between: float rounding of the stored numbers only.
      for (int k = 0; k <= 60 * 16; ++k) {
        const double x = k / 16.0;
        REQUIRE(clip.sample(x, row) == keyanim::Status::ok);
        const std::vector<double> v = hips.at(x / 30.0);
        for (int a = 0; a < 3; ++a) {
          CAPTURE(x);
          CHECK(std::fabs(v[size_t(a)] - row[size_t(a)]) <= 2e-5 * (1 + std::fabs(row[size_t(a)])));
        }
      }
      // Nodes without position channels keep their OFFSET and get no translation track.
      CHECK(tr.count({1, "translation"}) == 0);
      CHECK(g.doc["nodes"][1]["translation"] == json::array({0.0, 20.0, 0.0}));
    }
}

TEST_CASE("glTF rotations (and --linear translations) stay within the tolerance at every frame, as slerp or nlerp") {
  for (bool linear_only : {false, true})
    for (double tol : {0.05, 0.005, 0.5}) {
      CAPTURE(linear_only);
      CAPTURE(tol);
      const Clip clip = keyanim::offline::to_clip(test_clip(TangentRule::step_adjusted));
      GltfOptions o;
      o.tolerance = tol;
      o.linear_only = linear_only;
      GltfReport r;
      const Glb g = export_glb(clip, o, &r);
      CHECK(r.tolerance == tol);
      const double shell = 0.02 * keyanim::offline::skeleton_size(clip.skeleton());
      CHECK(r.shell_distance == doctest::Approx(shell).epsilon(1e-12));
      const auto tr = tracks(g);
      if (linear_only)
        for (const auto& [key, t] : tr) CHECK(t.interp == "LINEAR");
      double worst = 0;
      for (uint32_t f = 0; f < clip.frame_count(); ++f) {
        const auto want = clip_points(clip, f, shell);
        for (bool nlerp : {false, true}) {
          const auto got = gltf_points(g, tr, f * clip.frame_time(), nlerp, shell);
          REQUIRE(got.size() == want.size());
          for (size_t p = 0; p < got.size(); ++p)
            worst = std::max(worst, std::hypot(got[p][0] - want[p][0], got[p][1] - want[p][1], got[p][2] - want[p][2]));
        }
      }
      CHECK(worst <= tol);
      // The export reports what it reached (its player does not normalise slerp's result).
      CHECK(std::fabs(worst - r.max_error) <= 1e-6 * keyanim::offline::skeleton_size(clip.skeleton()));
      CHECK(r.linear_rotation_tracks + r.cubic_rotation_tracks == 5);
      CHECK(r.translation_tracks == 1);
    }
}

TEST_CASE("glTF asset: nodes, hierarchy, names, one animation, a packed buffer, and the same as .gltf with its .bin") {
  EncodedClip e = test_clip(TangentRule::step_adjusted);
  e.skeleton.joints[1].name = "Sp\"ine\\ \x01";    // escaped in JSON
  e.skeleton.joints[2].name = "Head \xff\xfe:1";    // not UTF-8: replaced by U+FFFD
  e.skeleton.joints[4].name = "Bra\xc3\xa7o";       // UTF-8 kept
  const Clip clip = keyanim::offline::to_clip(e);
  GltfOptions o;
  o.name = "walk";
  const Glb g = export_glb(clip, o);
  const json& nodes = g.doc["nodes"];
  REQUIRE(nodes.size() == 8);  // 7 joints and End Sites, then the bone mesh
  CHECK(nodes[1]["name"] == "Sp\"ine\\ \x01");
  CHECK(nodes[2]["name"] == "Head \xef\xbf\xbd\xef\xbf\xbd:1");
  CHECK(nodes[3]["name"] == "End Site of Head \xef\xbf\xbd\xef\xbf\xbd:1");  // as keyanim sample --world names it
  CHECK(nodes[4]["name"] == "Bra\xc3\xa7o");
  CHECK(nodes[0]["children"] == json::array({1}));
  CHECK(nodes[1]["children"] == json::array({2, 4}));
  CHECK(nodes[6]["translation"] == json::array({8.0, 0.0, 0.0}));
  CHECK_FALSE(nodes[6].contains("children"));
  CHECK(g.doc["scenes"][0]["nodes"] == json::array({0, 7}));
  CHECK(g.doc["asset"]["version"] == "2.0");
  CHECK(g.doc["animations"][0]["name"] == "walk");
  // One buffer, its views laid end to end (each 4-byte aligned), every accessor inside its view,
  // no byte left over but alignment padding.
  CHECK(g.doc["buffers"].size() == 1);
  CHECK(g.doc["buffers"][0]["byteLength"] == g.bin.size());
  CHECK_FALSE(g.doc["buffers"][0].contains("uri"));
  size_t end = 0;
  for (const json& v : g.doc["bufferViews"]) {
    CHECK(v.value("byteOffset", size_t(0)) == (end + 3) / 4 * 4);
    end = v.value("byteOffset", size_t(0)) + v["byteLength"].get<size_t>();
  }
  CHECK((end + 3) / 4 * 4 == g.bin.size());
  size_t bytes = 0;
  for (const json& a : g.doc["accessors"]) {
    const std::string type = a["type"];
    const size_t width = a["componentType"] == 5126 || a["componentType"] == 5125 ? 4 : a["componentType"] == 5123 ? 2 : 1;
    const size_t size = width * a["count"].get<size_t>() * (type == "SCALAR" ? 1 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16);
    CHECK(a.value("byteOffset", size_t(0)) + size <= g.doc["bufferViews"][a["bufferView"].get<size_t>()]["byteLength"]);
    bytes += size;
  }
  CHECK(bytes <= g.bin.size());
  CHECK(bytes + 3 * g.doc["bufferViews"].size() >= g.bin.size());
  // The same asset as .gltf + .bin.
  o.bin_uri = "walk data.bin";
  const GltfOutput split = keyanim::offline::export_gltf(clip, o);
  CHECK(split.bin == g.bin);
  json doc = json::parse(split.main);
  CHECK(doc["buffers"][0]["uri"] == "walk data.bin");
  doc["buffers"][0].erase("uri");
  CHECK(doc == g.doc);
}

TEST_CASE("glTF: joints at rest get no track, and an animation always spans the clip") {
  EncodedClip e = test_clip(TangentRule::step_adjusted);
  for (int c : {15, 16, 17}) e.channels[size_t(c)] = chan(Interpolation::cardinal, 0.0f, 1.0, {}, [](double) { return 0.0; });
  const auto tr = tracks(export_glb(keyanim::offline::to_clip(e), {}));
  CHECK(tr.count({5, "rotation"}) == 0);
  CHECK(tr.count({4, "rotation"}) == 1);
  for (const auto& [key, t] : tr) {
    CHECK(t.t.front() == 0.0f);
    CHECK(t.t.back() == float(60.0 / 30.0));
  }
  // A clip where nothing moves still carries one animation (a constant root translation).
  EncodedClip still = e;
  for (EncodedChannel& c : still.channels) c = chan(Interpolation::cardinal, 0.0f, 1.0, {}, [](double) { return 0.0; });
  still.skeleton.joints[0].offset = {0, 0, 0};
  const Glb g = export_glb(keyanim::offline::to_clip(still), {});
  const auto st = tracks(g);
  REQUIRE(st.size() == 1);
  CHECK(st.begin()->first == std::make_pair(0, std::string("translation")));
  CHECK(st.begin()->second.t == std::vector<float>{0.0f, 2.0f});
}

TEST_CASE("glTF --fps: LINEAR keys every 1/F s and one at the end, and a frame range starts at time 0") {
  const Clip clip = keyanim::offline::to_clip(test_clip(TangentRule::step_adjusted));
  GltfOptions o;
  o.fps = 7;  // 2 s: keys at 0, 1/7, ..., 14/7 = 2 (the end lands on a key)
  GltfReport r;
  auto tr = tracks(export_glb(clip, o, &r));
  for (const auto& [key, t] : tr) {
    CHECK(t.interp == "LINEAR");
    REQUIRE(t.t.size() == 15);
    for (size_t i = 0; i < t.t.size(); ++i) CHECK(t.t[i] == float(double(i) / 7.0));
  }
  CHECK(r.max_error > r.tolerance);  // 7 fps cannot follow this clip: reported, not bounded
  o.fps = 4.5;  // keys at 0 .. 8/4.5 = 1.78 s, then the end at 2 s
  tr = tracks(export_glb(clip, o));
  CHECK(tr.at({0, "translation"}).t.size() == 10);
  CHECK(tr.at({0, "translation"}).t.back() == 2.0f);
  // Frames 10 to 40: 1 s from time 0; the root's translation is the clip's from frame 10.
  GltfOptions range;
  range.first_frame = 10;
  range.last_frame = 40;
  tr = tracks(export_glb(clip, range, &r));
  const Track& hips = tr.at({0, "translation"});
  CHECK(hips.t.front() == 0.0f);
  CHECK(hips.t.back() == 1.0f);
  std::vector<float> row(clip.channel_count());
  for (double x : {10.0, 17.5, 33.25, 40.0}) {
    REQUIRE(clip.sample(x, row) == keyanim::Status::ok);
    CHECK(hips.at((x - 10) / 30.0)[0] == doctest::Approx(row[0]).epsilon(1e-5));
  }
  CHECK(r.worst_frame >= 10);
  CHECK(r.worst_frame <= 40);
}

TEST_CASE("glTF tolerance: the clip's own by default, else 0.05%, and refusals") {
  EncodedClip e = test_clip(TangentRule::step_adjusted);
  GltfReport r;
  export_glb(keyanim::offline::to_clip(e), {}, &r);
  CHECK(r.tolerance == 0.05);  // tolerance_units from the encoder notes
  e.notes.clear();
  const Clip clip = keyanim::offline::to_clip(e);
  export_glb(clip, {}, &r);
  const double size = keyanim::offline::skeleton_size(clip.skeleton());
  CHECK(r.tolerance == doctest::Approx(0.0005 * size).epsilon(1e-12));
  GltfOptions pct;
  pct.tolerance = 0.5;
  pct.tolerance_in_percent = true;
  export_glb(clip, pct, &r);
  CHECK(r.tolerance == doctest::Approx(0.005 * size).epsilon(1e-12));

  std::string error;
  auto refused = [&](GltfOptions o) {
    try {
      keyanim::offline::export_gltf(clip, o);
    } catch (const keyanim::offline::Error& refusal) {
      error = refusal.message();
      return !error.empty();
    }
    return false;
  };
  GltfOptions o;
  o.fps = -1;
  CHECK(refused(o));
  o = {};
  o.tolerance = std::nan("");
  CHECK(refused(o));
  o = {};
  o.first_frame = 30;
  o.last_frame = 20;
  CHECK(refused(o));
  o.first_frame = 0;
  o.last_frame = 61;
  CHECK(refused(o));
  o = {};
  o.tolerance = 1e-12;  // below float32 rounding
  CHECK(refused(o));
  CHECK(error.find("float32") != std::string::npos);
  o = {};
  o.fps = 1e9;  // 2e9 keys
  CHECK(refused(o));
}

TEST_CASE("glTF: a clip without frames has nodes and no animation, and one frame has one key") {
  EncodedClip e = test_clip(TangentRule::step_adjusted);
  e.frame_count = 1;
  for (EncodedChannel& c : e.channels)
    if (!c.frames.empty()) c.frames = {c.frames[0]}, c.q = {c.q[0]};
  const auto tr = tracks(export_glb(keyanim::offline::to_clip(e), {}));
  for (const auto& [key, t] : tr) CHECK(t.t == std::vector<float>{0.0f});
  e.frame_count = 0;
  for (EncodedChannel& c : e.channels) c.frames.clear(), c.q.clear();
  const Glb g = export_glb(keyanim::offline::to_clip(e), {});
  CHECK(g.doc["nodes"].size() == 8);  // and the skin: an armature without motion
  CHECK_FALSE(g.doc.contains("animations"));
  CHECK(g.doc["skins"].size() == 1);
  CHECK(g.doc["scenes"][0]["extras"]["keyanim"]["frame_count"] == 0);
}

namespace {

// An accessor of any component type, as numbers (normalized integers kept as stored).
std::vector<double> raw_accessor(const Glb& g, int index) {
  const json& a = g.doc["accessors"][index];
  const json& view = g.doc["bufferViews"][a["bufferView"].get<int>()];
  const std::string type = a["type"];
  const size_t k = type == "SCALAR" ? 1 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
  const int ct = a["componentType"];
  const size_t width = ct == 5126 || ct == 5125 ? 4 : ct == 5123 ? 2 : 1;
  const size_t at = view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0));
  const size_t count = a["count"].get<size_t>() * k;
  REQUIRE(at + width * count <= g.bin.size());
  std::vector<double> v(count);
  for (size_t i = 0; i < count; ++i) {
    uint32_t u = 0;
    std::memcpy(&u, g.bin.data() + at + width * i, width);  // little-endian host, as the tests run
    float f;
    std::memcpy(&f, &u, 4);
    v[i] = ct == 5126 ? double(f) : double(u);
  }
  return v;
}

}  // namespace

TEST_CASE("glTF skin: every node a joint, inverse bind matrices of the rest pose, a bone mesh, the timing in extras") {
  const Clip clip = keyanim::offline::to_clip(test_clip(TangentRule::step_adjusted));
  GltfOptions o;
  o.name = "walk";
  const Glb g = export_glb(clip, o);
  const auto& joints = clip.skeleton().joints;
  const json& skin = g.doc["skins"][0];
  CHECK(skin["name"] == "walk");
  CHECK(skin["skeleton"] == 0);
  REQUIRE(skin["joints"].size() == joints.size());
  for (size_t j = 0; j < joints.size(); ++j) CHECK(skin["joints"][j] == j);
  // Rest world positions by adding OFFSETs down the hierarchy: the inverse bind matrix of each
  // node is the translation by minus that, column-major.
  std::vector<std::array<double, 3>> rest(joints.size());
  for (size_t j = 0; j < joints.size(); ++j)
    for (int a = 0; a < 3; ++a) rest[j][a] = (joints[j].parent < 0 ? 0.0 : rest[size_t(joints[j].parent)][a]) + joints[j].offset[a];
  const std::vector<double> ibm = raw_accessor(g, skin["inverseBindMatrices"]);
  REQUIRE(ibm.size() == 16 * joints.size());
  for (size_t j = 0; j < joints.size(); ++j)
    for (int c = 0; c < 16; ++c) {
      const double want = c >= 12 && c < 15 ? -rest[j][c - 12] : c % 5 == 0 ? 1.0 : 0.0;
      CHECK(ibm[16 * j + size_t(c)] == double(float(want)));
    }
  // The mesh node: a scene root without a transform, after the joints.
  const json& node = g.doc["nodes"][joints.size()];
  CHECK(node["mesh"] == 0);
  CHECK(node["skin"] == 0);
  CHECK_FALSE(node.contains("translation"));
  CHECK_FALSE(node.contains("children"));
  // Every vertex follows one joint with weight 1; each bone of 5 vertices runs from its parent's
  // rest position (head, ring: the parent) to its node's (tail: the node itself).
  const json& prim = g.doc["meshes"][0]["primitives"][0];
  const std::vector<double> pos = raw_accessor(g, prim["attributes"]["POSITION"]);
  const std::vector<double> jw = raw_accessor(g, prim["attributes"]["JOINTS_0"]);
  const std::vector<double> ww = raw_accessor(g, prim["attributes"]["WEIGHTS_0"]);
  const std::vector<double> idx = raw_accessor(g, prim["indices"]);
  CHECK(g.doc["accessors"][prim["attributes"]["WEIGHTS_0"].get<int>()]["normalized"] == true);
  size_t segments = 0;
  for (size_t j = 1; j < joints.size(); ++j) segments += joints[j].offset != std::array<double, 3>{0, 0, 0};
  REQUIRE(pos.size() == 15 * segments);
  REQUIRE(idx.size() == 18 * segments);
  for (size_t v = 0; v < pos.size() / 3; ++v) {
    CHECK(ww[4 * v] == 255);
    CHECK(ww[4 * v + 1] + ww[4 * v + 2] + ww[4 * v + 3] == 0);
  }
  size_t bone = 0;
  for (size_t n = 1; n < joints.size(); ++n) {
    if (joints[n].offset == std::array<double, 3>{0, 0, 0}) continue;
    const size_t p = size_t(joints[n].parent), head = 5 * bone, tail = head + 1;
    CHECK(jw[4 * head] == p);
    CHECK(jw[4 * tail] == n);
    for (size_t r = head + 2; r < head + 5; ++r) CHECK(jw[4 * r] == p);
    for (int a = 0; a < 3; ++a) {
      CHECK(pos[3 * head + size_t(a)] == double(float(rest[p][a])));
      CHECK(pos[3 * tail + size_t(a)] == double(float(rest[n][a])));
    }
    ++bone;
  }
  for (double i : idx) CHECK(i < double(pos.size() / 3));
  // The frame rate and range in the scene's, the animation's and the asset's extras.
  for (const json* extras : {&g.doc["scenes"][0]["extras"], &g.doc["animations"][0]["extras"], &g.doc["asset"]["extras"]}) {
    const json& k = (*extras)["keyanim"];
    CHECK(k["fps"].get<double>() == doctest::Approx(30.0).epsilon(1e-12));
    CHECK(k["first_frame"] == 0);
    CHECK(k["last_frame"] == 60);
    CHECK(k["frame_count"] == 61);
  }
  // Without the mesh: the skin alone, no mesh node.
  o.bone_mesh = false;
  const Glb bare = export_glb(clip, o);
  CHECK(bare.doc["nodes"].size() == joints.size());
  CHECK_FALSE(bare.doc.contains("meshes"));
  CHECK(bare.doc["skins"][0]["joints"].size() == joints.size());
  CHECK(bare.doc["scenes"][0]["nodes"] == json::array({0}));
}
