// keyanim against ACL 2.1 (what Unreal ships), side by side in one process: issue 22's yardstick.
//
//   bench_vs_acl [--json] [--rounds N] [--clip NAME] [--corpus DIR]
//
// For every clip of the corpus groups CMU 120 fps (cmu/) and Bandai 30 fps (bandai/), keyanim is
// encoded at its defaults (0.05% of the skeleton size, shell 2%) and loaded with Clip::load, and
// ACL compresses the same motion exactly as ../shared/anchors/acl-2.1.0/README.md says (one qvvf
// track per node, precision 0.0005 x size, shell 0.02 x size, recommended lossy pre-processing,
// default compression settings). Every figure is keyanim's cost divided by ACL's: below 1 keyanim
// is ahead. Timed figures are the median over N interleaved rounds (rotating order) of the
// per-round ratio; each round times batches of poses at the same random times for both.
//
// Exit codes: 0 done; 1 a clip could not be read or compressed, or a sanity check failed (the
// figures would be meaningless); 2 bad arguments.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <time.h>
#if defined(__x86_64__)
#include <emmintrin.h>
#endif

#include <acl/compression/compress.h>
#include <acl/compression/pre_process.h>
#include <acl/compression/track_array.h>
#include <acl/compression/transform_error_metrics.h>
#include <acl/core/ansi_allocator.h>
#include <acl/decompression/decompress.h>
#include <rtm/qvvf.h>
#include <nlohmann/json.hpp>

#include "keyanim/clip.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/encode.h"
#include "keyanim/offline/fk.h"
#include "clock.h"
// Internal, for one purpose: the cold figure flushes every array a loaded clip owns, which only
// the runtime's image layout lists (bench_decode does the same). Nothing else reads it.
#include "cold.h"
#include "corpus_groups.h"

namespace {

using bench::CorpusClip;
using bench::CorpusError;
using bench::cpu_ns;
using bench::find_clips;
using bench::fence;
using bench::flush;
using bench::flush_image;
using bench::flush_vec;
using bench::median;
using bench::wall_ns;

namespace fs = std::filesystem;
namespace ko = keyanim::offline;
using keyanim::Clip;
using ko::Motion;
using json = nlohmann::json;

// A failure that makes the figures meaningless: reported, and the run exits 1.
struct BenchError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

constexpr double kAclPrecision = 0.0005;  // x size: keyanim's default tolerance (0.05%)
constexpr double kShell = 0.02;           // x size: keyanim's default shell (2%)
constexpr size_t kPoses = 2000;           // poses per timed batch
constexpr size_t kColdPoses = 200;        // cold samples per round (each timed alone)

volatile float g_sink = 0;  // keeps the samples from being optimized away
void sink(float v) { g_sink = g_sink + v; }

// ---------------------------------------------------------------------------------------------
// The clips

// ---------------------------------------------------------------------------------------------
// Poses in double precision, for the error: one FK for the original and both decodes.

struct LocalD {
  std::array<double, 4> q{0, 0, 0, 1};  // x, y, z, w
  ko::Vec3 t{};
};
using Pose = std::vector<LocalD>;

// The original's local transforms at a frame: rotation = the Euler channels' product in their
// order, translation = OFFSET with position channels replacing components (ACL's input too).
void original_pose(const keyanim::Skeleton& s, const double* row, Pose& out) {
  out.resize(s.joints.size());
  for (size_t j = 0; j < s.joints.size(); ++j) {
    const keyanim::Joint& joint = s.joints[j];
    out[j].q = ko::local_quaternion(joint, row);
    out[j].t = joint.offset;
    for (size_t k = 0; k < joint.channels.size(); ++k)
      if (!keyanim::is_rotation(joint.channels[k]))
        out[j].t[size_t(keyanim::channel_axis(joint.channels[k]))] = row[joint.first_channel + k];
  }
}

ko::Mat3 rotation_matrix(const std::array<double, 4>& q) {  // row-major, of a unit quaternion
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
          2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
          2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
}
ko::Mat3 mat_mul(const ko::Mat3& a, const ko::Mat3& b) {
  ko::Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) r[size_t(3 * i + j)] += a[size_t(3 * i + k)] * b[size_t(3 * k + j)];
  return r;
}

// The measured points of the shell metric: per node its world position, then for a joint (not
// an End Site) the points `shell` along its local x, y, z axes: 4 per node.
void shell_points(const keyanim::Skeleton& s, const Pose& pose, double shell, std::vector<ko::Vec3>& pts) {
  const size_t n = s.joints.size();
  std::vector<ko::Mat3> rw(n);
  pts.assign(4 * n, ko::Vec3{});
  for (size_t j = 0; j < n; ++j) {
    const int32_t p = s.joints[j].parent;
    const ko::Mat3 rl = rotation_matrix(pose[j].q);
    ko::Vec3 pos = pose[j].t;
    if (p >= 0 && size_t(p) < j) {
      const ko::Mat3& rp = rw[size_t(p)];
      const ko::Vec3& pp = pts[4 * size_t(p)];
      for (size_t i = 0; i < 3; ++i)
        pos[i] = pp[i] + rp[3 * i] * pose[j].t[0] + rp[3 * i + 1] * pose[j].t[1] + rp[3 * i + 2] * pose[j].t[2];
      rw[j] = mat_mul(rp, rl);
    } else {
      rw[j] = rl;
    }
    pts[4 * j] = pos;
    const double d = s.joints[j].end_site ? 0.0 : shell;
    for (size_t a = 0; a < 3; ++a)
      for (size_t i = 0; i < 3; ++i) pts[4 * j + 1 + a][i] = pos[i] + d * rw[j][3 * i + a];
  }
}

double max_distance(const std::vector<ko::Vec3>& a, const std::vector<ko::Vec3>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i)
    m = std::max(m, std::hypot(a[i][0] - b[i][0], a[i][1] - b[i][1], a[i][2] - b[i][2]));
  return m;
}

// ---------------------------------------------------------------------------------------------
// ACL: the clip built and compressed as ../shared/anchors/acl-2.1.0/README.md describes

using AclContext = acl::decompression_context<acl::default_transform_decompression_settings>;

// Decoded tracks land here: one rtm::qvvf per node (ACL's documented writer pattern).
struct QvvWriter final : acl::track_writer {
  rtm::qvvf* out = nullptr;
  void RTM_SIMD_CALL write_rotation(uint32_t i, rtm::quatf_arg0 r) { out[i].rotation = r; }
  void RTM_SIMD_CALL write_translation(uint32_t i, rtm::vector4f_arg0 t) { out[i].translation = t; }
  void RTM_SIMD_CALL write_scale(uint32_t i, rtm::vector4f_arg0 s) { out[i].scale = s; }
};

struct AclClip {
  acl::ansi_allocator* allocator = nullptr;
  acl::compressed_tracks* tracks = nullptr;
  std::vector<uint32_t> parent;  // acl::k_invalid_track_index for a root
  float rate = 0;
  AclClip() = default;
  AclClip(const AclClip&) = delete;
  AclClip& operator=(const AclClip&) = delete;
  ~AclClip() {
    if (tracks) allocator->deallocate(tracks, tracks->get_size());
  }
};

// One qvvf track per node (End Sites included, parents first): rotation = the Euler channels'
// product, translation = OFFSET with position channels replacing, scale 1.
acl::track_array_qvvf acl_tracks(acl::iallocator& allocator, const Motion& m, double size, float rate) {
  const keyanim::Skeleton& s = m.skeleton;
  acl::track_array_qvvf tracks(allocator, uint32_t(s.joints.size()));
  Pose pose;
  std::vector<acl::track_qvvf> list;
  for (uint32_t j = 0; j < s.joints.size(); ++j) {
    acl::track_desc_transformf desc;
    desc.output_index = j;
    desc.parent_index = s.joints[j].parent < 0 ? acl::k_invalid_track_index : uint32_t(s.joints[j].parent);
    desc.precision = float(kAclPrecision * size);
    desc.shell_distance = float(kShell * size);
    list.push_back(acl::track_qvvf::make_reserve(desc, allocator, m.frame_count, rate));
  }
  for (uint32_t f = 0; f < m.frame_count; ++f) {
    original_pose(s, m.frame(f), pose);
    for (uint32_t j = 0; j < s.joints.size(); ++j) {
      const LocalD& l = pose[j];
      list[j][f] = rtm::qvv_set(rtm::quat_set(float(l.q[0]), float(l.q[1]), float(l.q[2]), float(l.q[3])),
                                rtm::vector_set(float(l.t[0]), float(l.t[1]), float(l.t[2])), rtm::vector_set(1.0f));
    }
  }
  for (uint32_t j = 0; j < s.joints.size(); ++j) tracks[j] = std::move(list[j]);
  return tracks;
}

// Builds the tracks, pre-processes them (recommended, lossy, qvvf error metric) and compresses
// them with the default settings. Returns the CPU time of all of it (ACL's encode).
double acl_compress(const Motion& m, double size, AclClip& out) {
  const double t0 = cpu_ns();
  acl::track_array_qvvf tracks = acl_tracks(*out.allocator, m, size, out.rate);
  acl::qvvf_transform_error_metric metric;
  acl::pre_process_settings_t pre;
  pre.actions = acl::pre_process_actions::recommended;
  pre.precision_policy = acl::pre_process_precision_policy::lossy;
  pre.error_metric = &metric;
  acl::error_result r = acl::pre_process_track_list(*out.allocator, pre, tracks);
  if (r.any()) throw BenchError(std::string("ACL pre_process_track_list: ") + r.c_str());
  acl::compression_settings settings = acl::get_default_compression_settings();
  settings.error_metric = &metric;
  acl::output_stats stats;
  r = acl::compress_track_list(*out.allocator, tracks, settings, out.tracks, stats);
  if (r.any() || !out.tracks) throw BenchError(std::string("ACL compress_track_list: ") + r.c_str());
  const double t = cpu_ns() - t0;
  out.parent.clear();
  for (const keyanim::Joint& j : m.skeleton.joints)
    out.parent.push_back(j.parent < 0 ? acl::k_invalid_track_index : uint32_t(j.parent));
  return t;
}

LocalD to_double(const rtm::qvvf& x) {
  LocalD l;
  l.q = {rtm::quat_get_x(x.rotation), rtm::quat_get_y(x.rotation), rtm::quat_get_z(x.rotation),
         rtm::quat_get_w(x.rotation)};
  l.t = {rtm::vector_get_x(x.translation), rtm::vector_get_y(x.translation), rtm::vector_get_z(x.translation)};
  return l;
}
LocalD to_double(const keyanim::Transform& x) {
  LocalD l;
  l.q = {x.rotation[0], x.rotation[1], x.rotation[2], x.rotation[3]};
  l.t = {x.translation[0], x.translation[1], x.translation[2]};
  return l;
}

// ---------------------------------------------------------------------------------------------
// The systems under test, as loaded for sampling

struct Systems {
  const CorpusClip* clip = nullptr;
  std::vector<uint8_t> kanim;  // the .kanim file (archive profile)
  Clip ka;
  // The same clip in the runtime profile (spec section 9), 8-aligned as Clip::view needs, its
  // SKEL section's size, and a rig cache that holds the clip's rig, as an engine's would.
  std::vector<uint64_t> runtime_words;
  std::span<const uint8_t> runtime;
  uint64_t runtime_skel_bytes = 0;
  Clip ka_view;
  std::unique_ptr<keyanim::RigCache> rigs = std::make_unique<keyanim::RigCache>();
  ko::EncodeResult encoded;
  double ka_encode_ns = 0;
  AclClip acl;
  double acl_encode_ns = 0;
  double size = 0;
};

// keyanim at its defaults on one thread (the -j 1 equivalent), written as a .kanim; returns the
// CPU time.
double encode_keyanim(const Motion& m, ko::EncodeResult& encoded, std::vector<uint8_t>& kanim) {
  ko::EncodeSettings settings;  // 0.05%, shell 2%, error mode
  settings.threads = 1;
  const double t0 = cpu_ns();
  encoded = ko::encode(m, settings);
  kanim = ko::write_kanim(encoded.clip, settings.zstd_level);
  return cpu_ns() - t0;
}

// Stored_Size of section table entry i (spec section 3.1).
uint64_t section_stored_bytes(std::span<const uint8_t> file, size_t i) {
  uint64_t v;
  std::memcpy(&v, file.data() + 24 + 24 * i + 8, 8);
  return v;
}

double imag_bytes(std::span<const uint8_t> file) { return double(section_stored_bytes(file, 1)); }

// Both encodes, then keyanim's file loaded.
void encode_both(Systems& s) {
  s.ka_encode_ns = encode_keyanim(s.clip->motion, s.encoded, s.kanim);
  s.acl_encode_ns = acl_compress(s.clip->motion, s.size, s.acl);
  keyanim::ErrorInfo err;
  if (Clip::load(s.kanim, s.ka, &err) != keyanim::Status::ok)
    throw BenchError(std::string("keyanim cannot load its own file: ") + ko::Error::kanim(s.clip->name, err).what());
  if (s.ka.skeleton().joints.size() != s.clip->motion.skeleton.joints.size())
    throw BenchError(s.clip->name + ": the loaded clip's skeleton differs from the source's");
  const std::vector<uint8_t> runtime = ko::write_kanim_runtime(s.ka);
  s.runtime_words.assign((runtime.size() + 7) / 8, 0);
  std::memcpy(s.runtime_words.data(), runtime.data(), runtime.size());
  s.runtime = {reinterpret_cast<const uint8_t*>(s.runtime_words.data()), runtime.size()};
  s.runtime_skel_bytes = section_stored_bytes(s.runtime, 2);  // CLIP, IMAG, SKEL
  if (Clip::view(s.runtime, s.ka_view, &err, {}, s.rigs.get()) != keyanim::Status::ok)
    throw BenchError(std::string("keyanim cannot view its runtime file: ") + ko::Error::kanim(s.clip->name, err).what());
}

// Encoding takes up to seconds per clip, so it has rounds of its own, min(rounds, 3): the encodes
// that made the clips, then more in alternating order. Each must give the same bytes again.
struct EncodeTimes {
  std::vector<double> ns[2], ratio;
};
EncodeTimes time_encodes(const Systems& s, int rounds) {
  EncodeTimes t;
  const auto add = [&t](double ka, double acl) {
    t.ns[0].push_back(ka), t.ns[1].push_back(acl), t.ratio.push_back(ka / acl);
  };
  add(s.ka_encode_ns, s.acl_encode_ns);
  for (int r = 1; r < std::min(rounds, 3); ++r) {
    ko::EncodeResult encoded;
    std::vector<uint8_t> kanim;
    AclClip acl;
    acl.allocator = s.acl.allocator, acl.rate = s.acl.rate;
    double ka = 0, ac = 0;
    if (r % 2) ac = acl_compress(s.clip->motion, s.size, acl);
    ka = encode_keyanim(s.clip->motion, encoded, kanim);
    if (r % 2 == 0) ac = acl_compress(s.clip->motion, s.size, acl);
    if (kanim != s.kanim || acl.tracks->get_size() != s.acl.tracks->get_size() ||
        std::memcmp(acl.tracks, s.acl.tracks, s.acl.tracks->get_size()) != 0)
      throw BenchError(s.clip->name + ": encoding again gave other bytes");
    add(ka, ac);
  }
  return t;
}

// ---------------------------------------------------------------------------------------------
// Shell error of both decodes, one FK in double at every source frame

struct ShellError {
  double keyanim = 0, acl = 0;  // file units
};

ShellError shell_error(const Systems& s) {
  const Motion& m = s.clip->motion;
  const keyanim::Skeleton& sk = m.skeleton;
  const double shell = kShell * s.size;
  AclContext ctx;
  if (!ctx.initialize(*s.acl.tracks)) throw BenchError(s.clip->name + ": ACL decompression_context refused the clip");
  QvvWriter writer;
  std::vector<rtm::qvvf> acl_out(sk.joints.size());
  writer.out = acl_out.data();
  std::vector<keyanim::Transform> ka_out(sk.joints.size());
  Pose orig, ka(sk.joints.size()), ac(sk.joints.size());
  std::vector<ko::Vec3> p_orig, p_ka, p_acl;
  ShellError e;
  for (uint32_t f = 0; f < m.frame_count; ++f) {
    original_pose(sk, m.frame(f), orig);
    if (s.ka.sample_local(double(f), ka_out) != keyanim::Status::ok)
      throw BenchError(s.clip->name + ": keyanim sample_local failed");
    ctx.seek(float(f) / s.acl.rate, acl::sample_rounding_policy::none);
    ctx.decompress_tracks(writer);
    for (size_t j = 0; j < sk.joints.size(); ++j) ka[j] = to_double(ka_out[j]), ac[j] = to_double(acl_out[j]);
    shell_points(sk, orig, shell, p_orig);
    shell_points(sk, ka, shell, p_ka);
    shell_points(sk, ac, shell, p_acl);
    e.keyanim = std::max(e.keyanim, max_distance(p_orig, p_ka));
    e.acl = std::max(e.acl, max_distance(p_orig, p_acl));
  }
  if (!std::isfinite(e.keyanim) || !std::isfinite(e.acl)) throw BenchError(s.clip->name + ": a decode is not finite");
  return e;
}

// The checks without which the figures mean nothing: keyanim within its tolerance (its own
// report on the Euler channels, and this FK of its quaternion pose, which rounds to binary32),
// ACL within a few times its precision (it lands near 1.15-1.6x; 10x means a broken clip).
void check_errors(const Systems& s, const ShellError& e) {
  const double tol = s.encoded.tolerance_units;
  const std::string& n = s.clip->name;
  if (s.encoded.error.max_error > tol)
    throw BenchError(n + ": keyanim's encoder reports " + std::to_string(s.encoded.error.max_error) +
                     " above its tolerance " + std::to_string(tol));
  // keyanim's encoder measured its error by Euler FK; this program's FK must agree on it.
  const double reported = s.encoded.error.reading_max[size_t(keyanim::PositionReading::replace)];
  if (std::abs(e.keyanim - reported) > 0.02 * tol)
    throw BenchError(n + ": this program's FK gives keyanim an error of " + std::to_string(e.keyanim) +
                     ", its encoder " + std::to_string(reported) + ": the error metric is broken");
  if (e.keyanim > 1.02 * tol)
    throw BenchError(n + ": keyanim's sample_local is " + std::to_string(e.keyanim) + " from the original, above 1.02x its tolerance " +
                     std::to_string(tol));
  if (e.acl > 10 * kAclPrecision * s.size)
    throw BenchError(n + ": ACL's decode is " + std::to_string(e.acl) + " from the original, over 10x its precision " +
                     std::to_string(kAclPrecision * s.size) + ": its clip was not built right");
}

// ---------------------------------------------------------------------------------------------
// Timed figures: one job per system, both at the same random times, interleaved in rounds

// What the jobs share: the clip's systems, the random times, the outputs and the decoders.
struct Bench {
  explicit Bench(const Systems& sys) : s(sys), n(sys.ka.skeleton().joints.size()) {
    const double last = double(sys.clip->motion.frame_count - 1);
    uint64_t x = 12345;  // the same times for every run and both systems
    for (size_t i = 0; i < kPoses; ++i) {
      x = x * 6364136223846793005ull + 1442695040888963407ull;
      pos.push_back(double(x >> 11) / 9007199254740992.0 * last);
    }
    ka_out.resize(n), acl_local.resize(n), acl_model.resize(n), cold_ns.resize(kColdPoses);
    if (cursor.prepare(sys.ka) != keyanim::Status::ok) throw BenchError("Cursor::prepare failed");
    if (!ctx.initialize(*sys.acl.tracks)) throw BenchError("ACL decompression_context refused the clip");
    writer.out = acl_local.data();
  }
  const Systems& s;
  size_t n;                      // nodes
  std::vector<double> pos;       // frame positions; ACL's time is pos / rate
  std::vector<keyanim::Transform> ka_out;
  std::vector<rtm::qvvf> acl_local, acl_model;
  std::vector<double> cold_ns;
  keyanim::Cursor cursor;
  AclContext ctx;
  QvvWriter writer;
  uint32_t load_reps[3] = {1, 1, 1};  // keyanim runtime profile, ACL, keyanim archive

  void ka_local(double f, keyanim::Cursor* c = nullptr) {
    s.ka.sample_local(f, ka_out, c);
  }
  void acl_decode(double f) {
    ctx.seek(float(f / double(s.acl.rate)), acl::sample_rounding_policy::none);
    ctx.decompress_tracks(writer);
  }
  // A plain local-to-model loop (no scale: neither clip has any).
  void acl_to_model() {
    for (size_t j = 0; j < n; ++j) {
      const uint32_t p = s.acl.parent[j];
      acl_model[j] = p == acl::k_invalid_track_index ? acl_local[j] : rtm::qvv_mul_no_scale(acl_local[j], acl_model[p]);
    }
  }
  float ka_probe(size_t i) const { return ka_out[i % n].rotation[0]; }
  float acl_probe(size_t i, const std::vector<rtm::qvvf>& v) const { return rtm::quat_get_x(v[i % n].rotation); }

  // CPU ns per pose of a batch of kPoses.
  template <class F>
  static double per_pose(F&& f) {
    const double t0 = cpu_ns();
    for (size_t i = 0; i < kPoses; ++i) f(i);
    return (cpu_ns() - t0) / double(kPoses);
  }
  // Median wall ns of kColdPoses samples, each after `flush_all`.
  template <class Flush, class Sample>
  double cold(int round, Flush&& flush_all, Sample&& sample) {
    for (size_t i = 0; i < kColdPoses; ++i) {
      const double f = pos[(size_t(round) * kColdPoses + i) % kPoses];
      flush_all();
      fence();
      const double t0 = wall_ns();
      sample(f);
      cold_ns[i] = wall_ns() - t0;
      sink(float(i));
    }
    return median(cold_ns);
  }
  // keyanim's load of the runtime profile: Clip::load copies the file to aligned memory and
  // checks its structure and XXH64, as ACL's below; the rig is found in the cache (an engine
  // holds a character's skeleton once).
  double ka_load(uint32_t reps) {
    Clip c;
    const double t0 = cpu_ns();
    for (uint32_t r = 0; r < reps; ++r)
      if (Clip::load(s.runtime, c, nullptr, {}, s.rigs.get()) != keyanim::Status::ok) throw BenchError("Clip::load failed");
    return (cpu_ns() - t0) / reps;
  }
  // The archive profile: the file decoded into the image (no rig cache: its decode dominates).
  double ka_load_archive(uint32_t reps) {
    Clip c;
    const double t0 = cpu_ns();
    for (uint32_t r = 0; r < reps; ++r)
      if (Clip::load(s.kanim, c) != keyanim::Status::ok) throw BenchError("Clip::load failed");
    return (cpu_ns() - t0) / reps;
  }
  // ACL's load: its buffer copied to memory of its alignment and validated, hash included.
  double acl_load(uint32_t reps) {
    const size_t size = s.acl.tracks->get_size(), alloc = (size + 15) / 16 * 16;
    const double t0 = cpu_ns();
    for (uint32_t r = 0; r < reps; ++r) {
      void* b = std::aligned_alloc(16, alloc);
      if (!b) throw BenchError("out of memory");
      std::memcpy(b, s.acl.tracks, size);
      const auto* t = static_cast<const acl::compressed_tracks*>(b);
      const bool bad = t->is_valid(true).any();
      sink(float(t->get_num_tracks()));
      std::free(b);
      if (bad) throw BenchError("ACL's copied buffer is not valid");
    }
    return (cpu_ns() - t0) / reps;
  }
};

struct Figure {
  const char* name;
  std::function<double(int round)> job[2];  // keyanim, ACL: ns per pose (or per load)
  std::vector<double> ns[2], ratio;
};

using Job = std::function<double(int round)>;

std::vector<Figure> figures(Bench& b) {
  const uint32_t F = b.s.clip->motion.frame_count;
  std::vector<Figure> f;
  auto add = [&f](const char* name, Job ka, Job acl) { f.push_back(Figure{name, {std::move(ka), std::move(acl)}, {}, {}}); };
  add("warm_local",
      [&b](int) { return Bench::per_pose([&](size_t i) { b.ka_local(b.pos[i]); sink(b.ka_probe(i)); }); },
      [&b](int) { return Bench::per_pose([&](size_t i) { b.acl_decode(b.pos[i]); sink(b.acl_probe(i, b.acl_local)); }); });
  add("model",
      [&b](int) { return Bench::per_pose([&](size_t i) { b.s.ka.sample_model(b.pos[i], b.ka_out); sink(b.ka_probe(i)); }); },
      [&b](int) {
        return Bench::per_pose([&](size_t i) { b.acl_decode(b.pos[i]); b.acl_to_model(); sink(b.acl_probe(i, b.acl_model)); });
      });
  // Playback at the clip's rate, looping: keyanim with a Cursor, ACL seeking frame after frame.
  add("sequential",
      [&b, F](int) { return Bench::per_pose([&](size_t i) { b.ka_local(double(i % F), &b.cursor); sink(b.ka_probe(i)); }); },
      [&b, F](int) { return Bench::per_pose([&](size_t i) { b.acl_decode(double(i % F)); sink(b.acl_probe(i, b.acl_local)); }); });
  add("cold_local",
      [&b](int r) {
        return b.cold(r, [&] { flush_image(b.s.ka); flush_vec(b.ka_out); }, [&](double p) { b.ka_local(p); });
      },
      // ACL's buffer and the output, as the method says; not its decompression_context, the
      // per-instance decoder state (as a Cursor is; keyanim's cold sample uses none). Flushing
      // it too costs ACL about 100 ns more per cold pose (Bandai: ratio ~2.95 instead of ~3.2).
      [&b](int r) {
        const auto all = [&] { flush(b.s.acl.tracks, b.s.acl.tracks->get_size()), flush_vec(b.acl_local); };
        return b.cold(r, all, [&](double p) { b.acl_decode(p); });
      });
  add("load_runtime", [&b](int) { return b.ka_load(b.load_reps[0]); }, [&b](int) { return b.acl_load(b.load_reps[1]); });
  add("load_archive", [&b](int) { return b.ka_load_archive(b.load_reps[2]); }, [&b](int) { return b.acl_load(b.load_reps[1]); });
  return f;
}

// Rounds in rotating order: round r starts at job r of the list (A B C, B C A, ...), so that a
// drift of the machine hits both systems alike; a warm-up pass first.
void run_rounds(std::vector<Figure>& fig, int rounds) {
  const size_t jobs = 2 * fig.size();
  for (size_t i = 0; i < jobs; ++i) fig[i / 2].job[i % 2](0);
  std::vector<double> got(jobs);
  for (int r = 0; r < rounds; ++r) {
    for (size_t k = 0; k < jobs; ++k) {
      const size_t i = (size_t(r) + k) % jobs;
      got[i] = fig[i / 2].job[i % 2](r);
    }
    for (size_t i = 0; i < fig.size(); ++i) {
      fig[i].ns[0].push_back(got[2 * i]), fig[i].ns[1].push_back(got[2 * i + 1]);
      fig[i].ratio.push_back(got[2 * i] / got[2 * i + 1]);
    }
  }
}

// Loads per timed batch, so that one batch takes about 2 ms of CPU time.
void calibrate_loads(Bench& b) {
  for (int sys = 0; sys < 3; ++sys) {
    const double t = std::max(1.0, sys == 0 ? b.ka_load(1) : sys == 1 ? b.acl_load(1) : b.ka_load_archive(1));
    b.load_reps[sys] = uint32_t(std::clamp(std::ceil(2e6 / t), 1.0, 1e5));
  }
}

// ---------------------------------------------------------------------------------------------
// One clip: encode both, check their errors, time them

// acl_shell.tsv's row at threshold_fraction 0.0005, if any: the anchors' ACL at our settings,
// an independent check that this program builds ACL's clip as the anchors did.
struct Anchor {
  double bytes = 0, err_units = 0;
};
std::map<std::string, Anchor> read_anchors(const fs::path& tsv) {
  std::map<std::string, Anchor> out;
  std::ifstream in(tsv);
  std::string line;
  std::getline(in, line);  // header: file group frames fps channels raw size shell threshold bytes err err/size
  while (std::getline(in, line)) {
    std::vector<std::string> c;
    for (size_t a = 0, b; a <= line.size(); a = b + 1) {
      b = std::min(line.find('\t', a), line.size());
      c.push_back(line.substr(a, b - a));
    }
    if (c.size() >= 12 && std::strtod(c[8].c_str(), nullptr) == kAclPrecision)
      out[c[0]] = {std::strtod(c[9].c_str(), nullptr), std::strtod(c[10].c_str(), nullptr)};
  }
  return out;
}

json measure_clip(const CorpusClip& c, int rounds, const std::map<std::string, Anchor>& anchors) {
  static acl::ansi_allocator allocator;
  Systems s;
  s.clip = &c;
  s.size = ko::skeleton_size(c.motion.skeleton);
  if (!(s.size > 0)) throw BenchError(c.name + ": the rest pose has no extent");
  s.acl.allocator = &allocator;
  s.acl.rate = float(c.rate);
  encode_both(s);
  const ShellError e = shell_error(s);
  check_errors(s, e);

  Bench b(s);
  calibrate_loads(b);
  std::vector<Figure> fig = figures(b);
  run_rounds(fig, rounds);
  const EncodeTimes enc = time_encodes(s, rounds);

  const double file = double(s.kanim.size()), acl_bytes = double(s.acl.tracks->get_size());
  // A viewed runtime-profile clip holds the file's bytes (the caller's) plus its Image and notes
  // (animation_bytes counts the viewed IMAG too, so it is taken off) and the rig; with the rig
  // held once, neither the rig nor the file's SKEL section is the clip's own.
  const double runtime_file = double(s.runtime.size());
  const double runtime_resident = runtime_file + double(s.ka_view.memory_bytes()) - imag_bytes(s.runtime);
  const double rig_part = double(s.ka_view.skeleton_bytes()) + double(s.runtime_skel_bytes);
  json j = {{"name", c.name}, {"group", c.group}, {"frames", c.motion.frame_count},
            {"nodes", c.motion.skeleton.joints.size()}, {"fps", c.rate}, {"size", s.size}};
  json ka = {{"file_bytes", s.kanim.size()}, {"memory_bytes", s.ka.memory_bytes()},
             {"skeleton_bytes", s.ka.skeleton_bytes()}, {"animation_bytes", s.ka.animation_bytes()},
             {"keys", s.ka.total_keys()},
             {"encode_cpu_ms", median(enc.ns[0]) / 1e6}, {"shell_error_units", e.keyanim},
             {"shell_error_over_size", e.keyanim / s.size}, {"encoder_reported_error_units", s.encoded.error.max_error},
             {"tolerance_units", s.encoded.tolerance_units}};
  json ac = {{"bytes", s.acl.tracks->get_size()}, {"encode_cpu_ms", median(enc.ns[1]) / 1e6},
             {"shell_error_units", e.acl}, {"shell_error_over_size", e.acl / s.size},
             {"precision_units", kAclPrecision * s.size}};
  json ratio = {{"encode", median(enc.ratio)},
                {"runtime_bytes", runtime_resident / acl_bytes},
                {"runtime_bytes_rig_apart", (runtime_resident - rig_part) / acl_bytes},
                {"archive_bytes", file / acl_bytes}};
  for (const Figure& f : fig) {
    const std::string unit = std::string(f.name).starts_with("load_") ? "_ns" : "_ns_per_pose";
    ka[f.name + unit] = median(f.ns[0]);
    ac[f.name + unit] = median(f.ns[1]);
    ratio[f.name] = median(f.ratio);
  }
  ka["load_mb_s"] = runtime_file / median(fig[4].ns[0]) * 1e3;
  ka["load_archive_mb_s"] = file / median(fig[5].ns[0]) * 1e3;
  ka["runtime_file_bytes"] = s.runtime.size();
  ac["load_mb_s"] = acl_bytes / median(fig[4].ns[1]) * 1e3;
  j["keyanim"] = ka;
  j["acl"] = ac;
  j["ratio"] = ratio;
  if (const auto it = anchors.find(c.name); it != anchors.end())
    j["anchor"] = {{"acl_bytes", it->second.bytes}, {"acl_shell_error_units", it->second.err_units},
                   {"acl_bytes_over_anchor", acl_bytes / it->second.bytes},
                   {"acl_error_over_anchor", e.acl / it->second.err_units}};
  return j;
}

// ---------------------------------------------------------------------------------------------
// Groups, output, options

const char* const kFields[] = {"warm_local", "model", "sequential", "cold_local", "load_runtime", "load_archive",
                               "encode", "runtime_bytes", "runtime_bytes_rig_apart", "archive_bytes"};

json summarize(const json& clips) {
  json groups = json::object();
  for (const char* g : {"cmu120", "bandai30"}) {
    json out;
    std::vector<const json*> in;
    for (const json& c : clips)
      if (c["group"] == g) in.push_back(&c);
    out["clip_count"] = in.size();
    if (in.empty()) {
      groups[g] = out;
      continue;
    }
    for (const char* f : kFields) {
      std::vector<double> v;
      const json* worst = in[0];
      for (const json* c : in) {
        v.push_back((*c)["ratio"][f].get<double>());
        if ((*c)["ratio"][f].get<double>() > (*worst)["ratio"][f].get<double>()) worst = c;
      }
      out[f] = {{"median", median(v)}, {"worst", (*worst)["ratio"][f]}, {"worst_clip", (*worst)["name"]}};
    }
    std::vector<double> ka_mb, ka_archive_mb, acl_mb;
    for (const json* c : in) {
      ka_mb.push_back((*c)["keyanim"]["load_mb_s"]), acl_mb.push_back((*c)["acl"]["load_mb_s"]);
      ka_archive_mb.push_back((*c)["keyanim"]["load_archive_mb_s"]);
    }
    out["load_runtime_mb_s"] = median(ka_mb);
    out["load_archive_mb_s"] = median(ka_archive_mb);
    out["acl_load_mb_s"] = median(acl_mb);
    groups[g] = out;
  }
  return groups;
}

json notes() {
  return {{"ratios", "keyanim's cost (time or bytes) divided by ACL's: below 1 keyanim is ahead; timed figures are the "
                     "median over rounds of the per-round ratio"},
          {"runtime_bytes", "keyanim's runtime-profile file (spec section 9) viewed in place: the file's bytes plus "
                            "the clip's Image, notes and rig (skeleton included); ACL's is compressed_tracks::get_size(), which it "
                            "samples in place"},
          {"runtime_bytes_rig_apart", "runtime_bytes without the rig's part (Clip::skeleton_bytes(): names, parents, "
                                      "OFFSETs, channel lists, pose tables) and without the file's SKEL section, which "
                                      "an engine holds once per skeleton; ACL's buffer holds no "
                                      "names but its own per-track metadata, counted in full"},
          {"load_runtime_mb_s", "keyanim runtime-profile file MB (1e6 bytes) per CPU second through Clip::load (copy "
                                "to aligned memory, structure checks, XXH64), the rig found in a RigCache"},
          {"load_archive_mb_s", "archive .kanim MB per CPU second through Clip::load (decoded into the image)"},
          {"load_runtime", "keyanim Clip::load of the runtime-profile bytes through a RigCache holding the rig vs ACL "
                           "copying its buffer to aligned memory and is_valid(true) (hash checked)"},
          {"load_archive", "keyanim Clip::load of the archive .kanim (a full decode) vs the same ACL load"},
          {"encode", "CPU time of one thread: keyanim encode (threads 1) + write_kanim vs ACL building its tracks, "
                     "pre_process_track_list and compress_track_list"},
          {"cold_local", "median wall ns of single samples (steady clock), each after the system's clip (every "
                         "array of keyanim's image; ACL's buffer) and the output were flushed with clflush; ACL's "
                         "decompression_context (per-instance decoder state, like a Cursor) is not flushed"},
          {"shell_error", "max over every source frame of the distance of joints, End Sites and 3 shell points per "
                          "joint at 0.02 x size along its local axes; one FK in double of keyanim's sample_local and "
                          "ACL's decompressed local transforms against the original"},
          {"noise", "timings are per-thread CPU time on a machine others may be building on: ratios from one run "
                    "are meaningful, absolute ns less so"}};
}

void print_table(const json& clips, const json& groups) {
  std::printf("%-40s %6s %6s %6s %6s %6s %6s %6s %6s %6s %8s %8s\n", "clip (keyanim / ACL)", "frames", "warm",
              "model", "seq", "cold", "load", "encode", "memory", "file", "ka_err", "acl_err");
  for (const json& c : clips) {
    const json& r = c["ratio"];
    std::printf("%-40s %6u %6.2f %6.2f %6.2f %6.2f %6.2f %6.2f %6.3f %6.3f %8.6f %8.6f\n",
                c["name"].get<std::string>().substr(0, 40).c_str(), c["frames"].get<unsigned>(),
                r["warm_local"].get<double>(), r["model"].get<double>(), r["sequential"].get<double>(),
                r["cold_local"].get<double>(), r["load_runtime"].get<double>(), r["encode"].get<double>(),
                r["runtime_bytes"].get<double>(), r["archive_bytes"].get<double>(),
                c["keyanim"]["shell_error_over_size"].get<double>(), c["acl"]["shell_error_over_size"].get<double>());
  }
  std::printf("\n(errors as fractions of the skeleton size)\n\n%-14s", "median (worst)");
  for (const char* g : {"cmu120", "bandai30"}) std::printf(" %-24s", g);
  std::printf("\n");
  for (const char* f : kFields) {
    std::printf("%-14s", f);
    for (const char* g : {"cmu120", "bandai30"}) {
      const json& x = groups[g];
      if (x.contains(f)) std::printf(" %6.3f (%6.3f)         ", x[f]["median"].get<double>(), x[f]["worst"].get<double>());
      else std::printf(" %-24s", "-");
    }
    std::printf("\n");
  }
  for (const char* g : {"cmu120", "bandai30"})
    if (groups[g].contains("load_runtime_mb_s"))
      std::printf("%s: keyanim load %.1f MB/s (archive %.1f MB/s), ACL load %.1f MB/s\n", g,
                  groups[g]["load_runtime_mb_s"].get<double>(), groups[g]["load_archive_mb_s"].get<double>(),
                  groups[g]["acl_load_mb_s"].get<double>());
}

struct Options {
  bool json = false;
  int rounds = 17;
  std::string clip;
  std::string corpus = KEYANIM_CORPUS_DIR;
};

constexpr const char* kUsage =
    "usage: bench_vs_acl [--json] [--rounds N] [--clip NAME] [--corpus DIR]\n"
    "keyanim against ACL 2.1, side by side in one process, on the CMU 120 fps and Bandai 30 fps\n"
    "clips of the corpus (method: ../shared/anchors/acl-2.1.0/README.md). Figures are keyanim's\n"
    "cost divided by ACL's.\n"
    "  --json          print JSON (groups.cmu120, groups.bandai30, clips) instead of a table\n"
    "  --rounds N      interleaved timing rounds per clip (default 17; encoding: min(N, 3))\n"
    "  --clip NAME     only the clips whose file name contains NAME\n"
    "  --corpus DIR    the corpus (default " KEYANIM_CORPUS_DIR "; reads DIR/cmu and DIR/bandai)\n"
    "  --help          this text\n"
    "exit codes: 0 done, 1 a clip failed or a sanity check failed, 2 bad arguments\n";

int usage_error(const std::string& message) {
  std::cerr << "bench_vs_acl: " << message << "\ntry 'bench_vs_acl --help'\n";
  return 2;
}

// Returns -1 when the options are good, else the exit code.
int parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    } else if (a == "--json") {
      o.json = true;
    } else if (a == "--rounds" || a == "--clip" || a == "--corpus") {
      if (!has_value) return usage_error(a + " needs a value");
      const std::string v = argv[++i];
      if (a == "--clip") o.clip = v;
      if (a == "--corpus") o.corpus = v;
      if (a == "--rounds") {
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), o.rounds);
        if (ec != std::errc() || end != v.data() + v.size() || o.rounds < 1 || o.rounds > 1000)
          return usage_error("--rounds wants a whole number from 1 to 1000, not '" + v + "'");
      }
    } else {
      return usage_error("unknown argument '" + a + "'");
    }
  }
  if (!fs::is_directory(o.corpus)) return usage_error("--corpus " + o.corpus + ": not a directory");
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const int code = parse(argc, argv, o); code >= 0) return code;
  try {
    const std::vector<CorpusClip> clips = find_clips(o.corpus, o.clip);
    if (clips.empty())
      return usage_error("no CMU 120 fps or Bandai 30 fps clip of " + o.corpus +
                         (o.clip.empty() ? std::string() : " matches '" + o.clip + "'"));
    const auto anchors = read_anchors(fs::path(KEYANIM_ANCHORS_DIR) / "acl_shell.tsv");
    json list = json::array();
    for (const CorpusClip& c : clips) {
      if (!o.json) std::fprintf(stderr, "bench_vs_acl: %s\n", c.name.c_str());
      list.push_back(measure_clip(c, o.rounds, anchors));
    }
    const json groups = summarize(list);
    if (o.json) {
      std::cout << json{{"rounds", o.rounds}, {"poses_per_batch", kPoses}, {"cold_samples_per_round", kColdPoses},
                        {"encode_rounds", std::min(o.rounds, 3)},
                        {"notes", notes()}, {"groups", groups}, {"clips", list}}.dump(1) << "\n";
    } else {
      print_table(list, groups);
    }
  } catch (const BenchError& e) {
    std::cerr << "bench_vs_acl: " << e.what() << "\n";
    return 1;
  } catch (const ko::Error& e) {
    std::cerr << "bench_vs_acl: " << e.what() << "\n";
    return 1;
  } catch (const CorpusError& e) {
    std::cerr << "bench_vs_acl: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
