// kin2grf I/O: open any supported recording by its extension (.c3d, .trc, .mot, .sto).
#pragma once

#include <string>

#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/trial.hpp"

namespace kin2grf {

struct LoadOptions {
  C3dReadOptions c3d;
  double cop_threshold_N = 10.0;  ///< also used for GRF .mot files
};

Trial load_trial(const std::string& path, const LoadOptions& options = {});

}  // namespace kin2grf
