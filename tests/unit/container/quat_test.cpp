// Rotations stored as quaternions (version 5, spec/FORMAT.md section 4.7): the container, both
// profiles, the shared key frames of a node's x, y, z, and the rotation and Euler angles made
// from them, each checked against an independent computation.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "clips.h"
#include "crafted.h"
#include "keyanim/offline/fk.h"
#include "internal/quat_layout.h"
#include "keyanim/rotation.h"
#include "runtime/image.h"

using namespace container_test;
using keyanim::QuatNode;
using keyanim::Transform;

namespace {

// The rotation angle between unit quaternions a and b (either sign), in radians: 4 asin of half
// the chord, which keeps its digits for small angles (2 acos of the dot product does not).
double angle_between(const double (&a)[4], const double (&b)[4]) {
  const double sign = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] < 0.0 ? -1.0 : 1.0;
  double chord = 0.0;
  for (int k = 0; k < 4; ++k) chord += (a[k] - sign * b[k]) * (a[k] - sign * b[k]);
  return 4.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(chord)));
}

// R = R_axes[0](deg[0]) R_axes[1](deg[1]) R_axes[2](deg[2]) as a quaternion, by the offline FK's
// axis quaternions (not by the code under test).
void compose(const uint8_t (&axes)[3], const double (&deg)[3], double (&q)[4]) {
  keyanim::offline::Quat r{0, 0, 0, 1};
  for (int k = 0; k < 3; ++k) r = keyanim::offline::quat_multiply(r, keyanim::offline::axis_quaternion(axes[k], deg[k]));
  for (int k = 0; k < 4; ++k) q[k] = r[k];
}

std::vector<uint8_t> aligned_copy(const std::vector<uint8_t>& bytes, std::vector<uint64_t>& words) {
  words.assign((bytes.size() + 7) / 8, 0);
  std::memcpy(words.data(), bytes.data(), bytes.size());
  return bytes;
}

}  // namespace

TEST_SUITE("container") {

TEST_CASE("Euler angles of a quaternion recompose to it, for every axis order, and stay continuous") {
  const uint8_t orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  uint64_t s = 42;
  for (const auto& axes : orders) {
    CAPTURE(int(axes[0]) * 100 + int(axes[1]) * 10 + int(axes[2]));
    for (int i = 0; i < 2000; ++i) {
      // Random angles, a fifth of them at or next to gimbal lock.
      double in[3];
      for (double& a : in) a = double(lcg(s) % 3600000) / 10000.0 - 180.0;
      if (i % 5 == 0) in[1] = (i % 10 == 0 ? 90.0 : -90.0) + (i % 3 == 0 ? 0.0 : 1e-9 * double(i % 7));
      double q[4], deg[3], back[4];
      compose(axes, in, q);
      keyanim::euler_from_quaternion(q, axes, deg);
      CHECK(deg[1] >= -90.0);
      CHECK(deg[1] <= 90.0);
      compose(axes, deg, back);
      CHECK(angle_between(q, back) < 1e-9);
      // Near the previous frame's angles, the nearest solution is within a small step of them.
      double near[3] = {in[0] + 0.5, in[1] + 0.25, in[2] - 0.5};
      double moved[3] = {deg[0], deg[1], deg[2]};
      keyanim::nearest_euler(near, moved);
      compose(axes, moved, back);
      CHECK(angle_between(q, back) < 1e-9);
      if (std::fabs(std::fabs(in[1]) - 90.0) > 1.0)  // away from gimbal lock: the input itself
        for (int k = 0; k < 3; ++k) CHECK(std::fabs(moved[k] - in[k]) < 1e-6);
    }
  }
}

TEST_CASE("quaternion nodes round-trip through the archive and runtime profiles of version 5") {
  const std::vector<EncodedClip> clips = {random_quat_clip(1, 500, 8), random_quat_clip(2, 301, 9, true),
                                          random_quat_clip(3, 2, 3), random_quat_clip(4, 5000, 6),
                                          random_quat_clip(5, 64, 5, true)};
  for (const EncodedClip& e : clips) {
    CAPTURE(e.frame_count);
    REQUIRE_NOTHROW(keyanim::offline::validate_encoded_clip(e));
    const std::vector<uint8_t> bytes = keyanim::offline::write_kanim(e);
    const Loaded l = load(bytes);
    REQUIRE_MESSAGE(l.status == Status::ok, l.err.section << " " << l.err.detail);
    CHECK(l.clip.version_major() == keyanim::kQuatFormatVersionMajor);
    REQUIRE(l.clip.quat_node_count() == e.quat_nodes.size());
    for (uint32_t i = 0; i < e.quat_nodes.size(); ++i) {
      const QuatNode n = l.clip.quat_node(i);
      CHECK(n.node == e.quat_nodes[i].node);
      CHECK(n.reference[0] == e.quat_nodes[i].reference[0]);
      CHECK(n.reference[1] == e.quat_nodes[i].reference[1]);
      CHECK(n.reference[2] == e.quat_nodes[i].reference[2]);
      const uint32_t x = l.clip.skeleton().joints[n.node].first_channel + (n.node == 0 ? 3 : 0);
      CHECK(l.clip.channel(x).stored == keyanim::StoredAs::quat_x);
      CHECK(l.clip.channel(x + 1).stored == keyanim::StoredAs::quat_y);
      CHECK(l.clip.channel(x + 2).stored == keyanim::StoredAs::quat_z);
    }
    const Clip ref = keyanim::offline::to_clip(e);
    check_same_clip(l.clip, ref);
    check_same_samples(l.clip, ref);
    // The runtime profile, loaded and viewed where it lies, samples the same bits, and converts
    // back to the very bytes of the archive file.
    const std::vector<uint8_t> runtime = keyanim::offline::write_kanim_runtime(l.clip);
    std::vector<uint64_t> words;
    aligned_copy(runtime, words);
    const std::span<const uint8_t> in_place(reinterpret_cast<const uint8_t*>(words.data()), runtime.size());
    keyanim::DecodeLimits check;
    check.check_content = true;
    Clip loaded, viewed;
    ErrorInfo err;
    REQUIRE_MESSAGE(Clip::load(runtime, loaded, &err, check) == Status::ok, err.section << " " << err.detail);
    REQUIRE_MESSAGE(Clip::view(in_place, viewed, &err, check) == Status::ok, err.section << " " << err.detail);
    CHECK(viewed.version_major() == keyanim::kQuatFormatVersionMajor);
    check_same_clip(viewed, ref);
    check_same_samples(viewed, ref);
    check_same_samples(loaded, viewed);
    // (A single key comes back as q = +-1, step = |value|: spec section 9.3.)
    CHECK(keyanim::offline::write_kanim(keyanim::offline::encoded_clip(viewed)) ==
          keyanim::offline::write_kanim(keyanim::offline::encoded_clip(l.clip)));
  }
}

TEST_CASE("a quaternion node's pose is its reference times (x, y, z, w), and its channels its Euler angles") {
  const EncodedClip e = random_quat_clip(7, 300, 12, true);
  const Clip clip = keyanim::offline::to_clip(e);
  const uint32_t n = clip.channel_count();
  std::vector<float> stored(n), angles(n);
  std::vector<Transform> local(clip.skeleton().joints.size()), played(local.size());
  keyanim::Cursor cursor;
  REQUIRE(cursor.prepare(clip) == Status::ok);
  double worst_pose = 0.0, worst_angles = 0.0;
  for (double x = 0.0; x < 300.0; x += 0.37) {
    REQUIRE(clip.sample_stored(x, stored) == Status::ok);
    REQUIRE(clip.sample(x, angles) == Status::ok);
    REQUIRE(clip.sample_local(x, local) == Status::ok);
    REQUIRE(clip.sample_local(x, played, &cursor) == Status::ok);
    CHECK(std::memcmp(local.data(), played.data(), local.size() * sizeof(Transform)) == 0);
    for (const QuatNode& qn : e.quat_nodes) {
      const keyanim::Joint& j = clip.skeleton().joints[qn.node];
      const uint32_t c = j.first_channel;  // joints past the root: rotations only
      // Independently: w rebuilt, the Hamilton product written out, normalized.
      const double v[3] = {stored[c], stored[c + 1], stored[c + 2]};
      const double w = std::sqrt(std::max(0.0, 1.0 - v[0] * v[0] - v[1] * v[1] - v[2] * v[2]));
      // The reference: x, y, z in units of 2^-15, w rebuilt.
      const double rx = qn.reference[0] / 32768.0, ry = qn.reference[1] / 32768.0, rz = qn.reference[2] / 32768.0;
      const double r[4] = {rx, ry, rz, std::sqrt(1.0 - rx * rx - ry * ry - rz * rz)};
      double q[4] = {r[3] * v[0] + r[0] * w + r[1] * v[2] - r[2] * v[1], r[3] * v[1] - r[0] * v[2] + r[1] * w + r[2] * v[0],
                     r[3] * v[2] + r[0] * v[1] - r[1] * v[0] + r[2] * w, r[3] * w - r[0] * v[0] - r[1] * v[1] - r[2] * v[2]};
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      for (double& k : q) k /= norm;
      // The pose's binary32 arithmetic, whichever path (a track's or a curve's) computed it.
      float ref32[4], q32[4];
      keyanim::reference_of(qn, ref32);
      keyanim::stored_rotation<float>(ref32, stored[c], stored[c + 1], stored[c + 2], q32,
                                      [](float a) { return std::sqrt(a); }, [](float a) { return std::max(a, 0.0f); });
      CHECK(std::memcmp(q32, local[qn.node].rotation, sizeof q32) == 0);
      const double got[4] = {local[qn.node].rotation[0], local[qn.node].rotation[1], local[qn.node].rotation[2],
                             local[qn.node].rotation[3]};
      worst_pose = std::max(worst_pose, angle_between(q, got));
      const uint8_t axes[3] = {uint8_t(keyanim::channel_axis(j.channels[0])), uint8_t(keyanim::channel_axis(j.channels[1])),
                               uint8_t(keyanim::channel_axis(j.channels[2]))};
      const double deg[3] = {angles[c], angles[c + 1], angles[c + 2]};
      // sample()'s angles are Appendix B's from the node's own reference (the clip's QUAT entry,
      // not the image's binary32 copy of it), bit for bit.
      double exact_q[4], exact_deg[3];
      keyanim::stored_rotation(qn, stored[c], stored[c + 1], stored[c + 2], exact_q);
      keyanim::euler_from_quaternion(exact_q, axes, exact_deg);
      for (int k = 0; k < 3; ++k) CHECK(angles[c + k] == float(exact_deg[k]));
      double back[4];
      compose(axes, deg, back);
      worst_angles = std::max(worst_angles, angle_between(q, back));
    }
  }
  CHECK(worst_pose < 2e-6);    // binary32 arithmetic
  CHECK(worst_angles < 2e-6);  // angles rounded to binary32 degrees
  CHECK(worst_angles > 0.0);
}

// A Cursor moves a quaternion track's three streams together and gives its three states one
// range (cursor.cpp); sample_local with a cursor builds the tracks' rotations from the curves'
// values, not from the channels. Each must give the plain sampler's bits: forward steps,
// backward sweeps, far jumps (inside, before and after the keys), a cursor shared by every
// method, on clips with and without an Euler root.
TEST_CASE("a cursor plays quaternion tracks as the plain sampler does, bit for bit") {
  for (const EncodedClip& e : {random_quat_clip(11, 700, 12), random_quat_clip(12, 900, 13, true)}) {
    const Clip clip = keyanim::offline::to_clip(e);
    const uint32_t n = clip.channel_count(), nodes = uint32_t(clip.skeleton().joints.size());
    std::vector<float> a(n), b(n);
    std::vector<Transform> p(nodes), q(nodes);
    keyanim::Cursor cursor;
    REQUIRE(cursor.prepare(clip) == Status::ok);
    uint64_t s = 17, mismatches = 0;
    const double F = e.frame_count;
    for (int i = 0; i < 3000; ++i) {
      const double x = i < 1000 ? i * 0.73 - 2.0 : i < 2000 ? F + 1.0 - (i - 1000) * 0.61 : double(lcg(s) % 100000) / 100000.0 * (F + 20.0) - 10.0;
      switch (i % 4) {
        case 0:
          REQUIRE(clip.sample(x, a) == Status::ok);
          REQUIRE(clip.sample(x, b, &cursor) == Status::ok);
          break;
        case 1:
          REQUIRE(clip.sample_stored(x, a) == Status::ok);
          REQUIRE(clip.sample_stored(x, b, &cursor) == Status::ok);
          break;
        case 2:
          REQUIRE(clip.sample_local(x, p) == Status::ok);
          REQUIRE(clip.sample_local(x, q, &cursor) == Status::ok);
          break;
        default:
          REQUIRE(clip.sample_model(x, p) == Status::ok);
          REQUIRE(clip.sample_model(x, q, &cursor) == Status::ok);
      }
      for (uint32_t c = 0; c < n; ++c) mismatches += !same_bits(a[c], b[c]);
      mismatches += std::memcmp(p.data(), q.data(), nodes * sizeof(Transform)) != 0;
    }
    CHECK(mismatches == 0);
  }
}

// A track whose y keys are +0, -0, +0, -0 (q of both signs times a step that rounds them to
// zero): at those key frames the polynomial would give +0 for -0, so the cursor must make the
// track's key frame a direct state for its three curves, not for y alone: their states share
// one range, checked on x's lanes only (a y of its own range would keep its key's value past
// the key frame), and x and z still give their own values there.
TEST_CASE("a cursor gives a quaternion track's key values at its key frames when its y's is -0") {
  EncodedClip e;
  e.skeleton.joints.push_back(node("root", -1, 0, 0, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}));
  e.skeleton.joints.push_back(node("end", 0, 0, 1, 0, {}, true));
  e.frame_count = 40;
  e.frame_time = 1.0 / 30.0;
  e.tangent_rule = TangentRule::step_adjusted;
  e.quat_nodes = {QuatNode{0, {0, 0, 0}}};
  const int64_t q[3][4] = {{3, -3, 3, -3}, {1, -1, 2, -3}, {1, 2, 3, 4}};
  const double step[3] = {0.1, 1e-300, 0.05};
  for (int c = 0; c < 3; ++c) {
    EncodedChannel ch;
    ch.interp = kCard;
    ch.tension = 0.0f;
    ch.step = step[c];
    ch.frames = {0, 10, 25, 39};
    ch.q.assign(q[c], q[c] + 4);
    e.channels.push_back(std::move(ch));
  }
  const Clip clip = keyanim::offline::to_clip(e);
  std::vector<float> a(3), b(3);
  std::vector<Transform> p(2), r(2);
  keyanim::Cursor cursor;
  REQUIRE(cursor.prepare(clip) == Status::ok);
  uint64_t mismatches = 0, minus_zero = 0;
  for (double x = 0.0; x <= 39.0; x += 0.5) {
    REQUIRE(clip.sample_stored(x, a) == Status::ok);
    REQUIRE(clip.sample_stored(x, b, &cursor) == Status::ok);
    for (int c = 0; c < 3; ++c) mismatches += !same_bits(a[c], b[c]);
    minus_zero += (x == 10.0 || x == 39.0) && same_bits(b[1], -0.0f);
    REQUIRE(clip.sample_local(x, p) == Status::ok);
    REQUIRE(clip.sample_local(x, r, &cursor) == Status::ok);
    mismatches += std::memcmp(p.data(), r.data(), sizeof(Transform)) != 0;
  }
  CHECK(mismatches == 0);
  CHECK(minus_zero == 2);  // the test reaches the case
  REQUIRE(clip.sample_stored(25.0, b, &cursor) == Status::ok);
  CHECK(b[0] == 0.3f);
  CHECK(b[2] == 0.15f);
}

TEST_CASE("quat_in_node_order is the merge of the tracks' and the others' node lists") {
  // Every split of node sets drawn from 0..11 into tracks and others, each group increasing:
  // the binary search against the two lists merged by hand.
  std::mt19937 rng(5);
  for (int round = 0; round < 2000; ++round) {
    std::vector<uint32_t> tracks, others;
    for (uint32_t node = 0; node < 12; ++node) {
      const uint32_t where = static_cast<uint32_t>(rng() % 3);  // 0: not a quaternion node
      if (where == 1) tracks.push_back(node);
      if (where == 2) others.push_back(node);
    }
    std::vector<uint32_t> nodes = tracks;
    nodes.insert(nodes.end(), others.begin(), others.end());
    keyanim::internal::Image img;
    img.quat_node = nodes;
    img.quat_tracks = static_cast<uint32_t>(tracks.size());
    std::vector<uint32_t> merged = nodes;
    std::sort(merged.begin(), merged.end());
    for (uint32_t i = 0; i < merged.size(); ++i) {
      CAPTURE(round);
      CAPTURE(i);
      CHECK(nodes[keyanim::internal::quat_in_node_order(img, i)] == merged[i]);
    }
  }
}

TEST_CASE("the writer refuses quaternion nodes that break section 4.7") {
  using keyanim::offline::validate_encoded_clip;
  auto refused = [](EncodedClip e, const char* why) {
    CAPTURE(why);
    CHECK_THROWS(validate_encoded_clip(e));
  };
  const EncodedClip good = random_quat_clip(9, 100, 4);
  REQUIRE_NOTHROW(validate_encoded_clip(good));
  EncodedClip e = good;
  e.quat_nodes[1].reference[0] = e.quat_nodes[1].reference[1] = e.quat_nodes[1].reference[2] = 20000;
  refused(e, "reference beyond the unit ball");
  e = good;
  std::swap(e.quat_nodes[0], e.quat_nodes[1]);
  refused(e, "nodes not increasing");
  e = good;
  e.quat_nodes.push_back({4, {0, 0, 0}});  // the End Site
  refused(e, "a node without rotation channels");
  e = good;
  const uint32_t c = e.skeleton.joints[1].first_channel;
  e.channels[c + 1].frames.back() -= 1;
  refused(e, "y's key frames differ from x's");
  e = good;
  e.channels[c + 2].interp = e.channels[c].interp == kLin ? kCard : kLin;
  refused(e, "z's interpolation differs");
  e = good;
  for (int64_t& q : e.channels[c + 1].q) q = q == 0 ? 0 : q > 0 ? 17 : -17;
  e.channels[c + 1].step = 1.0;
  REQUIRE(std::any_of(e.channels[c + 1].q.begin(), e.channels[c + 1].q.end(), [](int64_t q) { return q != 0; }));
  refused(e, "a stored y beyond +-16");
}

TEST_CASE("the loader refuses a quaternion node's stored value beyond +-16 (section 4.7), and takes 16") {
  // The file crafted past the writer (which refuses it, above): an uncompressed file whose x
  // channel of a quaternion node has its Step scaled so that its largest key is 16, then 16.5.
  const EncodedClip e = random_quat_clip(9, 100, 4);
  const uint32_t c = e.skeleton.joints[1].first_channel;
  REQUIRE(keyanim::internal::stored_kinds(e.skeleton, e.quat_nodes)[c] == keyanim::internal::Stored::quat_x);
  int64_t top = 0;
  for (int64_t q : e.channels[c].q) top = std::max<int64_t>(top, q < 0 ? -q : q);
  REQUIRE(top > 0);
  const RawFile base = split(keyanim::offline::write_kanim(e, 0));
  const size_t channels = e.channels.size();
  for (const double bound : {16.0, 16.5}) {
    CAPTURE(bound);
    RawFile r = base;
    RawSection& chan = r.get("CHAN");
    REQUIRE(chan.flags == 0);
    poke(chan.stored, 5 * channels + 8 * c, bound / double(top));  // Step of channel c (4.3)
    const Loaded l = load(r.build());
    if (bound <= 16.0) {
      REQUIRE(l.status == Status::ok);
      const auto keys = keyanim::test::channel_keys(l.clip, c);
      float most = 0.0f;
      for (float v : keys.values) most = std::max(most, std::fabs(v));
      CHECK(most == 16.0f);
    } else {
      CHECK(l.status == Status::corrupt);
      CHECK(l.err.section == "KVAL");
      CHECK(l.err.detail.find("channel " + std::to_string(c)) != std::string::npos);
      CHECK(l.err.detail.find("16") != std::string::npos);
    }
  }
}

}  // TEST_SUITE
