// Storage handed from one clip's encode to the next on the same thread. Internal to the encoder.
//
// The tables an encode holds for all its rounds (OriginalPoints, Signals) are a megabyte or so
// on short clips; allocated fresh per clip, each came back as page faults every time (glibc
// returns the top of its heap to the system when it is freed): Bandai bow_feminine_001's encode
// took 11.5 ms instead of 9.0 (one thread, median of 15 in one process). A table takes the
// thread's spare vector of its type and gives its own back when it is done, if it is within its
// budget; so a thread keeps at most one budget's worth per type between encodes, and none
// after a clip whose tables are over it.
#pragma once
#include <cstddef>
#include <utility>
#include <vector>

namespace keyanim::offline {

template <class T>
std::vector<T>& thread_spare() {
  thread_local std::vector<T> spare;
  return spare;
}

// The thread's spare storage for a table of T (empty, with whatever capacity it had).
template <class T>
std::vector<T> take_spare() {
  std::vector<T> v = std::move(thread_spare<T>());
  thread_spare<T>() = {};
  v.clear();
  return v;
}

// Frees the thread's spare storage of T: a table over its budget is not held, and the clip
// that needs none should not carry an earlier clip's (its memory may be a target).
template <class T>
void drop_spare() {
  std::vector<T>().swap(thread_spare<T>());
}

// Keeps `v`'s storage for the next table of T on this thread if it takes at most `budget`
// bytes and is larger than what is kept.
template <class T>
void give_spare(std::vector<T>&& v, size_t budget) {
  std::vector<T>& spare = thread_spare<T>();
  if (v.capacity() * sizeof(T) <= budget && v.capacity() > spare.capacity()) spare = std::move(v);
}

}  // namespace keyanim::offline
