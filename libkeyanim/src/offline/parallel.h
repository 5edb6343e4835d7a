// The encoder's one way of running work on several threads. Internal to libkeyanim's offline side.
#pragma once
#include <cstddef>
#include <functional>

namespace keyanim::offline {

// 0 means one thread per core; anything else is taken as is.
unsigned resolve_threads(unsigned requested) noexcept;

// How many threads parallel_for(count, threads, ...) uses: its workers are numbered
// 0 .. workers - 1, so that callers can give each its own scratch memory.
unsigned parallel_workers(size_t count, unsigned threads) noexcept;

// Runs job(i, worker) for every i in [0, count) on at most `threads` threads (the caller's
// among them, as worker 0; 0: one per core), handing indices out in increasing order as
// threads become free, and returns when every job has finished. With one thread, or one job, everything runs on the
// caller's thread in order. If jobs throw, the remaining indices are skipped and the exception
// of the smallest failing index is rethrown once all threads have stopped. Results must not
// depend on which thread ran a job: callers write job i's output to slot i.
void parallel_for(size_t count, unsigned threads, const std::function<void(size_t, unsigned)>& job);

}  // namespace keyanim::offline
