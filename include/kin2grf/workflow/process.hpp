// kin2grf workflow: settings of the whole process, for a program that runs one job and exits
// (the command-line tool). A library user's program keeps its own allocator settings.
#pragma once

namespace kin2grf {

/// One short run touches a few MB of fresh heap, and on a virtual machine each 4 KB page fault
/// costs about 10 us: half of a 500-frame estimate. This makes the heap grow in 32 MB steps
/// backed by huge pages where the kernel allows (madvise), keeps freed blocks for reuse rather
/// than unmapping them, and has threads share that heap. A 510-frame estimate then takes 200
/// page faults, not 900. Blocks of 1 MB or more are mapped on their own and returned when freed
/// once they no longer fit in the heap's free top: kept in the heap they left holes that a long
/// trial's peak memory carried (0.97 -> 0.59 GB on a 557 MB capture). Call it first in
/// main(), before anything is allocated.
void tune_allocator_for_a_short_run();
/// A long run's time is its frames', not its page faults', and a huge page is resident whole from
/// its first write: a reader filling each marker's series row by row while it lets the file's
/// text go would hold all the series at their first row (a 600 s TRC: 46 -> 34 MB peak, the same
/// time). This takes the huge pages back from the heap's future faults. Call it once a run is
/// known to be long (the command line: a trial file of 8 MB or more).
void tune_allocator_for_a_long_run();
/// Work on `threads` threads that each allocate (a batch of trials): one heap arena per thread,
/// so that they do not wait on each other's malloc lock (a batch on 2 threads: 1.71-1.76 x one
/// thread with the one shared heap above, 1.78-1.80 x with one per thread). Call before the
/// threads start.
void allow_allocator_arenas(int threads);

}  // namespace kin2grf
