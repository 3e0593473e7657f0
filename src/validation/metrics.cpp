#include "kin2grf/validation/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kin2grf {

std::optional<SeriesMetrics> compare_series(const Eigen::VectorXd& est, const Eigen::VectorXd& meas) {
  const Eigen::Index n = std::min(est.size(), meas.size());
  double se = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, maxe = 0;
  double amin = std::numeric_limits<double>::infinity(), amax = -amin, bmin = amin, bmax = -amin;
  int k = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double a = est[i], b = meas[i];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    ++k;
    se += (a - b) * (a - b);
    maxe = std::max(maxe, std::abs(a - b));
    sa += a, sb += b;
    amin = std::min(amin, a), amax = std::max(amax, a), bmin = std::min(bmin, b), bmax = std::max(bmax, b);
  }
  if (k < 2) return std::nullopt;
  const double ma = sa / k, mb = sb / k;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double a = est[i], b = meas[i];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    saa += (a - ma) * (a - ma), sbb += (b - mb) * (b - mb), sab += (a - ma) * (b - mb);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SeriesMetrics m;
  m.samples = k;
  m.rmse = std::sqrt(se / k);
  const double mean_range = 0.5 * ((amax - amin) + (bmax - bmin));
  m.rrmse_percent = mean_range > 0 ? 100.0 * m.rmse / mean_range : nan;
  m.pearson_r = (saa > 0 && sbb > 0) ? sab / std::sqrt(saa * sbb) : nan;
  m.max_abs_error = maxe;
  m.peak_difference = amax - bmax;
  m.mean_error = ma - mb;
  return m;
}

std::optional<double> rising_crossing(const Eigen::VectorXd& v, const Eigen::VectorXd& t, double thr, Eigen::Index from,
                                      Eigen::Index to) {
  from = std::max<Eigen::Index>(from, 0);
  to = std::min<Eigen::Index>(to, v.size() - 1);
  for (Eigen::Index i = from; i <= to; ++i) {
    if (v[i] <= thr) continue;
    if (i == 0 || v[i - 1] > thr) return t[i];
    const double w = (thr - v[i - 1]) / (v[i] - v[i - 1]);
    return t[i - 1] + w * (t[i] - t[i - 1]);
  }
  return std::nullopt;
}

std::optional<double> falling_crossing(const Eigen::VectorXd& v, const Eigen::VectorXd& t, double thr, Eigen::Index from,
                                       Eigen::Index to) {
  from = std::max<Eigen::Index>(from, 0);
  to = std::min<Eigen::Index>(to, v.size() - 1);
  for (Eigen::Index i = to; i >= from; --i) {
    if (v[i] <= thr) continue;
    if (i + 1 >= v.size() || v[i + 1] > thr) return t[i];
    const double w = (v[i] - thr) / (v[i] - v[i + 1]);
    return t[i] + w * (t[i + 1] - t[i]);
  }
  return std::nullopt;
}

namespace {
/// The largest finite value of v over [from, to] (clamped to v), or NaN.
double peak_over(const Eigen::VectorXd& v, Eigen::Index from, Eigen::Index to) {
  double peak = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index i = std::max<Eigen::Index>(from, 0); i <= std::min<Eigen::Index>(to, v.size() - 1); ++i)
    if (std::isfinite(v[i]) && !(v[i] <= peak)) peak = v[i];
  return peak;
}
/// The ramp through v's crossings of lo and hi times `peak` in [from, to], extended to zero: the
/// rising crossings with t_hi after t_lo (`loading`), else the falling ones with t_hi before.
/// nullopt without a positive peak, either crossing, or that order.
std::optional<double> ramp_zero(const Eigen::VectorXd& v, const Eigen::VectorXd& t, double peak, Eigen::Index from, Eigen::Index to,
                                double lo, double hi, bool loading) {
  if (!(peak > 0) || !(hi > lo)) return std::nullopt;
  const auto crossing = [&](double level) {
    return loading ? rising_crossing(v, t, level * peak, from, to) : falling_crossing(v, t, level * peak, from, to);
  };
  const auto t_lo = crossing(lo), t_hi = crossing(hi);
  if (!t_lo || !t_hi || !(loading ? *t_hi > *t_lo : *t_lo > *t_hi)) return std::nullopt;
  // Where the line through (t_lo, lo) and (t_hi, hi) reaches zero.
  return *t_lo - (*t_hi - *t_lo) * lo / (hi - lo);
}
}  // namespace

std::optional<double> loading_ramp_onset(const Eigen::VectorXd& v, const Eigen::VectorXd& t, Eigen::Index from, Eigen::Index mid,
                                         Eigen::Index to, double lo, double hi) {
  return ramp_zero(v, t, peak_over(v, from, mid), from, to, lo, hi, true);
}

std::optional<double> unloading_ramp_offset(const Eigen::VectorXd& v, const Eigen::VectorXd& t, Eigen::Index from, Eigen::Index mid,
                                            Eigen::Index to, double lo, double hi) {
  return ramp_zero(v, t, peak_over(v, mid, to), from, to, lo, hi, false);
}

}  // namespace kin2grf
