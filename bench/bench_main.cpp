// kin2grf benchmarks (Google Benchmark). Run: build/release/bench/kin2grf_bench
// Figures are reported in the README with the command that produced them.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/text.hpp"

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

}  // namespace

BENCHMARK_MAIN();
