#include "kin2grf/parallel.hpp"

#include <cstdlib>

namespace kin2grf {

namespace {
thread_local int t_thread_count = 0;  // 0: the default
}

int thread_count() {
  if (t_thread_count > 0) return t_thread_count;
  static const int cores = [] {
    // KIN2GRF_THREADS, as OMP_NUM_THREADS: a shared machine's user may ask for fewer.
    if (const char* env = std::getenv("KIN2GRF_THREADS")) {
      char* end = nullptr;
      const long n = std::strtol(env, &end, 10);
      if (end != env && *end == '\0' && n >= 1) return static_cast<int>(std::min(n, 256L));
    }
    return static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
  }();
  return cores;
}

void set_thread_count(int n) { t_thread_count = std::max(0, n); }

ThreadCountScope::ThreadCountScope(int n) : previous_(t_thread_count) { set_thread_count(n); }
ThreadCountScope::~ThreadCountScope() { t_thread_count = previous_; }

std::vector<std::size_t> chunk_bounds(std::size_t n, std::size_t min_chunk, int threads) {
  const std::size_t most = std::max<std::size_t>(1, n / std::max<std::size_t>(1, min_chunk));
  const std::size_t chunks = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(1, threads)), 1, most);
  std::vector<std::size_t> b(chunks + 1);
  for (std::size_t c = 0; c <= chunks; ++c) b[c] = n * c / chunks;
  return b;
}

}  // namespace kin2grf
