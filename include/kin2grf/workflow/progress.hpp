// kin2grf progress lines for long runs, as the command line shows them on stderr: rewritten in
// place on a terminal, a line at a time in a log (a file, a pipe, a CI job). The core reports
// progress through callbacks and prints nothing; these are the callbacks the front ends give it.
#pragma once

#include <cstdio>
#include <functional>

#include "kin2grf/workflow/batch.hpp"

namespace kin2grf {

/// The contact solve's progress (EstimateOptions::progress) for runs of at least `min_frames`
/// frames: a percentage, every 1 % on a terminal, every 10 % in a log.
std::function<void(long, long)> solve_progress(std::FILE* out, long min_frames = 20000);

/// A batch's progress (BatchOptions::progress): a bar with the trials done, the elapsed time and
/// the trial just finished on a terminal; one line per trial in a log.
std::function<void(std::size_t, std::size_t, const BatchRow&)> batch_progress(std::FILE* out);

}  // namespace kin2grf
