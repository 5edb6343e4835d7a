#include "batch.h"


#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <system_error>
#include <thread>

#include "escape.h"
#include "progress.h"

namespace keyanim::cli {

std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs, const std::vector<std::string>& extensions) {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  for (const std::string& in : inputs) {
    std::error_code ec;
    if (in == "-" || !fs::is_directory(in, ec)) {
      out.push_back(in);
      continue;
    }
    std::vector<std::string> found;
    for (auto it = fs::recursive_directory_iterator(in, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
      std::string ext = it->path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
      if (it->is_regular_file(ec) && std::find(extensions.begin(), extensions.end(), ext) != extensions.end())
        found.push_back(it->path().string());
    }
    if (ec) fail(kBadInput, in + ": cannot list: " + ec.message());
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  }
  return out;
}

unsigned thread_count(const Args& args) {
  // More threads than cores would not go faster, only take more memory (and a huge -j, if
  // obeyed, could exhaust the machine's threads).
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const uint32_t j = args.get_uint("-j", 0);
  return j ? std::min<unsigned>(j, cores) : cores;
}

int run_batch(size_t count, unsigned threads, const Globals& g, const std::function<void(size_t)>& job,
              const std::vector<std::string>& names) {
  std::vector<int> codes(count, kOk);
  std::atomic<size_t> next{0};
  std::mutex out_mutex;
  // The bar counts bytes of input done, so that its time left holds with files of all sizes
  // (inputs, for a list so long that asking every size first would delay the start: a manifest).
  Globals shown = g;
  if (count < 2) shown.verbosity = 0;
  Progress bar(shown, std::to_string(count) + " inputs");
  std::vector<uint64_t> sizes(count, 1);
  uint64_t total = 0, done_bytes = 0;
  size_t done = 0;
  for (size_t i = 0; i < count && bar.shown() && count <= 10000; ++i) {
    std::error_code ec;
    sizes[i] = std::max<uint64_t>(1, std::filesystem::file_size(names[i], ec));
  }
  for (uint64_t s : sizes) total += s;
  auto progress = [&] {  // caller holds out_mutex
    bar.update(std::to_string(done) + " done", double(done_bytes) / double(total));
  };
  progress();
  auto worker = [&] {
    for (size_t i; (i = next.fetch_add(1)) < count;) {
      std::string message;
      try {
        job(i);
      } catch (const Failure& f) {
        codes[i] = f.code;
        message = f.message;
      } catch (const std::exception& e) {
        const Failure f = failure_of(e);
        codes[i] = f.code;
        message = names[i] + ": " + f.message;
      }
      std::lock_guard<std::mutex> lock(out_mutex);
      ++done, done_bytes += sizes[i];
      if (!message.empty()) {
        bar.erase();
        std::cerr << "keyanim: " << printable(message) << "\n";
      }
      progress();
    }
  };
  std::vector<std::thread> pool;
  const unsigned n = std::max(1u, std::min<unsigned>(threads, unsigned(count)));
  try {
    for (unsigned t = 1; t < n; ++t) pool.emplace_back(worker);
  } catch (const std::system_error&) {
    // Out of threads: the ones started (and this one) do all the work.
  }
  worker();
  for (std::thread& t : pool) t.join();
  bar.erase();
  size_t failed = 0;
  int first = kOk;
  for (int c : codes)
    if (c != kOk) ++failed, first = first == kOk ? c : first;
  if (failed && count > 1) std::cerr << "keyanim: " << failed << " of " << count << " inputs failed\n";
  return first;
}

}  // namespace keyanim::cli
