// The corpus clips that the comparisons with ACL use (bench_vs_acl, probe_rotation_curves):
// cmu/ at 120 fps and bandai/ at 30 fps, as ../shared/anchors/acl-2.1.0/README.md groups them.
#pragma once
#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <tuple>
#include <vector>

#include "keyanim/offline/bvh.h"
#include "keyanim/offline/motion.h"

namespace bench {

// A corpus folder that cannot be listed, or a file of it that does not load (named).
struct CorpusError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct CorpusClip {
  std::filesystem::path path;
  std::string name;   // file name
  std::string group;  // "cmu120" or "bandai30"
  keyanim::offline::Motion motion;
  double rate = 0;  // frames per second, snapped to an integer within 0.05% (ACL's sample rate)
};

// 1 / frame_time, snapped to the nearest integer when within 0.05% of it (120.005 -> 120).
inline double sample_rate(double frame_time) {
  const double r = 1.0 / frame_time, n = std::round(r);
  return std::abs(r - n) <= 0.0005 * n ? n : r;
}

// The clips of cmu/ at 120 fps and bandai/ at 30 fps whose name contains `filter`, in name order.
inline std::vector<CorpusClip> find_clips(const std::filesystem::path& corpus, const std::string& filter) {
  namespace fs = std::filesystem;
  std::vector<CorpusClip> out;
  for (const auto& [dir, group, fps] : {std::tuple{"cmu", "cmu120", 120.0}, {"bandai", "bandai30", 30.0}}) {
    std::vector<fs::path> files;
    std::error_code ec;
    if (!fs::is_directory(corpus / dir)) continue;  // a corpus without this group
    for (const auto& e : fs::directory_iterator(corpus / dir, ec))
      if (e.path().extension() == ".bvh" && e.path().filename().string().find(filter) != std::string::npos)
        files.push_back(e.path());
    if (ec) throw CorpusError(corpus.string() + "/" + dir + ": " + ec.message());
    std::sort(files.begin(), files.end());
    for (const fs::path& p : files) {
      CorpusClip c{p, p.filename().string(), group, {}, 0};
      try {
        c.motion = keyanim::offline::read_bvh_file(p.string());
      } catch (const std::exception& e) {
        throw CorpusError(p.string() + ": cannot load: " + e.what());
      }
      if (c.motion.frame_count < 2 || c.motion.frame_time <= 0) continue;
      c.rate = sample_rate(c.motion.frame_time);
      if (c.rate == fps) out.push_back(std::move(c));
    }
  }
  return out;
}

}  // namespace bench
