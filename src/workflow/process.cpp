#include "kin2grf/workflow/process.hpp"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>

namespace kin2grf {

namespace {
void* g_heap_below_huge_pages = nullptr;  // kept, never freed (reachable, for leak checkers)
std::uintptr_t g_huge_begin = 0, g_huge_end = 0;  // the heap's range advised for huge pages
}

void tune_allocator_for_a_short_run() {
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  mallopt(M_TOP_PAD, 32 << 20);
  mallopt(M_ARENA_MAX, 1);
  // Huge pages start at a 2 MB boundary of the heap. The part below it is taken by one block that
  // is never used (its untouched pages cost no memory), so that every allocation lands where pages
  // are huge. Nothing above the boundary may be written before the madvise, or that 2 MB would be
  // mapped page by page: the block ends (and malloc writes the top chunk's header) 32 KB below it.
  const auto huge = std::uintptr_t{2} << 20;
  const auto before = reinterpret_cast<std::uintptr_t>(sbrk(0));
  const auto start = (before + (64 << 10) + huge - 1) & ~(huge - 1);
  g_heap_below_huge_pages = std::malloc(start - before - (32 << 10));  // the heap grows by it and the pad
  const auto after = reinterpret_cast<std::uintptr_t>(sbrk(0));
  if (g_heap_below_huge_pages && after > start && madvise(reinterpret_cast<void*>(start), after - start, MADV_HUGEPAGE) == 0)
    g_huge_begin = start, g_huge_end = after;
}

void tune_allocator_for_a_long_run() {
  // Pages already huge stay so (the first few MB); later faults in the range are 4 KB.
  if (g_huge_end > g_huge_begin)
    madvise(reinterpret_cast<void*>(g_huge_begin), g_huge_end - g_huge_begin, MADV_NOHUGEPAGE);
  g_huge_begin = g_huge_end = 0;
}

void allow_allocator_arenas(int threads) {
  if (threads > 1) mallopt(M_ARENA_MAX, threads);
}

}  // namespace kin2grf
