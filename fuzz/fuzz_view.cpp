// Fuzz target: the runtime profile (spec/FORMAT.md section 9) sampled in place by Clip::view.
// The input is .kanim bytes. They are copied to 8-aligned memory (Clip::view refuses other
// addresses); a runtime-profile file (version >= 4, Header_Flags bit 0) gets its trailing XXH64
// recomputed, so that mutations reach the structure checks of section 9.4 instead of stopping
// at checksum_mismatch. Then:
//  * Clip::view and Clip::load (without the content check) must agree on the status; a failure
//    leaves the clip empty and names a section and an offset <= the input's size.
//  * A viewed clip is sampled as a player would: every channel at positions inside the clip,
//    between frames, at and around its last frame and clamped past both ends; one position by
//    time; local and model poses; a Cursor playing forward by quarter frames over a stretch;
//    channel_keys of every channel (frames strictly increasing and below the frame count, as
//    the structure checks promise). A file that passes the structure checks may break content
//    rules, so its values may be anything, but nothing may crash, read out of bounds or hang.
//    The clip loaded from the same bytes (a copy of them) must give the same bits.
//  * Clip::load with check_content: a failure is `corrupt` in IMAG; a success means the image
//    is the one its keys make, so the viewed clip must then sample, with or without a cursor,
//    bit for bit as the loaded clip and as eval_channel (cardinal.h, Appendix A) on its keys (a
//    quaternion node of version 5: its channels the Euler angles of its stored x, y, z so
//    evaluated, sample_stored those values, its local rotation their binary32 stored_rotation).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "fuzz_common.h"
#include "keyanim/clip.h"
#include "clip_reference.h"

namespace {

using keyanim::Clip;
using keyanim::Cursor;
using keyanim::ErrorInfo;
using keyanim::Status;
using keyanim::Transform;

// As fuzz_load: small enough that no input makes a run decompress much (an archive-profile
// input is decoded by view too); the runtime profile declares nothing it does not store.
keyanim::DecodeLimits fuzz_limits(bool check_content) {
  keyanim::DecodeLimits l;
  l.max_decompressed_bytes = 64u << 20;
  l.check_content = check_content;
  return l;
}

void check_failure(Status s, const ErrorInfo& err, const Clip& clip, size_t size) {
  FUZZ_CHECK(err.status == s);
  FUZZ_CHECK(!err.section.empty());
  FUZZ_CHECK(err.byte_offset <= size);
  FUZZ_CHECK(clip.channel_count() == 0 && clip.total_keys() == 0 && clip.frame_count() == 0);
  FUZZ_CHECK(clip.skeleton().joints.empty());
}

// Frame positions: around both ends, inside, between frames, the last frame; capped in number.
std::vector<double> positions(const Clip& clip) {
  const double n = static_cast<double>(clip.frame_count());
  std::vector<double> p = {-3.0, -0.25, 0.0, 0.25, 0.5, 1.0, 1.5, n / 3.0, n / 2.0 + 0.375, n - 2.0, n - 1.5,
                           n - 1.0, n - 0.75, n, n + 4.0, 1e9, -1e9};
  for (uint32_t b = 1; b < 4; ++b) {  // around block boundaries (64 frames)
    const double f = 64.0 * b;
    if (f < n) p.insert(p.end(), {f - 0.5, f, f + 0.5});
  }
  return p;
}

bool same_floats(std::span<const float> a, std::span<const float> b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (!keyanim::fuzz::same_float(a[i], b[i])) return false;
  return true;
}

bool same_transforms(std::span<const Transform> a, std::span<const Transform> b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    for (int k = 0; k < 4; ++k)
      if (!keyanim::fuzz::same_float(a[i].rotation[k], b[i].rotation[k])) return false;
    for (int k = 0; k < 3; ++k)
      if (!keyanim::fuzz::same_float(a[i].translation[k], b[i].translation[k])) return false;
  }
  return true;
}

// Everything a player asks of a clip, into one flat list of floats (so that two clips can be
// compared): poses at positions(), local and model transforms, a cursor's playback.
struct Samples {
  std::vector<float> values;
  std::vector<Transform> poses;
  std::vector<float> playback;   // by a cursor
  std::vector<float> plain;      // the same positions without one
};

Samples sample_all(const Clip& clip) {
  Samples out;
  const uint32_t channels = clip.channel_count();
  const size_t nodes = clip.skeleton().joints.size();
  std::vector<float> pose(channels);
  std::vector<Transform> xf(nodes);
  for (double x : positions(clip)) {
    FUZZ_CHECK(clip.sample(x, pose) == Status::ok);
    out.values.insert(out.values.end(), pose.begin(), pose.end());
    FUZZ_CHECK(clip.sample_local(x, xf) == Status::ok);
    out.poses.insert(out.poses.end(), xf.begin(), xf.end());
    FUZZ_CHECK(clip.sample_model(x, xf) == Status::ok);
    out.poses.insert(out.poses.end(), xf.begin(), xf.end());
  }
  FUZZ_CHECK(clip.sample_time(clip.duration() * 0.5, pose) == Status::ok);
  out.values.insert(out.values.end(), pose.begin(), pose.end());
  FUZZ_CHECK(clip.sample(std::nan(""), pose) == Status::invalid_argument);
  if (channels > 0) {
    std::vector<float> short_out(channels - 1);
    FUZZ_CHECK(clip.sample(0.0, short_out) == Status::output_too_small);
    float one = 0.0f;
    FUZZ_CHECK(clip.sample_channel(channels - 1, 0.5f, one) == Status::ok);
    FUZZ_CHECK(clip.sample_channel(channels, 0.5f, one) == Status::invalid_argument);
  }
  // Forward playback by quarter frames over a stretch from the middle to past the end (at most
  // 80 frames of it), then a jump back to the start.
  Cursor cursor;
  FUZZ_CHECK(cursor.prepare(clip) == Status::ok);
  const double n = static_cast<double>(clip.frame_count());
  const double from = std::max(0.0, std::floor(n / 2.0) - 40.0), to = std::min(n + 1.0, from + 80.0);
  std::vector<double> walk;
  for (double x = from; x <= to; x += 0.25) walk.push_back(x);
  walk.push_back(0.0);
  walk.push_back(0.25);
  for (double x : walk) {
    FUZZ_CHECK(clip.sample(x, pose, &cursor) == Status::ok);
    out.playback.insert(out.playback.end(), pose.begin(), pose.end());
    FUZZ_CHECK(clip.sample(x, pose) == Status::ok);
    out.plain.insert(out.plain.end(), pose.begin(), pose.end());
  }
  FUZZ_CHECK(clip.sample_local(from + 0.5, xf, &cursor) == Status::ok);
  out.poses.insert(out.poses.end(), xf.begin(), xf.end());
  return out;
}

// channel_keys of every channel: the promises of the structure checks.
std::vector<keyanim::test::ChannelKeys> keys_of(const Clip& clip) {
  std::vector<keyanim::test::ChannelKeys> all;
  for (uint32_t c = 0; c < clip.channel_count(); ++c) {
    const keyanim::ChannelInfo info = clip.channel(c);
    FUZZ_CHECK(info.key_count <= clip.frame_count());
    keyanim::test::ChannelKeys k = keyanim::test::channel_keys(clip, c);
    FUZZ_CHECK(k.frames.size() == info.key_count);
    for (size_t i = 0; i < k.frames.size(); ++i) {
      FUZZ_CHECK(k.frames[i] < clip.frame_count());
      if (i > 0) FUZZ_CHECK(k.frames[i] > k.frames[i - 1]);
    }
    if (info.key_count > 0) {
      std::vector<uint32_t> f(info.key_count - 1);
      std::vector<float> v(info.key_count);
      FUZZ_CHECK(clip.channel_keys(c, f, v) == Status::output_too_small);
    }
    all.push_back(std::move(k));
  }
  std::vector<uint32_t> f;
  std::vector<float> v;
  FUZZ_CHECK(clip.channel_keys(clip.channel_count(), f, v) == Status::invalid_argument);
  return all;
}

// The viewed clip whose image passed the content check: every value is eval_channel's on its
// keys, which are the loaded clip's (a quaternion node's rotation channels: the Euler angles of
// its stored x, y, z so evaluated; sample_stored: those values; its local rotation: the binary32
// stored_rotation of them, rotation.h, whichever path, a track's or a curve's, computed it).
void check_against_reference(const Clip& viewed, const Clip& checked, const Samples& sv) {
  const auto keys = keys_of(viewed), checked_keys = keys_of(checked);
  FUZZ_CHECK(keys.size() == checked_keys.size());
  for (size_t c = 0; c < keys.size(); ++c) {
    FUZZ_CHECK(keys[c].frames == checked_keys[c].frames);
    FUZZ_CHECK(same_floats(keys[c].values, checked_keys[c].values));
    for (float v : keys[c].values) FUZZ_CHECK(std::isfinite(v));
  }
  FUZZ_CHECK(same_floats(sv.playback, sv.plain));
  const uint32_t channels = viewed.channel_count();
  if (channels == 0) return;
  const keyanim::test::SampleReference ref = keyanim::test::sample_reference(viewed, keys);
  size_t at = 0;
  for (double x : positions(viewed))
    for (uint32_t c = 0; c < channels; ++c, ++at)
      FUZZ_CHECK(keyanim::fuzz::same_float(sv.values[at], keyanim::test::reference_sample(viewed, ref, c, static_cast<float>(x))));
  std::vector<float> stored(channels);
  std::vector<Transform> xf(viewed.skeleton().joints.size());
  for (double x : positions(viewed)) {
    FUZZ_CHECK(viewed.sample_stored(x, stored) == Status::ok);
    for (uint32_t c = 0; c < channels; ++c)
      FUZZ_CHECK(keyanim::fuzz::same_float(stored[c], keyanim::test::reference_value(viewed, keys[c], static_cast<float>(x))));
    if (ref.quats.empty()) continue;
    FUZZ_CHECK(viewed.sample_local(x, xf) == Status::ok);
    for (const keyanim::test::QuatChannels& q : ref.quats) {
      float r[4], want[4];
      keyanim::reference_of(q.node, r);
      keyanim::stored_rotation<float>(r, stored[q.first], stored[q.first + 1], stored[q.first + 2], want,
                                      [](float v) { return std::sqrt(v); }, [](float v) { return v > 0.0f ? v : 0.0f; });
      for (int k = 0; k < 4; ++k) FUZZ_CHECK(keyanim::fuzz::same_float(xf[q.node.node].rotation[k], want[k]));
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint64_t> words(size / 8 + 1);  // 8-aligned, as Clip::view needs
  uint8_t* bytes = reinterpret_cast<uint8_t*>(words.data());
  if (size > 0) std::memcpy(bytes, data, size);
  if (keyanim::fuzz::is_runtime_profile(bytes, size)) keyanim::fuzz::fix_checksum(bytes, size);
  const std::span<const uint8_t> in(bytes, size);

  Clip viewed, loaded;
  ErrorInfo verr, lerr;
  const Status vs = Clip::view(in, viewed, &verr, fuzz_limits(false));
  const Status ls = Clip::load(in, loaded, &lerr, fuzz_limits(false));
  FUZZ_CHECK(vs == ls);
  if (vs != Status::ok) {
    check_failure(vs, verr, viewed, size);
    check_failure(ls, lerr, loaded, size);
    return 0;
  }
  FUZZ_CHECK(verr.status == Status::ok);
  keys_of(viewed);
  const Samples sv = sample_all(viewed);
  const Samples sl = sample_all(loaded);
  FUZZ_CHECK(same_floats(sv.values, sl.values));
  FUZZ_CHECK(same_transforms(sv.poses, sl.poses));
  FUZZ_CHECK(same_floats(sv.playback, sl.playback));

  // Through a rig cache that lives across inputs: a SKEL seen before (in another input, maybe
  // with other CLIP counts) is found by its bytes, not parsed; the clip must be the same.
  static keyanim::RigCache rigs;
  {
    Clip shared, again;
    FUZZ_CHECK(Clip::view(in, shared, nullptr, fuzz_limits(false), &rigs) == Status::ok);
    FUZZ_CHECK(Clip::view(in, again, nullptr, fuzz_limits(false), &rigs) == Status::ok);
    FUZZ_CHECK(again.shares_rig(shared) && shared.rig_hash() == viewed.rig_hash());
    FUZZ_CHECK(shared.skeleton().joints.size() == viewed.skeleton().joints.size());
    const Samples ss = sample_all(again);
    FUZZ_CHECK(same_floats(sv.values, ss.values));
    FUZZ_CHECK(same_transforms(sv.poses, ss.poses));
  }
  rigs.rig_count();  // drops the expired entries: the cache stays small

  Clip checked;
  ErrorInfo cerr;
  const Status cs = Clip::load(in, checked, &cerr, fuzz_limits(true));
  if (cs != Status::ok) {
    // Only the runtime profile has content rules beyond what loading already checks.
    FUZZ_CHECK(cs == Status::corrupt && cerr.section == "IMAG" && keyanim::fuzz::is_runtime_profile(bytes, size));
    check_failure(cs, cerr, checked, size);
    return 0;
  }
  const Samples sc = sample_all(checked);
  FUZZ_CHECK(same_floats(sv.values, sc.values));
  FUZZ_CHECK(same_transforms(sv.poses, sc.poses));
  FUZZ_CHECK(same_floats(sv.playback, sc.playback));
  check_against_reference(viewed, checked, sv);
  return 0;
}
