// kin2grf: small numeric helpers shared by the pipeline's steps.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

namespace kin2grf {

/// Median (upper middle element for an even count); NaN for an empty vector.
inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace kin2grf
