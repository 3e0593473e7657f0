// kin2grf: small numeric helpers shared by the pipeline's steps.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace kin2grf {

/// A missing value (no sample, not measured, not defined).
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Median (upper middle element for an even count); NaN for an empty vector.
inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// R(a): the plane rotation by a (rad, counter-clockwise).
inline Eigen::Matrix2d rotation(double a) {
  Eigen::Matrix2d R;
  R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return R;
}

/// The sagittal moment (N m, counter-clockwise +) about the origin of a force (fx, fy) (N)
/// applied at (rx, ry) (m): rx fy - ry fx. The one place kin2grf writes it.
inline double sagittal_moment(double rx, double ry, double fx, double fy) { return rx * fy - ry * fx; }

/// Where the parabola through (-1, y0), (0, y1), (1, y2) has its vertex, as an offset from 0:
/// refines an extremum found at a sample between it and its neighbours. 0 unless the parabola
/// opens the way the extremum needs (upward for a minimum, downward for a maximum).
inline double parabola_vertex_offset(double y0, double y1, double y2, bool maximum) {
  const double den = y0 - 2 * y1 + y2;
  return (maximum ? den < 0 : den > 0) ? 0.5 * (y0 - y2) / den : 0.0;
}

/// r turned by +90 degrees: d/da (R(a) rho) = perp(R(a) rho).
inline Eigen::Vector2d perp(const Eigen::Vector2d& r) { return Eigen::Vector2d(-r.y(), r.x()); }

/// Consecutive indices first..last (inclusive) where a condition holds.
struct IndexRun {
  Eigen::Index first = 0, last = -1;
};

/// The runs of 0..n-1 where holds(i) is true, in order.
template <class Holds>
std::vector<IndexRun> runs_where(Eigen::Index n, Holds holds) {
  std::vector<IndexRun> out;
  for (Eigen::Index i = 0; i < n;) {
    if (!holds(i)) {
      ++i;
      continue;
    }
    Eigen::Index k = i;
    while (k < n && holds(k)) ++k;
    out.push_back({i, k - 1});
    i = k;
  }
  return out;
}

/// `runs` (in order) with those separated by at most max_gap indices joined into one.
inline std::vector<IndexRun> merge_close_runs(const std::vector<IndexRun>& runs, Eigen::Index max_gap) {
  std::vector<IndexRun> out;
  for (const IndexRun& r : runs) {
    if (!out.empty() && r.first - out.back().last - 1 <= max_gap) out.back().last = r.last;
    else out.push_back(r);
  }
  return out;
}

/// The runs where v is above thr (NaN is not).
inline std::vector<IndexRun> runs_above(const Eigen::Ref<const Eigen::VectorXd>& v, double thr) {
  return runs_where(v.size(), [&](Eigen::Index i) { return std::isfinite(v[i]) && v[i] > thr; });
}

}  // namespace kin2grf
