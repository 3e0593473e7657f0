#pragma once
// Splitting a loop over frames, rows or columns across the machine's cores.
//
// kin2grf's long loops (parsing a text file's rows, the per-frame contact solve, filtering columns)
// have independent iterations, so each contiguous chunk runs on its own thread with its own
// workspace and writes only its own rows: the result is the same, bit for bit, whatever the
// number of threads. An error is reported as a sequential run would report it: the exception of
// the earliest chunk that threw.

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace kin2grf {

/// The threads kin2grf's loops may use: set_thread_count()'s value on this thread, else
/// KIN2GRF_THREADS (as OMP_NUM_THREADS), else the machine's cores (at most 8). A batch running
/// several trials at once sets 1 on its workers.
int thread_count();

/// n >= 1 sets the count for the calling thread; 0 returns it to the default.
void set_thread_count(int n);

/// Sets a thread count for the calling thread while in scope.
class ThreadCountScope {
 public:
  explicit ThreadCountScope(int n);
  ~ThreadCountScope();
  ThreadCountScope(const ThreadCountScope&) = delete;
  ThreadCountScope& operator=(const ThreadCountScope&) = delete;

 private:
  int previous_;
};

/// The least work worth a thread of its own, in seconds. Starting a thread and waking an idle
/// core takes 0.1-2 ms on a virtual machine (measured on a 2-core VM), and threads of a short run
/// wait on each other at the allocator's lock; below this a loop stays on its thread (a
/// 500-frame trial is read and solved on one core, a 12,000-frame one on all of them).
inline constexpr double kMinSecondsPerChunk = 0.005;

/// The fewest items per chunk for items that take about `seconds_per_item` each.
inline std::size_t min_chunk_for(double seconds_per_item) {
  return seconds_per_item > 0 ? static_cast<std::size_t>(kMinSecondsPerChunk / seconds_per_item) + 1 : 1;
}

/// The chunks [begin, end) that for_chunks() gives n items with at least `min_chunk` per chunk.
std::vector<std::size_t> chunk_bounds(std::size_t n, std::size_t min_chunk, int threads);

/// fn(chunk, begin, end) over [0, n) in contiguous chunks, one per thread (the first on the
/// calling thread); the earliest chunk's exception, if any, is rethrown after all have finished.
template <class Fn>
void for_chunks(std::size_t n, std::size_t min_chunk, Fn&& fn) {
  const std::vector<std::size_t> b = chunk_bounds(n, min_chunk, thread_count());
  const std::size_t chunks = b.size() - 1;
  if (chunks <= 1) {
    if (n > 0) fn(std::size_t{0}, std::size_t{0}, n);
    return;
  }
  std::vector<std::exception_ptr> errors(chunks);
  auto run = [&](std::size_t c) {
    const ThreadCountScope inner(1);  // a loop inside a chunk runs on the chunk's thread
    try {
      fn(c, b[c], b[c + 1]);
    } catch (...) {
      errors[c] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(chunks - 1);
  for (std::size_t c = 1; c < chunks; ++c) threads.emplace_back(run, c);
  run(0);
  for (auto& t : threads) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace kin2grf
