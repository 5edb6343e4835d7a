// Verification against what a decoder reproduces: the encoder's channel decoding against the
// runtime's sampler, the frames a refit can change against brute force, and window
// verification against measure_error on the decoded motion.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/metrics.h"
#include "offline/encode/verify.h"
#include "report_checks.h"
#include "shell_reference.h"

using namespace keyanim;
using namespace keyanim::offline;

namespace {

// A random channel of `frames` frames: sorted distinct key frames, random integers.
EncodedChannel random_channel(std::mt19937& rng, uint32_t frames, bool linear, uint32_t max_keys) {
  EncodedChannel ch;
  ch.interp = linear ? Interpolation::linear : Interpolation::cardinal;
  ch.tension = linear ? 0.0f : float(rng() % 5) * 0.25f - 0.5f;
  ch.step = 0.01 * double(1 + rng() % 4);
  const uint32_t keys = std::min<uint32_t>(frames, uint32_t(rng() % (max_keys + 1)));
  std::vector<uint32_t> pick(frames);
  for (uint32_t f = 0; f < frames; ++f) pick[f] = f;
  std::shuffle(pick.begin(), pick.end(), rng);
  ch.frames.assign(pick.begin(), pick.begin() + keys);
  std::sort(ch.frames.begin(), ch.frames.end());
  for (size_t i = 0; i < ch.frames.size(); ++i) ch.q.push_back(int64_t(rng() % 2001) - 1000);
  return ch;
}

// One channel in a clip of its own, sampled by the runtime at every frame.
std::vector<float> sampled(const EncodedChannel& ch, uint32_t frames, TangentRule rule) {
  EncodedClip clip;
  clip.skeleton.joints = {{"J", -1, {0, 0, 0}, {ChannelType::x_position}}};
  clip.skeleton.assign_channel_columns();
  clip.frame_count = frames;
  clip.frame_time = 0.1;
  clip.tangent_rule = rule;
  clip.channels = {ch};
  REQUIRE_NOTHROW(validate_encoded_clip(clip));
  const Clip c = to_clip(clip);
  std::vector<float> out(frames);
  for (uint32_t f = 0; f < frames; ++f) REQUIRE(c.sample_channel(0, float(f), out[f]) == Status::ok);
  return out;
}

// The same over entries in the same order, bit for bit.
void check_same_overs(const std::vector<OverNode>& a, const std::vector<OverNode>& b) {
  REQUIRE(a.size() == b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].frame == b[i].frame);
    CHECK(uint32_t(a[i].node) == uint32_t(b[i].node));
    CHECK(uint32_t(a[i].shell) == uint32_t(b[i].shell));
    CHECK(a[i].error == b[i].error);
  }
}

}  // namespace

TEST_SUITE("verify") {
  TEST_CASE("decoded channels are the runtime sampler's values, bit for bit") {
    std::mt19937 rng(11);
    for (int trial = 0; trial < 300; ++trial) {
      const uint32_t frames = 1 + uint32_t(rng() % 60);
      const TangentRule rule = trial % 2 ? TangentRule::uniform : TangentRule::step_adjusted;
      const EncodedChannel ch = random_channel(rng, frames, trial % 3 == 0, 12);
      const std::vector<float> want = sampled(ch, frames, rule);
      std::vector<uint32_t> all(frames);
      for (uint32_t f = 0; f < frames; ++f) all[f] = f;
      std::vector<double> got(frames);
      decode_channel_at(ch, rule, all.data(), frames, got.data(), 1);
      // Every other frame too: the cursor skips frames.
      std::vector<uint32_t> odd;
      for (uint32_t f = 1; f < frames; f += 2) odd.push_back(f);
      std::vector<double> got_odd(odd.size());
      decode_channel_at(ch, rule, odd.data(), odd.size(), got_odd.data(), 1);
      int wrong = 0;
      for (uint32_t f = 0; f < frames; ++f) wrong += got[f] != double(want[f]);
      for (size_t i = 0; i < odd.size(); ++i) wrong += got_odd[i] != double(want[odd[i]]);
      CAPTURE(trial);
      CHECK(wrong == 0);
    }
  }

  TEST_CASE("changed ranges hold every frame whose decoded value differs") {
    std::mt19937 rng(12);
    int covered = 0, tight = 0;
    for (int trial = 0; trial < 2000; ++trial) {
      const uint32_t frames = 2 + uint32_t(rng() % 80);
      EncodedChannel a = random_channel(rng, frames, trial % 7 == 0, 20);
      // b: a with a few edits (keys added, removed, requantized), or something else entirely.
      EncodedChannel b = a;
      const int edits = 1 + int(rng() % 3);
      for (int e = 0; e < edits; ++e) {
        const uint32_t f = uint32_t(rng() % frames);
        auto it = std::lower_bound(b.frames.begin(), b.frames.end(), f);
        const size_t i = size_t(it - b.frames.begin());
        if (it != b.frames.end() && *it == f) {
          if (rng() % 2) b.frames.erase(it), b.q.erase(b.q.begin() + long(i));
          else b.q[i] += 1;
        } else {
          b.frames.insert(it, f), b.q.insert(b.q.begin() + long(i), int64_t(rng() % 100));
        }
      }
      if (trial % 11 == 0) b.step *= 0.5;
      if (trial % 13 == 0) b.interp = Interpolation::linear;
      const std::vector<float> va = sampled(a, frames, TangentRule::step_adjusted);
      const std::vector<float> vb = sampled(b, frames, TangentRule::step_adjusted);
      std::vector<std::pair<uint32_t, uint32_t>> ranges;
      changed_ranges(a, b, frames, ranges);
      std::vector<uint8_t> in(frames, 0);
      for (size_t r = 0; r < ranges.size(); ++r) {
        CHECK(ranges[r].first <= ranges[r].second);
        CHECK(ranges[r].second < frames);
        if (r > 0) CHECK(ranges[r - 1].second + 1 < ranges[r].first);  // increasing, disjoint, merged
        for (uint32_t f = ranges[r].first; f <= ranges[r].second; ++f) in[f] = 1;
      }
      int missed = 0, marked = 0, differ = 0;
      for (uint32_t f = 0; f < frames; ++f) {
        const bool d = va[f] != vb[f];
        missed += d && !in[f];
        marked += in[f];
        differ += d;
      }
      CAPTURE(trial);
      CHECK(missed == 0);
      covered += differ > 0;
      tight += marked < int(frames);
    }
    CHECK(covered > 1000);  // the edits did change values
    CHECK(tight > 1000);    // and the ranges are not simply everything
  }

  TEST_CASE("window verification finds exactly the nodes measure_error finds over") {
    // A two-bone arm (with a twisting forearm, and in the second variant a position channel on
    // the Arm, read both ways), its encoding at a coarse uniform key interval, and a tolerance
    // between the smallest and largest errors: the over nodes are those an independent FK
    // (shell_reference.h) finds over, on joints, End Sites and shell points.
    for (const bool position_below_root : {false, true}) {
    CAPTURE(position_below_root);
    Motion m;
    const ChannelType arm_y = position_below_root ? ChannelType::y_position : ChannelType::y_rotation;
    m.skeleton.joints = {{"Root", -1, {0, 0, 0}, {ChannelType::x_position, ChannelType::z_rotation}},
                         {"Arm", 0, {0, 5, 0}, {ChannelType::z_rotation, arm_y}},
                         {"", 1, {0, 5, 0}, {}, true}};
    m.skeleton.assign_channel_columns();
    m.frame_count = 300;
    m.frame_time = 1.0 / 30.0;
    for (uint32_t f = 0; f < 300; ++f) {
      const double t = f / 30.0;
      const double y = position_below_root ? 5.0 + 0.3 * std::sin(1.7 * t) : 50.0 * std::sin(0.9 * t);
      m.values.insert(m.values.end(), {std::sin(t), 30.0 * std::sin(2.1 * t), 40.0 * std::cos(1.3 * t), y});
    }
    EncodedClip clip;
    clip.skeleton = m.skeleton;
    clip.frame_count = 300;
    clip.frame_time = m.frame_time;
    for (uint32_t c = 0; c < 4; ++c) {
      EncodedChannel ch;
      ch.step = 0.001;
      for (uint32_t f = 0; f < 300; f += 37) ch.frames.push_back(f), ch.q.push_back(std::llround(m.values[f * 4 + c] / 0.001));
      clip.channels.push_back(ch);
    }
    const Motion decoded = decode_motion(to_clip(clip));
    const double shell = 2.5;
    const ErrorReport report = measure_error(m, decoded, shell);
    CHECK(report.both_readings == position_below_root);
    const double tol = 0.5 * report.max_error;
    FrameMarks marks(300, 3);
    marks.mark_all();
    std::vector<OverNode> over;
    VerifyScratch scratch;
    for (uint32_t first = 0; first < 300; first += 64)
      verify_window(m, clip.channels, clip.tangent_rule, tol, shell, first, std::min(64u, 300 - first), marks, over,
                    scratch);
    // Independently: the reference FK of both motions, node by node, the worse reading.
    size_t want = 0, matched = 0, shells = 0;
    for (uint32_t f = 0; f < 300; ++f) {
      std::vector<test::NodeError> e(3);
      for (const test::Reading r : {test::Reading::replace, test::Reading::add}) {
        if (r == test::Reading::add && !test::has_position_channels(m.skeleton)) continue;
        const auto one = test::node_errors(m.skeleton, m.frame(f), decoded.frame(f), shell, r);
        for (uint32_t d = 0; d < 3; ++d)
          e[d].all = std::max(e[d].all, one[d].all), e[d].shell = std::max(e[d].shell, one[d].shell);
      }
      for (uint32_t d = 0; d < 3; ++d) {
        if (e[d].all <= tol) continue;
        ++want;
        for (const OverNode& o : over)
          if (o.frame == f && o.node == d && o.error == doctest::Approx(double(e[d].all)).epsilon(1e-9) &&
              o.shell == (e[d].shell > tol))
            ++matched, shells += o.shell;
      }
    }
    CHECK(want > 0);
    CHECK(shells > 0);
    CHECK(over.size() == want);
    CHECK(matched == want);
    // Marks: over frames stay marked for a full check; nothing else is.
    for (uint32_t f = 0; f < 300; ++f) {
      bool is_over = false;
      for (const OverNode& o : over) is_over |= o.frame == f;
      CHECK(marks.check()[f] == (is_over ? FrameMarks::kOver : 0));
    }
    // A frame marked as changed at the Arm only measures the Arm and its End Site.
    FrameMarks some(300, 3);
    some.mark(1, 10, 12);
    std::vector<OverNode> only;
    verify_window(m, clip.channels, clip.tangent_rule, 0.0, shell, 0, 64, some, only, scratch);
    for (const OverNode& o : only) {
      CHECK(o.node != 0);
      CHECK(o.frame >= 10);
      CHECK(o.frame <= 12);
    }
    CHECK(only.size() >= 3);  // with a tolerance of 0, whatever moved is over
    // A later round measures only the nodes that were over and the subtrees that moved, and
    // finds exactly what verifying every node finds: edit the Arm's keys, mark what changed,
    // verify again with the marks of the first pass, and compare with a fresh full pass.
    std::vector<EncodedChannel> edited = clip.channels;
    edited[2].q[4] += 40;  // the Arm's z rotation, at one key: frames 74 to 222 change
    std::vector<std::pair<uint32_t, uint32_t>> ranges;
    changed_ranges(clip.channels[2], edited[2], 300, ranges);
    CHECK(!ranges.empty());
    for (const auto& [a, b] : ranges) marks.mark(1, a, b);
    std::vector<OverNode> incremental, full;
    for (uint32_t first = 0; first < 300; first += 64)
      verify_window(m, edited, clip.tangent_rule, tol, shell, first, std::min(64u, 300 - first), marks, incremental,
                    scratch);
    FrameMarks fresh(300, 3);
    fresh.mark_all();
    for (uint32_t first = 0; first < 300; first += 64)
      verify_window(m, edited, clip.tangent_rule, tol, shell, first, std::min(64u, 300 - first), fresh, full, scratch);
    size_t outside = 0;  // over entries the edit cannot have caused: measured as over nodes only
    for (const OverNode& o : full) outside += o.frame < ranges.front().first || o.frame > ranges.back().second;
    CHECK(outside > 0);
    check_same_overs(incremental, full);
    for (uint32_t f = 0; f < 300; ++f) CHECK(marks.check()[f] == fresh.check()[f]);
    // With the original's points held (OriginalPoints: four decoded frames per FK pass instead
    // of two frames' original and decoded rows), a first pass and a later one find the same,
    // bit for bit, under both readings where both are measured.
    const OriginalPoints held(m, shell, size_t(1) << 30, 1);
    REQUIRE(!held.empty());
    CHECK(OriginalPoints(m, shell, 1000, 1).empty());  // over its budget: none held
    FrameMarks plain(300, 3), with(300, 3);
    plain.mark_all(), with.mark_all();
    for (const std::vector<EncodedChannel>* channels : {&clip.channels, &edited}) {
      if (channels == &edited)
        for (const auto& [a, b] : ranges) plain.mark(1, a, b), with.mark(1, a, b);
      std::vector<OverNode> posed, from_held;
      for (uint32_t first = 0; first < 300; first += 64) {
        const uint32_t n = std::min(64u, 300 - first);
        verify_window(m, *channels, clip.tangent_rule, tol, shell, first, n, plain, posed, scratch);
        verify_window(m, *channels, clip.tangent_rule, tol, shell, first, n, with, from_held, scratch, &held);
      }
      CHECK(!posed.empty());
      check_same_overs(posed, from_held);
      for (uint32_t f = 0; f < 300; ++f) CHECK(plain.check()[f] == with.check()[f]);
    }
    }
  }

  TEST_CASE("the final measurement is measure_error's report on the decoded motion") {
    Motion m;
    m.skeleton.joints = {{"Root", -1, {0, 0, 0}, {ChannelType::y_position, ChannelType::x_rotation}},
                         {"", 0, {0, 0, 3}, {}, true}};
    m.skeleton.assign_channel_columns();
    m.frame_count = 700;  // several measurement windows
    m.frame_time = 0.01;
    for (uint32_t f = 0; f < 700; ++f) m.values.insert(m.values.end(), {0.01 * f, 20.0 * std::sin(f * 0.05)});
    EncodedClip clip;
    clip.skeleton = m.skeleton;
    clip.frame_count = 700;
    clip.frame_time = 0.01;
    for (uint32_t c = 0; c < 2; ++c) {
      EncodedChannel ch;
      ch.step = 0.01;
      for (uint32_t f = 0; f < 700; f += 50) ch.frames.push_back(f), ch.q.push_back(std::llround(m.values[f * 2 + c] / 0.01));
      if (ch.frames.back() != 699) ch.frames.push_back(699), ch.q.push_back(std::llround(m.values[699 * 2 + c] / 0.01));
      clip.channels.push_back(ch);
    }
    const Motion decoded = decode_motion(to_clip(clip));
    const ErrorReport want = measure_error(m, decoded, 0.25);
    for (unsigned threads : {1u, 2u, 3u}) {
      keyanim::test::check_same_report(measure_encoded(m, clip, 0.25, threads), want);
    }
  }
}
