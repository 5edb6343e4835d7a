// fuzz_bank's seeds (corpus/bank/): banks written by write_bank from clips cut short from
// data/'s two CMU files and from tests/data/bvh fixtures (two roots, mixed rotation orders, one
// frame), in both profiles, with and without a dictionary, with sections stored raw (so that
// mutations reach the member parsers' fields), one clip, no clip, and many clips with names
// sharing prefixes (the name order's binary search). Those clips keep Euler rotations (members
// of version 4, banks of 4.1, as the seeds were first made); the quat_ banks (version 5.0) hold
// the CMU clips with quaternion nodes (spec 4.7), alone and beside the Euler ones (members of
// versions 5 and 4 in one bank). Each seed stays under 64 KiB, the -max_len CI runs with. Run
// through make_seeds.py --bank; usage: make_bank_seeds REPO_DIR OUT_DIR
#include <cstdio>
#include <cstddef>
#include <exception>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "keyanim/offline/bank.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/encode.h"

namespace off = keyanim::offline;

namespace {

off::Motion cut(const off::Motion& m, uint32_t from, uint32_t count) {
  off::Motion c = m;
  c.frame_count = count;
  const size_t n = m.skeleton.channel_count();
  c.values.assign(m.values.begin() + std::ptrdiff_t(from * n), m.values.begin() + std::ptrdiff_t((from + count) * n));
  return c;
}

off::EncodedClip encode(const off::Motion& m, bool coarse, bool quaternion = false) {
  off::EncodeSettings s;
  s.rotations = quaternion ? off::Rotations::quaternion : off::Rotations::euler;
  if (coarse) {  // fewer keys: a smaller seed
    s.key_mode = off::KeyMode::uniform;
    s.uniform_interval = 5;
  }
  return off::encode(m, s).clip;
}

void write(const std::string& dir, const std::string& name, const std::vector<off::BankInput>& clips,
           const off::BankOptions& o) {
  const off::WrittenBank w = off::write_bank(clips, o);
  if (w.bytes.size() >= 65536) throw std::runtime_error(name + ": " + std::to_string(w.bytes.size()) + " bytes, not < 64 KiB");
  if (o.dictionary == off::BankDictionary::always && !o.runtime && w.dictionary_bytes == 0)
    throw std::runtime_error(name + ": zstd trained no dictionary");
  std::ofstream f(dir + "/" + name, std::ios::binary);
  f.write(reinterpret_cast<const char*>(w.bytes.data()), std::streamsize(w.bytes.size()));
  if (!f) throw std::runtime_error(name + ": cannot write");
  std::printf("%s: %zu bytes, %u skeletons, dictionary %llu bytes\n", name.c_str(), w.bytes.size(), w.skeletons,
              static_cast<unsigned long long>(w.dictionary_bytes));
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_bank_seeds REPO_DIR OUT_DIR\n");
    return 2;
  }
  const std::string repo = argv[1], out = argv[2];
  const off::Motion walk = off::read_bvh_file(repo + "/data/cmu_02_01_walk.bvh");
  const off::Motion hop = off::read_bvh_file(repo + "/data/cmu_131_03_hop.bvh");
  const off::Motion roots = off::read_bvh_file(repo + "/tests/data/bvh/multi_root.bvh");
  const off::Motion orders = off::read_bvh_file(repo + "/tests/data/bvh/mixed_rotation_orders.bvh");
  const off::Motion one = off::read_bvh_file(repo + "/tests/data/bvh/one_frame.bvh");

  // Two skeletons of CMU clips: three clips of the walk's, one of the hop's ("walk" sorts
  // before "walk/start", and the table's order is not the name order).
  const std::vector<off::BankInput> cmu = {
      {"walk/start", encode(cut(walk, 0, 12), true)},
      {"hop", encode(cut(hop, 0, 10), true)},
      {"walk", encode(cut(walk, 60, 1), false)},
      {"walk/end", encode(cut(walk, 100, 8), false)},
  };
  const std::vector<off::BankInput> fixtures = {
      {"fixtures/multi_root", encode(roots, false)},
      {"fixtures/mixed_orders", encode(orders, false)},
      {"fixtures/one_frame", encode(one, false)},
  };
  off::BankOptions archive, dictionary, raw, runtime;
  dictionary.dictionary = off::BankDictionary::always;
  raw.zstd_level = 0;
  raw.dictionary = off::BankDictionary::never;
  runtime.runtime = true;
  write(out, "cmu_archive.kbank", cmu, archive);
  write(out, "cmu_archive_dictionary.kbank", cmu, dictionary);
  write(out, "cmu_archive_raw.kbank", cmu, raw);
  write(out, "cmu_runtime.kbank", cmu, runtime);
  write(out, "fixtures_archive_raw.kbank", fixtures, raw);
  write(out, "fixtures_runtime.kbank", fixtures, runtime);
  write(out, "one_clip_runtime.kbank", {cmu[1]}, runtime);
  write(out, "one_clip_archive_raw.kbank", {fixtures[2]}, raw);
  write(out, "no_clip.kbank", {}, archive);
  // 40 one-frame clips of one small skeleton, names a/b/c-like paths sharing prefixes.
  std::vector<off::BankInput> many;
  for (int k = 0; k < 40; ++k) {
    const std::string name = std::string(1, char('a' + k % 3)) + (k % 2 ? "/" : "") + std::to_string(k * 7 % 40);
    many.push_back({name, encode(cut(orders, uint32_t(k % orders.frame_count), 1), false)});
  }
  write(out, "many_clips_archive_raw.kbank", many, raw);
  write(out, "many_clips_runtime.kbank", many, runtime);
  // Version 5.0: the CMU clips with quaternion nodes, then beside an Euler clip of each skeleton
  // (a skeleton's clips share it whatever their rotations).
  const std::vector<off::BankInput> quat = {
      {"walk/start", encode(cut(walk, 0, 12), true, true)},
      {"hop", encode(cut(hop, 0, 10), true, true)},
      {"walk/end", encode(cut(walk, 100, 8), false, true)},
  };
  for (const off::BankInput& c : quat)
    if (c.clip.quat_nodes.empty()) throw std::runtime_error(c.name + ": no quaternion node");
  std::vector<off::BankInput> mixed = quat;
  mixed.push_back({"walk/euler", cmu[2].clip});
  mixed.push_back({"hop/euler", encode(cut(hop, 20, 6), true)});
  write(out, "quat_archive.kbank", quat, archive);
  write(out, "quat_archive_raw.kbank", quat, raw);
  write(out, "quat_runtime.kbank", quat, runtime);
  write(out, "quat_mixed_archive_dictionary.kbank", mixed, dictionary);
  write(out, "quat_mixed_runtime.kbank", mixed, runtime);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "make_bank_seeds: %s\n", e.what());
  return 1;
}
