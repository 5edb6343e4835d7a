// bench_bank: banks (spec/FORMAT.md section 10, issue 25) against ACL and against one file per
// clip. Prints one JSON object:
//   bandai_archive_over_acl, bandai_runtime_over_acl, cmu_archive_over_acl: the bytes of the
//     corpus' 11 Bandai 30 fps (17 CMU 120 fps) clips in one bank, over the sum of ACL's buffers
//     at each clip's measured error (../shared/anchors/acl_shell.tsv, interpolated as
//     bench_codec does, on the replace reading ACL uses);
//   dictionary_gain: the Bandai archive bank's bytes without a dictionary over its bytes with
//     one (> 1: the dictionary pays), with both sizes and the dictionary's;
//   open_10k_ms, open_10k_resident_bytes: Bank::open_file of a bank of 10,000 clips (corpus
//     clips repeated under distinct names; opening reads the index only, so the members' sizes
//     do not enter it: the shortest Bandai clips are repeated, to keep the file small), the
//     median time and the resident memory it adds (VmRSS), before any clip is sampled (the
//     largest of 15 opens after a first, whose code pages are reported apart);
//   sample_bank_over_file: a random local pose from a runtime bank's clip, sampled in place,
//     over the same from the clip's own runtime-profile file (median over the Bandai clips of
//     the ratio of medians, interleaved rounds).
// Times are wall clock on one thread: run it on a quiet machine.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "clock.h"
#include "keyanim/bank.h"
#include "keyanim/offline/acl_compare.h"
#include "keyanim/offline/bank.h"
#include "keyanim/offline/bvh.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/decode.h"
#include "keyanim/offline/metrics.h"

namespace fs = std::filesystem;
using namespace keyanim;

namespace {

struct Encoded {
  std::string name;
  offline::EncodedClip clip;
  double acl_bytes = 0;
  size_t own_bytes = 0;  // its own archive file
};

// The group's corpus clips, encoded with the default settings, with ACL's bytes at their error.
std::vector<Encoded> encode_group(const std::string& group, const std::map<std::string, offline::AclFile>& acl) {
  std::vector<Encoded> out;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(KEYANIM_CORPUS_DIR) / (group == "cmu_120fps" ? "cmu" : "bandai")))
    if (e.path().extension() == ".bvh") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& p : files) {
    const auto it = acl.find(p.filename().string());
    if (it == acl.end() || offline::comparison_group(it->second) != group) continue;
    const offline::Motion m = offline::read_bvh_file(p.string());
    offline::EncodedClip clip = offline::encode(m, {}).clip;
    const offline::ErrorReport e = offline::measure_error(m, offline::decode_motion(offline::to_clip(clip)));
    const double acl_bytes = offline::acl_at(it->second, e.reading_max[0])["bytes"].get<double>();
    const size_t own = offline::write_kanim(clip).size();
    out.push_back({p.stem().string(), std::move(clip), acl_bytes, own});
  }
  return out;
}

std::vector<offline::BankInput> inputs_of(const std::vector<Encoded>& clips) {
  std::vector<offline::BankInput> in;
  for (const Encoded& c : clips) in.push_back({c.name, c.clip});
  return in;
}

double acl_sum(const std::vector<Encoded>& clips) {
  double s = 0;
  for (const Encoded& c : clips) s += c.acl_bytes;
  return s;
}

size_t own_sum(const std::vector<Encoded>& clips) {
  size_t s = 0;
  for (const Encoded& c : clips) s += c.own_bytes;
  return s;
}

// A line of /proc/self/status in bytes ("VmRSS:", "RssAnon:", "RssFile:").
long status_bytes(const std::string& key) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key, 0) == 0) return std::stol(line.substr(key.size())) * 1024;
  return 0;
}

nlohmann::json open_10k(const std::vector<Encoded>& bandai) {
  std::vector<const Encoded*> shortest;
  for (const Encoded& c : bandai) shortest.push_back(&c);
  std::sort(shortest.begin(), shortest.end(), [](auto* a, auto* b) { return a->clip.frame_count < b->clip.frame_count; });
  shortest.resize(std::min<size_t>(3, shortest.size()));
  std::vector<offline::BankInput> in;
  for (int i = 0; i < 10000; ++i) {
    const Encoded& c = *shortest[size_t(i) % shortest.size()];
    in.push_back({"clips/" + std::to_string(i) + "/" + c.name, c.clip});
  }
  offline::BankOptions o;
  o.dictionary = offline::BankDictionary::never;
  const std::vector<uint8_t> bytes = offline::write_bank(in, o).bytes;
  const fs::path path = fs::temp_directory_path() / "bench_bank_10k.kbank";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  std::vector<double> ms;
  long resident = 0, anon = 0, file = 0, first = 0;
  // The first open also faults in the library's own code (file pages, shared with every other
  // user of the library): reported apart, and the figure is the largest of the later opens.
  for (int rep = 0; rep < 16; ++rep) {
    const long before = status_bytes("VmRSS:"), anon0 = status_bytes("RssAnon:"), file0 = status_bytes("RssFile:");
    const double t0 = bench::wall_ns();
    Bank bank;
    if (Bank::open_file(path.string(), bank) != Status::ok || bank.clip_count() != 10000) return {{"error", "open failed"}};
    const double t = (bench::wall_ns() - t0) / 1e6;
    const long added = status_bytes("VmRSS:") - before;
    if (rep == 0) {
      first = added;
      continue;
    }
    ms.push_back(t);
    if (added >= resident) resident = added, anon = status_bytes("RssAnon:") - anon0, file = status_bytes("RssFile:") - file0;
  }
  fs::remove(path);
  // The index's own size: what opening must read.
  const uint64_t index = 40 + 32 * 3 + 44 * 10000 + [&] { size_t n = 0; for (const auto& c : in) n += c.name.size(); return n; }();
  return {{"clips", 10000}, {"file_bytes", bytes.size()}, {"index_bytes", index}, {"ms", bench::median(ms)},
          {"resident_bytes", resident}, {"resident_anon_bytes", anon}, {"resident_file_bytes", file},
          {"first_open_resident_bytes", first}};
}

// Median ns of a local pose at random positions, `clip` sampled `n` times.
double pose_ns(const Clip& clip, std::vector<Transform>& pose, std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> at(0.0, std::max(0.0, double(clip.frame_count()) - 1.0));
  std::vector<double> t;
  for (int i = 0; i < n; ++i) {
    const double f = at(rng);
    const double t0 = bench::wall_ns();
    (void)clip.sample_local(f, pose);
    t.push_back(bench::wall_ns() - t0);
  }
  return bench::median(t);
}

double sample_ratio(const std::vector<Encoded>& clips) {
  offline::BankOptions o;
  o.runtime = true;
  const std::vector<uint8_t> bytes = offline::write_bank(inputs_of(clips), o).bytes;
  Bank bank;
  if (Bank::open(bytes, bank) != Status::ok) return 0;
  std::vector<double> ratios;
  std::mt19937 rng(1);
  for (uint32_t i = 0; i < bank.clip_count(); ++i) {
    Clip in_bank, own;
    if (bank.clip(i, in_bank) != Status::ok) return 0;
    if (Clip::load(offline::write_kanim_runtime(offline::to_clip(clips[i].clip)), own) != Status::ok) return 0;
    std::vector<Transform> pose(own.skeleton().joints.size());
    std::vector<double> a, b;
    for (int round = 0; round < 9; ++round) {
      a.push_back(pose_ns(in_bank, pose, rng, 400));
      b.push_back(pose_ns(own, pose, rng, 400));
    }
    ratios.push_back(bench::median(a) / bench::median(b));
  }
  return bench::median(ratios);
}

}  // namespace

int main(int argc, char** argv) {
  const bool json = argc > 1 && std::string(argv[1]) == "--json";
  if (!fs::is_directory(KEYANIM_CORPUS_DIR)) {
    std::cerr << "bench_bank: corpus not found at " << KEYANIM_CORPUS_DIR << "\n";
    return 1;
  }
  std::string acl_error;
  const auto acl = offline::read_acl_table((fs::path(KEYANIM_ANCHORS_DIR) / "acl_shell.tsv").string(), acl_error);
  if (!acl_error.empty()) {
    std::cerr << "bench_bank: " << acl_error << "\n";
    return 1;
  }
  const std::vector<Encoded> bandai = encode_group("bandai_30fps", acl);
  const std::vector<Encoded> cmu = encode_group("cmu_120fps", acl);
  offline::BankOptions archive, runtime, always;
  runtime.runtime = true;
  always.dictionary = offline::BankDictionary::always;
  const offline::WrittenBank b_arch = offline::write_bank(inputs_of(bandai), archive);
  const offline::WrittenBank b_run = offline::write_bank(inputs_of(bandai), runtime);
  const offline::WrittenBank b_dict = offline::write_bank(inputs_of(bandai), always);
  const offline::WrittenBank c_arch = offline::write_bank(inputs_of(cmu), archive);
  const nlohmann::json out = {
      {"bandai_clips", bandai.size()},
      {"cmu_clips", cmu.size()},
      {"bandai_archive_over_acl", double(b_arch.bytes.size()) / acl_sum(bandai)},
      {"bandai_runtime_over_acl", double(b_run.bytes.size()) / acl_sum(bandai)},
      {"cmu_archive_over_acl", double(c_arch.bytes.size()) / acl_sum(cmu)},
      {"bandai_own_files_over_acl", double(own_sum(bandai)) / acl_sum(bandai)},
      {"cmu_own_files_over_acl", double(own_sum(cmu)) / acl_sum(cmu)},
      {"bandai_bytes", {{"acl_sum", acl_sum(bandai)}, {"own_files", own_sum(bandai)}, {"archive_bank", b_arch.bytes.size()},
                        {"runtime_bank", b_run.bytes.size()}, {"archive_bank_dictionary_bytes", b_arch.dictionary_bytes}}},
      {"cmu_bytes", {{"acl_sum", acl_sum(cmu)}, {"own_files", own_sum(cmu)}, {"archive_bank", c_arch.bytes.size()},
                     {"archive_bank_dictionary_bytes", c_arch.dictionary_bytes}}},
      {"dictionary_gain", b_dict.dictionary_bytes > 0 ? double(b_dict.bytes_without_dictionary) / double(b_dict.bytes.size()) : 0.0},
      {"dictionary", {{"bytes", b_dict.dictionary_bytes}, {"bank_with", b_dict.bytes.size()},
                      {"bank_without", b_dict.bytes_without_dictionary}}},
      {"open_10k", open_10k(bandai)},
      {"sample_bank_over_file", sample_ratio(bandai)},
  };
  nlohmann::json flat = out;
  flat["open_10k_ms"] = out["open_10k"].value("ms", 0.0);
  flat["open_10k_resident_bytes"] = out["open_10k"].value("resident_bytes", 0L);
  std::cout << (json ? flat.dump() : flat.dump(2)) << "\n";
  return 0;
}
