// parallel_for: every index exactly once, in order on one thread, really concurrent on two,
// and failures reported by the smallest failing index.
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "offline/parallel.h"

using keyanim::offline::parallel_for;
using keyanim::offline::resolve_threads;

TEST_SUITE("parallel") {
  TEST_CASE("every index runs exactly once whatever the thread count") {
    for (unsigned threads : {0u, 1u, 2u, 3u, 8u}) {
      for (size_t count : {size_t(0), size_t(1), size_t(2), size_t(1000)}) {
        std::vector<std::atomic<int>> runs(count);
        parallel_for(count, threads, [&](size_t i, unsigned) { runs[i].fetch_add(1); });
        int wrong = 0;
        for (auto& r : runs) wrong += r.load() != 1;
        CAPTURE(threads);
        CAPTURE(count);
        CHECK(wrong == 0);
      }
    }
  }

  TEST_CASE("one thread runs the jobs in order on the caller's thread") {
    std::vector<size_t> order;
    const auto caller = std::this_thread::get_id();
    bool same_thread = true;
    parallel_for(50, 1, [&](size_t i, unsigned) {
      order.push_back(i);
      same_thread &= std::this_thread::get_id() == caller;
    });
    REQUIRE(order.size() == 50);
    for (size_t i = 0; i < order.size(); ++i) CHECK(order[i] == i);
    CHECK(same_thread);
  }

  TEST_CASE("two threads run two jobs at the same time") {
    // Each job waits (up to a generous 10 s) until both have started: run one after the other,
    // the first would wait in vain and see only itself.
    std::atomic<int> started{0};
    std::vector<int> seen(2, 0);
    parallel_for(2, 2, [&](size_t i, unsigned) {
      started.fetch_add(1);
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (started.load() < 2 && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
      seen[i] = started.load();
    });
    CHECK(seen[0] == 2);
    CHECK(seen[1] == 2);
  }

  TEST_CASE("a failing job's exception reaches the caller, after every thread has stopped") {
    for (unsigned threads : {1u, 2u, 4u}) {
      std::atomic<int> running{0};
      std::string what;
      try {
        parallel_for(100, threads, [&](size_t i, unsigned) {
          running.fetch_add(1);
          if (i == 37) {
            running.fetch_sub(1);
            throw std::runtime_error("job 37");
          }
          running.fetch_sub(1);
        });
      } catch (const std::runtime_error& e) {
        what = e.what();
      }
      CAPTURE(threads);
      CHECK(what == "job 37");
      CHECK(running.load() == 0);
    }
    // Several failures: the smallest failing index wins (one thread: the first to fail).
    std::string what;
    try {
      parallel_for(10, 1, [&](size_t i, unsigned) {
        if (i >= 3) throw std::runtime_error("job " + std::to_string(i));
      });
    } catch (const std::runtime_error& e) {
      what = e.what();
    }
    CHECK(what == "job 3");
  }

  TEST_CASE("zero threads means one per core, and workers are numbered below parallel_workers") {
    CHECK(resolve_threads(0) >= 1);
    CHECK(resolve_threads(3) == 3);
    CHECK(keyanim::offline::parallel_workers(2, 8) == 2);
    CHECK(keyanim::offline::parallel_workers(0, 8) == 1);
    CHECK(keyanim::offline::parallel_workers(100, 3) == 3);
    std::vector<std::atomic<int>> by_worker(3);
    parallel_for(300, 3, [&](size_t, unsigned w) { by_worker.at(w).fetch_add(1); });
    CHECK(by_worker[0] + by_worker[1] + by_worker[2] == 300);
  }
}
