#include "kin2grf/workflow/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <string>

namespace kin2grf {

std::function<void(long, long)> solve_progress(std::FILE* out, long min_frames) {
  const bool tty = isatty(fileno(out)) != 0;
  return [out, tty, min_frames, last = -1](long done, long all) mutable {
    if (all < min_frames) return;
    const int pct = static_cast<int>(100 * done / std::max(1L, all));
    if (pct / 10 == last / 10 && pct != 100 && !tty) return;
    if (pct == last) return;
    last = pct;
    std::fprintf(out, tty ? "\rkin2grf: contact solve %3d %% (%ld of %ld frames)" : "kin2grf: contact solve %3d %% (%ld of %ld frames)\n",
                 pct, done, all);
    if (tty && pct == 100) std::fputc('\n', out);
  };
}

std::function<void(std::size_t, std::size_t, const BatchRow&)> batch_progress(std::FILE* out) {
  const bool tty = isatty(fileno(out)) != 0;
  const auto start = std::chrono::steady_clock::now();
  return [out, tty, start](std::size_t done, std::size_t all, const BatchRow& row) {
    const int width = 30;
    const int filled = static_cast<int>(width * done / std::max<std::size_t>(1, all));
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string what = row.ok ? row.name : row.name + " FAILED";
    if (tty)
      std::fprintf(out, "\r[%s%s] %zu/%zu  %.0f s  %-40.40s", std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(width - filled), '.').c_str(), done, all, elapsed, what.c_str());
    else
      std::fprintf(out, "kin2grf: batch %zu/%zu (%.0f s): %s\n", done, all, elapsed, what.c_str());
    if (tty && done == all) std::fputc('\n', out);
  };
}

}  // namespace kin2grf
