// Estimates the synthetic walk through the installed library and prints its peak vertical force.
#include <cstdio>

#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/io/marker_presets.hpp"

int main() {
  const kin2grf::Trial walk = kin2grf::make_example_walk();
  const auto* set = kin2grf::find_marker_set("kin2grf-example");
  const kin2grf::EstimateResult r = kin2grf::estimate(walk, nullptr, *set, {});
  const double peak = r.feet[0].force_N.col(1).maxCoeff();
  std::printf("kin2grf consumer: %ld frames, right foot peak vertical %.0f N\n", static_cast<long>(r.time_s.size()), peak);
  return r.time_s.size() > 100 && peak > 600 && peak < 1500 ? 0 : 1;
}
