// kin2grf benchmarks (Google Benchmark). Run: build/release/bench/kin2grf_bench
// Figures are reported in the README with the command that produced them.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/io/marker_presets.hpp"

// Every heap allocation of the process is counted (the per-frame solve must make none): malloc,
// calloc and realloc are interposed and passed to glibc's own (operator new and Eigen allocate
// through malloc).
namespace {
std::atomic<long> g_allocations{0};
}  // namespace
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
}

namespace {

std::string data_file(const std::string& rel) {
  const char* env = std::getenv("KIN2GRF_DATA_DIR");
  return (std::filesystem::path(env && *env ? env : KIN2GRF_DATA_DIR) / rel).string();
}

void BM_ReadC3dWalking2(benchmark::State& state) {
  const std::string path = data_file("opensim_c3d_overground_walk/walking2.c3d");
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("shared data not found");
    return;
  }
  const auto bytes = kin2grf::read_file_bytes(path);
  long frames = 0;
  for (auto _ : state) {
    const auto t = kin2grf::read_c3d_bytes(bytes, path);
    frames += t.markers.frames();
    benchmark::DoNotOptimize(t);
  }
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReadC3dWalking2)->Unit(benchmark::kMillisecond);

/// Reading text: Rajagopal's treadmill run (TRC, 42 markers, 510 rows of printf-padded
/// numbers), the file's text already in memory, so that only the parse is timed.
void BM_ParseTrcRun(benchmark::State& state) {
  const std::string path = data_file("rajagopal2016_treadmill_run/motion_capture_run.trc");
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("shared data not found");
    return;
  }
  const std::string text = kin2grf::read_file_text(path);
  long frames = 0;
  for (auto _ : state) {
    const auto m = kin2grf::parse_trc(text, path);
    frames += m.frames();
    benchmark::DoNotOptimize(m);
  }
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  state.counters["MB_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(text.size()) / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ParseTrcRun)->Unit(benchmark::kMillisecond);

/// A trial to run the method on: Rajagopal's overground walk (shared data) or, without the
/// data, the synthetic squat (always available).
struct Workload {
  kin2grf::Trial trial;
  const kin2grf::MarkerSet* set = nullptr;
  kin2grf::EstimateOptions options;
  bool ok = false;
};

Workload workload(bool real) {
  Workload w;
  if (real) {
    const std::string path = data_file("rajagopal2016_overground_walk/markers_walk.trc");
    if (!std::filesystem::exists(path)) return w;
    w.trial = kin2grf::load_trial(path);
    w.options.mass_kg = 85.27;
    w.set = kin2grf::recognise_marker_set(w.trial.markers);
  } else {
    kin2grf::SyntheticOptions so;
    so.duration_s = 10.0;
    w.trial = kin2grf::make_synthetic_trial(so);
    w.set = kin2grf::find_marker_set("kin2grf-example");
  }
  w.ok = w.set != nullptr;
  return w;
}

/// The per-frame contact problem alone (Eqs. 5-10 with the active-set iterations): motion and
/// contact points prepared once, ContactSolver::solve timed over every frame.
void BM_ContactSolvePerFrame(benchmark::State& state) {
  const Workload w = workload(state.range(0) == 1);
  if (!w.ok) {
    state.SkipWithError("shared data not found");
    return;
  }
  const auto r = kin2grf::estimate(w.trial, nullptr, *w.set, w.options);
  kin2grf::ModelMotion motion = kin2grf::compute_motion(r.model(), r.landmarks, w.options.kinematic_cutoff_hz, w.options.torso_length);
  kin2grf::ContactSolver solver(r.model(), r.calibration, w.options.solver);
  const Eigen::Index n = motion.frames();
  // Each frame's q, qdd and contacts made once, outside the timing (the pipeline makes them per
  // frame as it solves it).
  std::vector<kin2grf::MotionFrame> frame(static_cast<std::size_t>(n));
  std::vector<kin2grf::FrameContacts> contacts(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    motion.frame(i, frame[k]);
    kin2grf::contact_frame(r.model(), r.calibration.contact, w.options.contact, false, frame[k], contacts[k]);
  }
  long frames = 0, allocations = 0;
  for (auto _ : state) {
    const long before = g_allocations.load();
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto& f = frame[static_cast<std::size_t>(i)];
      auto s = solver.solve(f.q, f.qdd, contacts[static_cast<std::size_t>(i)]);
      benchmark::DoNotOptimize(s);
    }
    allocations += g_allocations.load() - before;
    frames += n;
  }
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  // Heap allocations per frame inside the solve (malloc, calloc, realloc: operator new and Eigen too).
  state.counters["allocations_per_frame"] = static_cast<double>(allocations) / static_cast<double>(std::max(1L, frames));
}
BENCHMARK(BM_ContactSolvePerFrame)->Arg(0)->Arg(1)->ArgNames({"real"})->Unit(benchmark::kMillisecond);

/// The whole method on a loaded trial: landmarks, sagittal frame, model, kinematics, contact
/// solve, post-filter, outputs in memory (file reading excluded; see BM_ReadC3dWalking2).
/// `3d`: the 3D model (--model 3d: the mediolateral force, the COP's lateral place and the 3D
/// ankle and knee moments on top).
void BM_EstimatePipeline(benchmark::State& state) {
  Workload w = workload(state.range(0) == 1);
  if (!w.ok) {
    state.SkipWithError("shared data not found");
    return;
  }
  if (state.range(1) == 1) w.options.model = kin2grf::ModelKind::ThreeD;
  long frames = 0;
  for (auto _ : state) {
    const auto r = kin2grf::estimate(w.trial, nullptr, *w.set, w.options);
    frames += r.time_s.size();
    benchmark::DoNotOptimize(r);
  }
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EstimatePipeline)->Args({0, 0})->Args({1, 0})->Args({1, 1})->ArgNames({"real", "3d"})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
