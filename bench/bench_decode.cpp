// Decode-side benchmark: load speed, random-access and sequential full-pose sampling against a
// raw float32 pose copy, memory, and a measurement of container layout alternatives. Prints
// JSON. Usage: bench_decode [file.bvh]   (default: the CMU 01_01 clip of the corpus)
//
// The clip is made without the encoder's key selection: keys every 8th frame (and the last),
// values quantized with step 1e-3. If the encoder works, an error-bounded clip of the same
// motion is measured too.
#include <zstd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include <time.h>

#include <nlohmann/json.hpp>

#include "keyanim/clip.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"

namespace {

using Clock = std::chrono::steady_clock;
using keyanim::Clip;
using keyanim::offline::EncodedClip;
using keyanim::offline::Motion;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Thread CPU time: the benchmark machines are shared, and wall time would count waiting.
double cpu_now_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e9 + double(t.tv_nsec);
}

template <class F>
double time_ns(F&& f) {
  const double t0 = cpu_now_ns();
  f();
  return cpu_now_ns() - t0;
}

volatile float g_sink = 0;  // keeps results alive

EncodedClip uniform_clip(const Motion& m, uint32_t interval, double step) {
  EncodedClip e;
  e.skeleton = m.skeleton;
  e.frame_count = m.frame_count;
  e.frame_time = m.frame_time;
  e.tangent_rule = keyanim::TangentRule::step_adjusted;
  const uint32_t C = m.channel_count();
  for (uint32_t c = 0; c < C; ++c) {
    keyanim::offline::EncodedChannel ch;
    ch.step = step;
    for (uint32_t f = 0; m.frame_count > 0; f += interval) {
      const uint32_t k = std::min(f, m.frame_count - 1);  // always the last frame too
      ch.frames.push_back(k);
      ch.q.push_back(std::llround(m.value(k, c) / step));
      if (k == m.frame_count - 1) break;
    }
    e.channels.push_back(std::move(ch));
  }
  return e;
}

struct SectionSizes {
  uint64_t ktim_raw = 0, kval_raw = 0, ktim_stored = 0, kval_stored = 0, file = 0;
};

SectionSizes section_sizes(const std::vector<uint8_t>& f) {
  SectionSizes s;
  s.file = f.size();
  uint32_t count = 0;
  std::memcpy(&count, &f[16], 4);
  for (uint32_t i = 0; i < count; ++i) {
    const uint8_t* e = &f[24 + 24 * i];
    uint64_t stored = 0, raw = 0;
    std::memcpy(&stored, e + 8, 8);
    std::memcpy(&raw, e + 16, 8);
    if (std::memcmp(e, "KTIM", 4) == 0) s.ktim_raw = raw, s.ktim_stored = stored;
    if (std::memcmp(e, "KVAL", 4) == 0) s.kval_raw = raw, s.kval_stored = stored;
  }
  return s;
}

void put_varint(std::vector<uint8_t>& out, uint64_t v) {
  while (v >= 0x80) {
    out.push_back(uint8_t(v | 0x80));
    v >>= 7;
  }
  out.push_back(uint8_t(v));
}
uint64_t zz(int64_t d) { return (uint64_t(d) << 1) ^ uint64_t(d >> 63); }
size_t zsize(const std::vector<uint8_t>& raw, int level) {
  std::vector<uint8_t> z(ZSTD_compressBound(raw.size()));
  return ZSTD_compress(z.data(), z.size(), raw.data(), raw.size(), level);
}

// Compressed bytes of the key data under several layouts (what section 4.4/4.5 chose vs
// alternatives), so that the choice is measured, not assumed.
nlohmann::json layout_experiment(const EncodedClip& e) {
  std::vector<uint8_t> ktim, kval, kval2, inter;
  for (const auto& ch : e.channels) {
    std::vector<uint8_t> t, v;
    for (size_t i = 0; i < ch.frames.size(); ++i) {
      put_varint(t, i == 0 ? ch.frames[0] : ch.frames[i] - ch.frames[i - 1] - 1);
      put_varint(v, zz(ch.q[i] - (i ? ch.q[i - 1] : 0)));
      // Second-order: predict by linear extrapolation of the two previous keys.
      const int64_t pred = i >= 2 ? 2 * ch.q[i - 1] - ch.q[i - 2] : i == 1 ? ch.q[0] : 0;
      put_varint(kval2, zz(ch.q[i] - pred));
    }
    ktim.insert(ktim.end(), t.begin(), t.end());
    kval.insert(kval.end(), v.begin(), v.end());
    inter.insert(inter.end(), t.begin(), t.end());
    inter.insert(inter.end(), v.begin(), v.end());
  }
  // Alternatives for the values: varints split into first bytes and continuation bytes, and
  // 32-bit zigzag deltas stored as four byte planes (a "shuffle" filter).
  std::vector<uint8_t> first_bytes, rest_bytes, planes[4];
  for (const auto& ch : e.channels) {
    for (size_t i = 0; i < ch.q.size(); ++i) {
      const uint64_t v = zz(ch.q[i] - (i ? ch.q[i - 1] : 0));
      std::vector<uint8_t> one;
      put_varint(one, v);
      first_bytes.push_back(one[0]);
      rest_bytes.insert(rest_bytes.end(), one.begin() + 1, one.end());
      for (int k = 0; k < 4; ++k) planes[k].push_back(uint8_t(v >> (8 * k)));
    }
  }
  std::vector<uint8_t> both = ktim;
  both.insert(both.end(), kval.begin(), kval.end());
  const int L = 19;
  nlohmann::json j;
  j["separate_ktim_kval_frames"] = zsize(ktim, L) + zsize(kval, L);
  j["one_frame_ktim_then_kval"] = zsize(both, L);
  j["one_frame_interleaved_per_channel"] = zsize(inter, L);
  j["separate_with_second_order_kval"] = zsize(ktim, L) + zsize(kval2, L);
  j["separate_kval_varints_split_first_byte"] = zsize(ktim, L) + zsize(first_bytes, L) + zsize(rest_bytes, L);
  j["separate_kval_u32_byte_planes"] =
      zsize(ktim, L) + zsize(planes[0], L) + zsize(planes[1], L) + zsize(planes[2], L) + zsize(planes[3], L);
  j["raw_ktim_kval"] = ktim.size() + kval.size();
  return j;
}

nlohmann::json measure(const EncodedClip& e, const Motion& m) {
  nlohmann::json j;
  const auto bytes = keyanim::offline::write_kanim(e, 19);
  if (bytes.empty()) return {{"error", "write_kanim refused the clip"}};
  const SectionSizes sizes = section_sizes(bytes);
  const uint32_t F = m.frame_count, C = m.channel_count();

  // Load speed.
  Clip clip;
  std::vector<double> load_ns;
  for (int r = 0; r < 15; ++r) {
    load_ns.push_back(time_ns([&] {
      if (Clip::load(bytes, clip) != keyanim::Status::ok) std::abort();
    }));
  }
  const double load = median(load_ns);
  const double key_array_bytes = double(clip.total_keys()) * 8.0;
  const double key_stream_bytes = double(sizes.ktim_raw + sizes.kval_raw);

  // Raw float32 frames x channels, and the positions every method visits.
  std::vector<float> raw(size_t(F) * C);
  for (size_t i = 0; i < raw.size(); ++i) raw[i] = float(m.values[i]);
  const size_t poses = 50000;
  std::vector<uint32_t> frames(poses);
  std::vector<double> positions(poses);
  uint64_t s = 12345;
  for (size_t i = 0; i < poses; ++i) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    const double x = double(s >> 11) / 9007199254740992.0 * double(F - 1);
    positions[i] = x;
    frames[i] = uint32_t(x);
  }
  std::vector<float> out(C);
  std::vector<double> random_ns, seq_ns, copy_random_ns, copy_seq_ns;
  keyanim::Cursor cursor;
  cursor.prepare(clip);
  for (int r = 0; r < 11; ++r) {
    copy_random_ns.push_back(time_ns([&] {
      for (size_t i = 0; i < poses; ++i) {
        std::memcpy(out.data(), raw.data() + size_t(frames[i]) * C, C * sizeof(float));
        g_sink = g_sink + out[i % C];
      }
    }) / double(poses));
    random_ns.push_back(time_ns([&] {
      for (size_t i = 0; i < poses; ++i) {
        clip.sample(positions[i], out);
        g_sink = g_sink + out[i % C];
      }
    }) / double(poses));
    copy_seq_ns.push_back(time_ns([&] {
      for (size_t i = 0; i < poses; ++i) {
        std::memcpy(out.data(), raw.data() + size_t(i % F) * C, C * sizeof(float));
        g_sink = g_sink + out[i % C];
      }
    }) / double(poses));
    seq_ns.push_back(time_ns([&] {
      for (size_t i = 0; i < poses; ++i) {
        clip.sample(double(i % F), out, &cursor);  // playback, looping
        g_sink = g_sink + out[i % C];
      }
    }) / double(poses));
  }
  const double rnd = median(random_ns), seq = median(seq_ns), crnd = median(copy_random_ns),
               cseq = median(copy_seq_ns);

  j["frames"] = F;
  j["channels"] = C;
  j["keys"] = clip.total_keys();
  j["file_bytes"] = sizes.file;
  j["raw_float32_bytes"] = uint64_t(F) * C * 4;
  j["ktim_bytes"] = {{"raw", sizes.ktim_raw}, {"stored", sizes.ktim_stored}};
  j["kval_bytes"] = {{"raw", sizes.kval_raw}, {"stored", sizes.kval_stored}};
  j["load_ms"] = load / 1e6;
  j["load_mb_per_s_key_arrays"] = key_array_bytes / load * 1e3;
  j["load_mb_per_s_key_streams"] = key_stream_bytes / load * 1e3;
  j["load_mb_per_s_file"] = double(bytes.size()) / load * 1e3;
  j["memory_bytes"] = clip.memory_bytes();
  j["key_array_bytes"] = uint64_t(key_array_bytes);
  j["memory_over_key_arrays"] = double(clip.memory_bytes()) / key_array_bytes;
  j["random_pose_ns"] = rnd;
  j["sequential_cursor_pose_ns"] = seq;
  j["raw_copy_random_pose_ns"] = crnd;
  j["raw_copy_sequential_pose_ns"] = cseq;
  j["ratio_random_vs_raw_copy"] = rnd / crnd;
  j["ratio_sequential_vs_raw_sequential_copy"] = seq / cseq;
  j["ratio_sequential_vs_raw_random_copy"] = seq / crnd;
  j["targets"] = {{"random_max_ratio", 15}, {"sequential_max_ratio", 4}, {"load_min_mb_per_s", 200}};
  j["key_layout_compressed_bytes"] = layout_experiment(e);
  j["key_layout_compressed_bytes"]["this_format_varint_planes"] = sizes.ktim_stored + sizes.kval_stored;
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : std::string(KEYANIM_CORPUS_DIR) + "/cmu/assimp__01_01.bvh";
  Motion m;
  keyanim::offline::BvhError err;
  if (!keyanim::offline::read_bvh_file(path, m, err)) {
    std::cerr << err.to_string() << "\n";
    return 1;
  }
  nlohmann::json j;
  j["file"] = path;
  j["joints"] = m.skeleton.joints.size();
  j["uniform_every_8_step_1e-3"] = measure(uniform_clip(m, 8, 1e-3), m);

  keyanim::offline::EncodeSettings settings;  // defaults: error-bounded keys
  keyanim::offline::EncodeResult result;
  std::string why;
  const auto t0 = Clock::now();
  if (keyanim::offline::encode(m, settings, result, why) && !result.clip.channels.empty()) {
    j["encoder_default"] = measure(result.clip, m);
    j["encoder_default"]["encode_s"] = std::chrono::duration<double>(Clock::now() - t0).count();
  } else {
    j["encoder_default"] = {{"error", why.empty() ? "encoder unavailable" : why}};
  }
  std::cout << j.dump(1) << "\n";
  return 0;
}
