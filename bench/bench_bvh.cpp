// BVH read/write throughput over the corpus, and the parser's cost relative to a bare
// std::from_chars loop over the same motion numbers. Prints one JSON object.
// Usage: bench_bvh [corpus_dir] [--runs N]
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "keyanim/offline/bvh.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

template <class F>
double median_seconds(int runs, F&& f) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    f();
    t.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Start of the first motion line: just after the line holding "Frame Time".
size_t motion_start(const std::string& text) {
  std::string lower(text.size(), '\0');
  std::transform(text.begin(), text.end(), lower.begin(), [](char c) {
    return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c;
  });
  size_t p = lower.find("frame time");
  if (p == std::string::npos) return text.size();
  p = text.find_first_of("\r\n", p);
  return p == std::string::npos ? text.size() : p;
}

// The baseline: skip whitespace, from_chars, store. No checks beyond what from_chars does.
size_t from_chars_loop(const char* p, const char* end, double* out) {
  size_t n = 0;
  while (p != end) {
    if (static_cast<unsigned char>(*p) <= ' ') {
      ++p;
      continue;
    }
    const auto r = std::from_chars(p, end, out[n]);
    if (r.ptr == p) {
      ++p;
      continue;
    }
    ++n;
    p = r.ptr;
  }
  return n;
}

double mb_per_s(size_t bytes, double seconds) { return seconds > 0 ? double(bytes) / seconds / 1e6 : 0.0; }

}  // namespace

int main(int argc, char** argv) {
  fs::path dir = KEYANIM_CORPUS_DIR;
  int runs = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else dir = a;
  }
  std::vector<fs::path> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec))
    if (it->is_regular_file() && it->path().extension() == ".bvh") files.push_back(it->path());
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "bench_bvh: no .bvh files under %s\n", dir.string().c_str());
    return 1;
  }

  nlohmann::json per_file = nlohmann::json::array();
  size_t total_bytes = 0, total_written = 0, total_values = 0;
  double total_parse = 0, total_write = 0, total_from_chars = 0;
  for (const fs::path& path : files) {
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

    keyanim::offline::Motion motion;
    try {
      motion = keyanim::offline::read_bvh(text, path.string());
    } catch (const keyanim::offline::Error& e) {
      std::fprintf(stderr, "bench_bvh: %s\n", e.what());
      return 1;
    }
    const double parse_s = median_seconds(runs, [&] { keyanim::offline::read_bvh(text, path.string()); });
    std::string written;
    const double write_s = median_seconds(runs, [&] { written = keyanim::offline::write_bvh(motion); });

    const size_t start = motion_start(text);
    std::vector<double> sink(motion.values.size() + 1);
    size_t numbers = 0;
    const double from_chars_s = median_seconds(
        runs, [&] { numbers = from_chars_loop(text.data() + start, text.data() + text.size(), sink.data()); });
    if (numbers != motion.values.size()) {
      std::fprintf(stderr, "bench_bvh: %s: baseline found %zu numbers, parser %zu\n", path.string().c_str(), numbers,
                   motion.values.size());
      return 1;
    }

    per_file.push_back({{"file", fs::relative(path, dir).string()},
                        {"bytes", text.size()},
                        {"frames", motion.frame_count},
                        {"channels", motion.channel_count()},
                        {"parse_ms", parse_s * 1e3},
                        {"parse_mb_s", mb_per_s(text.size(), parse_s)},
                        {"write_bytes", written.size()},
                        {"write_ms", write_s * 1e3},
                        {"write_mb_s", mb_per_s(written.size(), write_s)},
                        {"from_chars_ms", from_chars_s * 1e3},
                        {"parse_over_from_chars", from_chars_s > 0 ? parse_s / from_chars_s : 0.0}});
    total_bytes += text.size();
    total_written += written.size();
    total_values += motion.values.size();
    total_parse += parse_s;
    total_write += write_s;
    total_from_chars += from_chars_s;
  }

  const nlohmann::json out = {
      {"bench", "bvh"},
      {"runs", runs},
      {"note", "medians per file; from_chars = bare skip-space/from_chars/store loop over the motion numbers"},
      {"files", per_file},
      {"total",
       {{"files", files.size()},
        {"bytes", total_bytes},
        {"values", total_values},
        {"parse_ms", total_parse * 1e3},
        {"parse_mb_s", mb_per_s(total_bytes, total_parse)},
        {"write_bytes", total_written},
        {"write_ms", total_write * 1e3},
        {"write_mb_s", mb_per_s(total_written, total_write)},
        {"from_chars_ms", total_from_chars * 1e3},
        {"from_chars_mb_s", mb_per_s(total_bytes, total_from_chars)},
        {"parse_over_from_chars", total_from_chars > 0 ? total_parse / total_from_chars : 0.0}}}};
  std::cout << out.dump(2) << "\n";
  return 0;
}
