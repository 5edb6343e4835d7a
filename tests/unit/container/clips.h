// Hand-built clips for the container tests (the test vectors are made from the first five:
// never change them), a pseudo-random clip generator, and field-by-field comparisons of loaded
// clips. Shared by the tests in tests/unit/container/.
#pragma once
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

namespace container_test {

using keyanim::ChannelType;
using keyanim::Clip;
using keyanim::ErrorInfo;
using keyanim::Interpolation;
using keyanim::Joint;
using keyanim::Status;
using keyanim::TangentRule;
using keyanim::offline::EncodedChannel;
using keyanim::offline::EncodedClip;

// ---------------------------------------------------------------------------------------------
// Hand-built clips. The test vectors are made from the first five: never change them.

inline Joint node(const char* name, int32_t parent, double x, double y, double z, std::vector<ChannelType> ch,
           bool end_site = false) {
  Joint j;
  j.name = name;
  j.parent = parent;
  j.offset = {x, y, z};
  j.channels = std::move(ch);
  j.end_site = end_site;
  return j;
}

inline EncodedChannel chan(Interpolation interp, float tension, double step, std::vector<uint32_t> frames,
                    std::vector<int64_t> q) {
  EncodedChannel c;
  c.interp = interp;
  c.tension = tension;
  c.step = step;
  c.frames = std::move(frames);
  c.q = std::move(q);
  return c;
}

constexpr auto kCard = Interpolation::cardinal;
constexpr auto kLin = Interpolation::linear;
using CT = ChannelType;

// Step-adjusted rule, uneven spacing, tensions, linear, zero, constant and 2-key channels,
// position channels, a named End Site.
inline EncodedClip vector_rules() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Hips", -1, 0, 0, 0, {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Chest", 0, 0, 10.5, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Head_end", 1, 0, 5.25, 0.125, {}, true),
      node("LeftLeg", 0, 3, -2, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("", 3, 0, -8, 0, {}, true),
  };
  c.frame_count = 20;
  c.frame_time = 1.0 / 30.0;
  c.tangent_rule = TangentRule::step_adjusted;
  std::vector<uint32_t> all(20);
  std::vector<int64_t> dense(20);
  for (uint32_t i = 0; i < 20; ++i) {
    all[i] = i;
    dense[i] = int64_t(i * i) - 7 * int64_t(i);
  }
  c.channels = {
      chan(kCard, 0.0f, 0.01, {0, 3, 4, 10, 19}, {0, 150, 170, -30, 20}),
      chan(kLin, 0.0f, 0.01, {0, 7, 19}, {1000, 1200, 900}),
      chan(kCard, 0.0f, 1.0, {}, {}),
      chan(kCard, 0.0f, 0.1, {5}, {123}),
      chan(kCard, 0.3f, 0.5, {2, 15}, {-10, 40}),
      chan(kCard, -0.5f, 0.25, {0, 1, 2, 6, 12, 19}, {4, -4, 9, 30, 2, -17}),
      chan(kCard, 1.0f, 0.1, {0, 5, 10, 15, 19}, {0, 300, -200, 100, 50}),
      chan(kCard, 0.75f, 0.05, {0, 2, 9, 19}, {-100, 40, 900, 0}),
      chan(kCard, 0.0f, 0.2, {4, 8, 16}, {10, -10, 25}),
      chan(kCard, 0.0f, 0.125, all, dense),
      chan(kLin, 0.0f, 0.5, {0, 19}, {-7, 7}),
      chan(kCard, 0.25f, 1e-3, {0, 10}, {123456, -654321}),
  };
  return c;
}

// Uniform rule, two roots, keys not at the first or last frame, negative values.
inline EncodedClip vector_uniform() {
  EncodedClip c;
  c.skeleton.joints = {
      node("A", -1, 1, 2, 3, {CT::x_position, CT::y_rotation}),
      node("", 0, 0, 1, 0, {}, true),
      node("B", -1, -1, 0, 0.5, {CT::x_rotation, CT::z_rotation}),
      node("B1", 2, 0, 2, 0, {CT::y_rotation}),
      node("", 3, 0, 1, 0, {}, true),
  };
  c.frame_count = 12;
  c.frame_time = 0.0083333;
  c.tangent_rule = TangentRule::uniform;
  c.channels = {
      chan(kCard, 0.0f, 0.001, {1, 4, 5, 9}, {-5000, -2500, -2600, 100}),
      chan(kCard, 0.5f, 0.01, {0, 2, 4, 6, 8, 10, 11}, {0, -18000, -36000, -54000, -36000, -36500, -36400}),
      chan(kCard, -1.0f, 0.1, {3, 4, 10}, {-1, 1, -3}),
      chan(kLin, 0.0f, 0.1, {2, 8}, {-50, -20}),
      chan(kCard, 0.0f, 0.05, {0, 11}, {9, -9}),
  };
  return c;
}

// One frame, Frame_Time 0, notes.
inline EncodedClip vector_single() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Root", -1, 0, 0, 0, {CT::y_position, CT::x_rotation, CT::z_rotation}),
      node("Tip", 0, 0, 0, 4, {}, true),
  };
  c.frame_count = 1;
  c.frame_time = 0.0;
  c.tangent_rule = TangentRule::step_adjusted;
  c.channels = {
      chan(kCard, 0.0f, 0.001, {0}, {95250}),
      chan(kCard, 0.0f, 0.01, {}, {}),
      chan(kLin, 0.0f, 0.01, {0}, {-18000}),
  };
  c.notes = "encoder=test-vectors\nmode=manual\n";
  return c;
}

// Long enough that zstd shrinks the key sections: compressed KTIM/KVAL/NOTE for readers.
inline EncodedClip vector_long() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Pelvis", -1, 0, 90, 0, {CT::x_position, CT::y_position, CT::z_position, CT::y_rotation}),
      node("Spine", 0, 0, 12, 0, {CT::z_rotation, CT::y_rotation, CT::x_rotation}),
      node("", 1, 0, 20, 0, {}, true),
  };
  c.frame_count = 240;
  c.frame_time = 1.0 / 120.0;
  c.tangent_rule = TangentRule::step_adjusted;
  const uint32_t gaps[5] = {1, 2, 3, 5, 8};
  for (uint32_t ch = 0; ch < 7; ++ch) {
    EncodedChannel e;
    e.interp = ch == 3 ? kLin : kCard;
    e.tension = ch == 5 ? 0.2f : 0.0f;
    e.step = 0.001;
    uint32_t f = 0;
    for (uint32_t i = 0;; ++i) {
      e.frames.push_back(f);
      // A smooth integer-valued curve, so that the file does not depend on any libm.
      const int64_t x = int64_t(f) - 120;
      e.q.push_back((int64_t(ch) + 1) * (x * x * 3 - 40 * x) + int64_t(ch) * 1000);
      if (f == 239) break;
      const uint32_t gap = ch % 2 == 0 ? 4 : gaps[i % 5];
      f = f + gap > 239 ? 239 : f + gap;
    }
    c.channels.push_back(std::move(e));
  }
  std::string notes;
  for (int i = 0; i < 12; ++i) notes += "note" + std::to_string(i) + "=the same words again and again\n";
  c.notes = notes;
  return c;
}

// Version 2.0's value prediction (spec 4.5): ramps the extrapolation predicts exactly, halves
// rounded up for positive and negative deltas, a gap of 2^16 frames or more and deltas of 2^40
// or more (both fall back to repeating the delta), and a noisy channel that stays delta-coded.
inline EncodedClip vector_predict() {
  EncodedClip c;
  c.skeleton.joints = {node("Root", -1, 0, 0, 0, {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation}),
                       node("Tip", 0, 0, 1, 0, {CT::x_rotation}, false)};
  c.frame_count = 70001;
  c.frame_time = 1.0 / 30.0;
  c.tangent_rule = TangentRule::step_adjusted;
  std::vector<uint32_t> far = {0, 100, 200, 300, 400, 500, 600, 700, 800, 900, 1000, 67000, 67100, 70000};
  std::vector<int64_t> ramp;
  for (uint32_t f : far) ramp.push_back(40 * int64_t(f));
  c.channels.push_back(chan(kCard, 0.0f, 0.01, far, ramp));
  std::vector<uint32_t> tight = {0, 1, 3, 4, 6, 7, 9, 10, 12};
  std::vector<int64_t> huge;
  for (size_t i = 0; i < tight.size(); ++i) huge.push_back(int64_t(tight[i]) * (int64_t(1) << 41) - (int64_t(1) << 52));
  c.channels.push_back(chan(kCard, 0.0f, 1e-12, tight, huge));
  std::vector<uint32_t> halves = {0, 2, 3, 5, 6, 8, 9, 11, 12, 14, 15, 17, 18, 20};
  std::vector<int64_t> up, down;
  for (uint32_t f : halves) up.push_back(301 * int64_t(f) / 2), down.push_back(-(301 * int64_t(f) + 1) / 2 + 7);
  c.channels.push_back(chan(kCard, 0.5f, 0.001, halves, up));
  c.channels.push_back(chan(kLin, 0.0f, 0.001, halves, down));
  std::vector<int64_t> noisy;
  for (size_t i = 0; i < halves.size(); ++i) noisy.push_back((i * 7919) % 13 - 6);
  c.channels.push_back(chan(kCard, 0.0f, 0.5, halves, noisy));
  return c;
}

// Version 3.0 adds nothing for blocks to the file, but a decoder's runtime layout (keyanim's:
// 64-frame blocks, spec Appendix F) meets its limits here: keys on both sides of every block
// boundary, a block full of keys, a gap of 40 000 frames (context frames 2^15 and more away),
// curves that start and end inside blocks, 2 keys in adjacent blocks, values across the whole
// +-2^53 range; and a sparse channel, which keyanim keeps as a plain list of keys. (Every other
// curve has keys on the last 300 frames too, so that keyanim gives it records.)
inline EncodedClip vector_blocks() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Root", -1, 0, 0, 0, {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Arm", 0, 4, 1, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Hand", 1, 0, 2, 0, {CT::z_rotation, CT::y_rotation}),
      node("", 2, 0.5, 0, 0, {}, true),
  };
  c.frame_count = 70000;
  c.frame_time = 1.0 / 120.0;
  c.tangent_rule = TangentRule::step_adjusted;
  // Keys at frames 69700 .. 69999 after a curve's own, with values from `seed`.
  auto with_tail = [](std::vector<uint32_t> frames, std::vector<int64_t> values, int64_t seed) {
    for (uint32_t f = 69700; f < 70000; ++f) {
      if (!frames.empty() && frames.back() >= f) continue;
      frames.push_back(f);
      values.push_back((int64_t(f) * (seed + 7)) % 23 - 11);
    }
    return std::make_pair(frames, values);
  };
  auto add = [&](Interpolation interp, float tension, double step, std::vector<uint32_t> frames,
                 std::vector<int64_t> values, int64_t seed) {
    auto [f, v] = with_tail(std::move(frames), std::move(values), seed);
    c.channels.push_back(chan(interp, tension, step, f, v));
  };
  std::vector<uint32_t> edges = {0, 1, 62, 63, 64, 65, 127, 128, 191, 192, 255, 256, 1000};
  std::vector<int64_t> ev;
  for (size_t i = 0; i < edges.size(); ++i) ev.push_back((int64_t(i) * 37) % 11 * 100 - 500);
  add(kCard, 0.0f, 0.01, edges, ev, 1);
  std::vector<uint32_t> full;
  std::vector<int64_t> fv;
  for (uint32_t f = 128; f < 256; ++f) full.push_back(f), fv.push_back(int64_t(f % 7) * 13 - int64_t(f / 9));
  add(kCard, 0.25f, 0.02, full, fv, 2);                             // blocks 2 and 3 full
  add(kCard, 0.0f, 0.1, {0, 5, 40000}, {10, -20, 30}, 3);           // a 40 000-frame gap
  add(kCard, -0.5f, 0.05, {70, 75, 200}, {5, -5, 15}, 4);            // starts inside a block
  add(kLin, 0.0f, 0.1, {63, 64}, {-1000, 1000}, 5);                  // two keys, adjacent blocks
  const int64_t big = int64_t(1) << 53;
  add(kCard, 0.0f, 1e-20, {0, 64, 65, 129}, {big, -big, big - 1, -big + 1}, 6);
  c.channels.push_back(chan(kCard, 0.0f, 0.5, {}, {}));      // zero
  c.channels.push_back(chan(kCard, 0.0f, 0.5, {33}, {-7}));  // constant
  std::vector<uint32_t> sparse;                               // a list curve: 15 keys
  std::vector<int64_t> sv;
  for (uint32_t f = 0; f < 70000; f += 4999) sparse.push_back(f), sv.push_back(int64_t(f / 4999) * int64_t(f / 4999) * 50);
  sparse.push_back(69999), sv.push_back(0);
  c.channels.push_back(chan(kCard, 0.1f, 0.001, sparse, sv));
  add(kLin, 0.0f, 0.25, {100, 160, 161, 224, 288, 289, 352}, {1, 2, 3, 4, 5, 6, 7}, 8);
  c.channels.push_back(chan(kCard, 0.0f, 0.125, {0, 69999}, {-3, 3}));  // a list curve: 2 keys
  return c;
}

// A bigger pseudo-random clip: many densities, so that the segment index and cursor meet every
// case (dense channels, sparse ones, keys far from the ends).
inline uint64_t lcg(uint64_t& s) {
  s = s * 6364136223846793005ull + 1442695040888963407ull;
  return s >> 33;
}

inline EncodedClip random_clip(uint64_t seed, uint32_t frames, uint32_t joints) {
  EncodedClip c;
  uint64_t s = seed;
  for (uint32_t j = 0; j < joints; ++j) {
    std::vector<ChannelType> ch;
    if (j == 0) ch = {CT::x_position, CT::y_position, CT::z_position};
    ch.insert(ch.end(), {CT::z_rotation, CT::x_rotation, CT::y_rotation});
    std::string name = "j";
    name += std::to_string(j);  // not "j" + ...: GCC 12 warns falsely (-Wrestrict)
    c.skeleton.joints.push_back(node(name.c_str(), j == 0 ? -1 : int32_t(lcg(s) % j), 1, 2, 3, ch));
  }
  c.skeleton.joints.push_back(node("end", 1, 0, 1, 0, {}, true));
  c.frame_count = frames;
  c.frame_time = 1.0 / 120.0;
  c.tangent_rule = seed % 2 ? TangentRule::step_adjusted : TangentRule::uniform;
  const uint32_t channels = c.skeleton.channel_count();
  for (uint32_t ch = 0; ch < channels; ++ch) {
    EncodedChannel e;
    e.interp = lcg(s) % 5 == 0 ? kLin : kCard;
    e.tension = float(int(lcg(s) % 21) - 10) / 10.0f;
    e.step = 1e-3 * double(1 + lcg(s) % 10);
    const uint32_t kind = ch % 7;
    const uint32_t density = kind == 0 ? 1 : kind == 1 ? 2 : kind == 2 ? 40 : kind == 3 ? 300 : 6;
    if (kind == 4 && ch % 2 == 0) {  // zero channel
      c.channels.push_back(e);
      continue;
    }
    const bool inner = kind == 5 && frames > 40;  // keys away from both ends
    for (uint32_t f = inner ? 17 : 0; f < (inner ? frames - 13 : frames); ++f) {
      if (f == 0 || lcg(s) % density == 0) {
        e.frames.push_back(f);
        e.q.push_back(int64_t(lcg(s) % 200001) - 100000);
      }
    }
    c.channels.push_back(std::move(e));
  }
  return c;
}

// Version 5 (spec section 4.7): quaternion nodes beside Euler channels. A root keeping its
// Euler channels; a chest stored as a quaternion about the identity (dense keys across block
// boundaries, a tension, different steps for x, y, z); an arm about another reference, linear,
// whose rotation channels come before a position channel; a hand in X Y Z order with one key; a
// still neck with none; a head whose rotations are not consecutive (Euler, as it must be); a
// node with two rotation channels (Euler); End Sites. Integer-valued curves, so that the file
// does not depend on any libm.
inline EncodedClip vector_quat() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Hips", -1, 0, 90, 0, {CT::x_position, CT::y_position, CT::z_position, CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Chest", 0, 0, 12, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Arm", 1, 8, 4, 0, {CT::y_rotation, CT::z_rotation, CT::x_rotation, CT::x_position}),
      node("Hand", 2, 10, 0, 0, {CT::x_rotation, CT::y_rotation, CT::z_rotation}),
      node("", 3, 3, 0, 0, {}, true),
      node("Neck", 1, 0, 6, 0, {CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("Head", 5, 0, 4, 0, {CT::z_rotation, CT::x_position, CT::x_rotation, CT::y_rotation}),
      node("Jaw", 6, 0, 1, 1, {CT::x_rotation, CT::z_rotation}),
      node("", 7, 0, 0, 2, {}, true),
  };
  c.frame_count = 200;
  c.frame_time = 1.0 / 60.0;
  c.tangent_rule = TangentRule::step_adjusted;
  c.skeleton.assign_channel_columns();
  // A smooth integer curve through frames `f` (seeded), small enough that x^2 + y^2 + z^2 < 1.
  auto curve = [](const std::vector<uint32_t>& f, int64_t seed, int64_t scale) {
    std::vector<int64_t> q;
    for (uint32_t x : f) {
      const int64_t t = int64_t(x) - 100;
      q.push_back(((t * t * (seed % 5 + 1)) / 7 - t * (seed * 13 % 17) - 3000 * (seed % 3)) * scale / 100);
    }
    return q;
  };
  std::vector<uint32_t> dense, sparse = {0, 37, 90, 150, 199};
  for (uint32_t f = 0; f < 200; f += f % 5 == 0 ? 2 : 3) dense.push_back(f);
  if (dense.back() != 199) dense.push_back(199);
  // Hips: positions and Euler angles, as version 3 stores them.
  c.channels.push_back(chan(kCard, 0.0f, 0.01, dense, curve(dense, 1, 100)));
  c.channels.push_back(chan(kCard, 0.0f, 0.01, {0}, {9000}));
  c.channels.push_back(chan(kLin, 0.0f, 0.01, {0, 199}, {0, 5000}));
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kCard, 0.0f, 0.02, sparse, curve(sparse, 2 + k, 100)));
  // Chest: x, y, z about the identity (steps 2^-14, 2^-13.75, 2^-14.25).
  const double steps[3] = {1.0 / 16384.0, 1.189207115002721 / 16384.0, 0.8408964152537145 / 16384.0};
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kCard, 0.25f, steps[k], dense, curve(dense, 4 + k, 15)));
  // Arm: y, z, x rotations then a position; x, y, z about a turned reference, linear.
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kLin, 0.0f, 1.0 / 8192.0, sparse, curve(sparse, 7 + k, 4)));
  c.channels.push_back(chan(kCard, 0.0f, 0.01, sparse, curve(sparse, 10, 10)));
  // Hand: one key.
  const int64_t one[3] = {-1200, 400, 2500};
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kCard, 0.0f, 1.0 / 8192.0, {120}, {one[k]}));
  // Neck: no key (its reference's rotation throughout).
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kCard, 0.0f, 1.0 / 8192.0, {}, {}));
  // Head (Euler: a position channel between its rotations) and Jaw (two rotation channels).
  for (int k = 0; k < 4; ++k) c.channels.push_back(chan(kCard, 0.0f, 0.05, sparse, curve(sparse, 11 + k, 50)));
  for (int k = 0; k < 2; ++k) c.channels.push_back(chan(kCard, -0.5f, 0.05, dense, curve(dense, 15 + k, 20)));
  c.quat_nodes = {{1, {0, 0, 0}}, {2, {-9000, 12000, 3000}}, {3, {0, 0, 16384}}, {5, {100, -200, 300}}};
  return c;
}

// Version 5 over many blocks: quaternion nodes whose three curves are block curves (keys on
// both sides of block boundaries, a block full of keys, a 3000-frame gap, curves starting and
// ending inside blocks) and one whose are list curves (fewer keys than a quarter of the
// blocks), beside an Euler channel.
inline EncodedClip vector_quat_blocks() {
  EncodedClip c;
  c.skeleton.joints = {
      node("Root", -1, 0, 0, 0, {CT::y_position, CT::z_rotation, CT::x_rotation, CT::y_rotation}),
      node("A", 0, 0, 5, 0, {CT::z_rotation, CT::y_rotation, CT::x_rotation}),
      node("B", 1, 0, 5, 0, {CT::x_rotation, CT::z_rotation, CT::y_rotation}),
      node("", 2, 0, 5, 0, {}, true),
  };
  c.frame_count = 5000;
  c.frame_time = 1.0 / 120.0;
  c.tangent_rule = TangentRule::step_adjusted;
  c.skeleton.assign_channel_columns();
  std::vector<uint32_t> edges = {0, 1, 62, 63, 64, 65, 127, 128, 191, 192, 255, 256, 3300, 3301, 4999};
  for (uint32_t f = 3968; f < 4032; ++f) edges.push_back(f);  // block 62 full: 64 keys
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<uint32_t> inner = {70, 75, 200, 4500};
  std::vector<uint32_t> sparse = {0, 2500, 4999};
  auto values = [](const std::vector<uint32_t>& f, int64_t seed) {
    std::vector<int64_t> q;
    for (size_t i = 0; i < f.size(); ++i) q.push_back((int64_t(i) * (37 + seed) + seed * 11) % 401 - 200);
    return q;
  };
  c.channels.push_back(chan(kCard, 0.0f, 0.01, edges, values(edges, 0)));
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kCard, 0.0f, 0.25, inner, values(inner, 1 + k)));  // Euler
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kCard, 0.0f, 1.0 / 1024.0, edges, values(edges, 4 + k)));
  for (int k = 0; k < 3; ++k) c.channels.push_back(chan(kCard, 0.5f, 1.0 / 512.0, sparse, values(sparse, 7 + k)));
  c.quat_nodes = {{1, {1000, 2000, -3000}}, {2, {0, 0, 0}}};
  return c;
}

// A pseudo-random clip whose joints' rotations are stored as quaternions (version 5): every
// joint's x, y, z share key frames (dense, sparse enough to be list curves, or one key), with
// values within a quarter turn of the reference, which differs from joint to joint; the root
// keeps Euler channels when `euler_root`, and its positions are values.
inline EncodedClip random_quat_clip(uint64_t seed, uint32_t frames, uint32_t joints, bool euler_root = false) {
  EncodedClip c = random_clip(seed, frames, joints);
  uint64_t s = seed * 7 + 1;
  c.skeleton.assign_channel_columns();
  for (uint32_t j = euler_root ? 1 : 0; j < joints; ++j) {
    keyanim::QuatNode n;  // references within the unit ball; every other one the identity
    n.node = j;
    if (j % 2 == 1)
      for (int16_t& r : n.reference) r = int16_t(int(lcg(s) % 36000) - 18000);
    c.quat_nodes.push_back(n);
    const uint32_t first = c.skeleton.joints[j].first_channel + (j == 0 ? 3 : 0);
    const uint32_t density = j % 4 == 0 ? 1 : j % 4 == 1 ? 3 : j % 4 == 2 ? 200 : 100000;
    const double step = 1.0 / double(1u << (12 + lcg(s) % 6));
    std::vector<uint32_t> keys;
    for (uint32_t f = 0; f < frames; ++f)
      if (f == 0 || lcg(s) % density == 0) keys.push_back(f);
    const Interpolation interp = lcg(s) % 4 == 0 ? kLin : kCard;
    const float tension = float(int(lcg(s) % 11) - 5) / 10.0f;
    for (uint32_t k = 0; k < 3; ++k) {
      EncodedChannel& e = c.channels[first + k];
      e.interp = interp, e.tension = tension, e.step = step * (k + 1), e.frames = keys;
      e.q.clear();
      for (size_t i = 0; i < keys.size(); ++i)  // |x|, |y|, |z| below 0.38: w above 0.5
        e.q.push_back(std::llround((double(lcg(s) % 20001) / 10000.0 - 1.0) * 0.38 / e.step));
    }
  }
  return c;
}

inline std::vector<uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every array a decoder builds, field by field.
inline void check_same_clip(const Clip& a, const Clip& b) {
  REQUIRE(a.frame_count() == b.frame_count());
  REQUIRE(a.channel_count() == b.channel_count());
  CHECK(a.frame_time() == b.frame_time());
  CHECK(a.tangent_rule() == b.tangent_rule());
  CHECK(a.total_keys() == b.total_keys());
  CHECK(a.encoder_notes() == b.encoder_notes());
  REQUIRE(a.skeleton().joints.size() == b.skeleton().joints.size());
  for (size_t i = 0; i < a.skeleton().joints.size(); ++i) {
    const Joint& x = a.skeleton().joints[i];
    const Joint& y = b.skeleton().joints[i];
    CHECK(x.name == y.name);
    CHECK(x.parent == y.parent);
    CHECK(std::memcmp(x.offset.data(), y.offset.data(), sizeof x.offset) == 0);
    CHECK(x.channels == y.channels);
    CHECK(x.end_site == y.end_site);
    CHECK(x.first_channel == y.first_channel);
  }
  for (uint32_t c = 0; c < a.channel_count(); ++c) {
    CHECK(a.channel(c).key_count == b.channel(c).key_count);
    CHECK(a.channel(c).interp == b.channel(c).interp);
    CHECK(same_bits(a.channel(c).tension, b.channel(c).tension));
    const keyanim::test::ChannelKeys ka = keyanim::test::channel_keys(a, c), kb = keyanim::test::channel_keys(b, c);
    CHECK(ka.frames == kb.frames);
    REQUIRE(ka.values.size() == kb.values.size());
    for (size_t k = 0; k < ka.values.size(); ++k) CHECK(same_bits(ka.values[k], kb.values[k]));
  }
}

// Samples every quarter frame (and outside the clip) of both clips, bit-exactly (stored values,
// and the channels' values: for quaternion nodes their Euler angles), and checks each stored
// value against eval_channel on the clip's own keys.
inline void check_same_samples(const Clip& a, const Clip& b) {
  const uint32_t n = a.channel_count();
  std::vector<float> sa(n), sb(n), ea(n), eb(n);
  keyanim::Cursor cursor;
  REQUIRE(cursor.prepare(b) == Status::ok);
  const auto keys = keyanim::test::all_channel_keys(a);
  uint64_t mismatches = 0, eval_mismatches = 0, angle_mismatches = 0;
  const double end = double(a.frame_count()) + 1.0;
  for (double x = -2.0; x <= end; x += 0.25) {
    REQUIRE(a.sample_stored(x, sa) == Status::ok);
    REQUIRE(b.sample_stored(x, sb, &cursor) == Status::ok);
    REQUIRE(a.sample(x, ea) == Status::ok);
    REQUIRE(b.sample(x, eb) == Status::ok);
    for (uint32_t c = 0; c < n; ++c) {
      if (!same_bits(sa[c], sb[c])) ++mismatches;
      if (!same_bits(ea[c], eb[c])) ++angle_mismatches;
      if (!same_bits(sa[c], keyanim::test::reference_value(a, keys[c], float(x)))) ++eval_mismatches;
    }
  }
  CHECK(mismatches == 0);
  CHECK(angle_mismatches == 0);
  CHECK(eval_mismatches == 0);
}

// ---------------------------------------------------------------------------------------------
// A file builder for crafted files, independent of the writer.

// Version 1.0 files are frozen (written by the 1.0 writer); the current writer makes the rest.
// v4_* are the runtime profile of the v3_* file of the same name (keyanim convert --runtime),
// and v4_archive is v3_rules as an archive file of version 4.0 (spec/test-vectors/make_v4_archive.py).
// v5_quat and v5_blocks are archive files of version 5, v5_quat_runtime and v5_blocks_runtime
// their runtime profiles.
const char* const kVectorNames[] = {"v1_rules",  "v1_uniform", "v1_single",  "v1_long",    "v2_rules",
                                    "v2_long",   "v2_predict", "v3_rules",   "v3_uniform", "v3_single",
                                    "v3_long",   "v3_predict", "v3_blocks",  "v4_rules",   "v4_uniform",
                                    "v4_single", "v4_long",    "v4_predict", "v4_blocks",  "v4_archive",
                                    "v5_quat",   "v5_blocks",  "v5_quat_runtime", "v5_blocks_runtime"};
inline EncodedClip vector_clip(const std::string& name) {
  const std::string kind = name.substr(3);
  if (kind.starts_with("quat")) return vector_quat();
  if (name.starts_with("v5_blocks")) return vector_quat_blocks();
  if (kind == "rules" || kind == "archive") return vector_rules();
  if (kind == "uniform") return vector_uniform();
  if (kind == "single") return vector_single();
  if (kind == "predict") return vector_predict();
  if (kind == "blocks") return vector_blocks();
  return vector_long();
}
inline std::string vector_path(const std::string& name, const char* ext) {
  return std::string(KEYANIM_SPEC_DIR) + "/test-vectors/" + name + ext;
}

}  // namespace container_test
