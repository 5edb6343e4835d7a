#include "offline/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace keyanim::offline {

unsigned resolve_threads(unsigned requested) noexcept {
  return requested ? requested : std::max(1u, std::thread::hardware_concurrency());
}

unsigned parallel_workers(size_t count, unsigned threads) noexcept {
  return unsigned(std::max<size_t>(1, std::min<size_t>(resolve_threads(threads), count)));
}

void parallel_for(size_t count, unsigned threads, const std::function<void(size_t, unsigned)>& job) {
  const unsigned n = parallel_workers(count, threads);
  if (n <= 1) {
    for (size_t i = 0; i < count; ++i) job(i, 0);
    return;
  }
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  size_t failed_index = count;
  std::exception_ptr error;
  auto work = [&](unsigned worker) {
    for (size_t i; !failed.load(std::memory_order_relaxed) && (i = next.fetch_add(1)) < count;) {
      try {
        job(i, worker);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (i < failed_index) failed_index = i, error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(n - 1);
  try {
    for (unsigned t = 1; t < n; ++t) pool.emplace_back(work, t);
  } catch (...) {  // no thread to be had: the ones started and this one do the work
  }
  work(0);
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace keyanim::offline
