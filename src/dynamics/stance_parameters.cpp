#include "kin2grf/dynamics/stance_parameters.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kin2grf {

namespace {

/// The frame of the largest finite value of `x` over [from, to]; -1 where there is none.
Eigen::Index argmax(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index from, Eigen::Index to) {
  Eigen::Index best = -1;
  for (Eigen::Index i = from; i <= to; ++i)
    if (std::isfinite(x[i]) && (best < 0 || x[i] > x[best])) best = i;
  return best;
}

/// The time (in frames, fractional) at which `x` first reaches `level` over [from, to], the
/// crossing interpolated linearly from the frame before; NaN where it never does, or where it
/// already does at `from` (the rise is not seen).
double first_crossing(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index from, Eigen::Index to, double level) {
  if (!(std::isfinite(x[from]) && x[from] < level)) return std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index i = from + 1; i <= to; ++i) {
    if (!std::isfinite(x[i])) return std::numeric_limits<double>::quiet_NaN();
    if (x[i] >= level) return static_cast<double>(i - 1) + (level - x[i - 1]) / (x[i] - x[i - 1]);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

StanceParameters stance_parameters(const Eigen::MatrixX2d& force_N, double rate_hz, Eigen::Index first, Eigen::Index last) {
  if (!(first >= 0 && first <= last && last < force_N.rows()))
    throw std::invalid_argument("stance_parameters: frames " + std::to_string(first) + "-" + std::to_string(last) + " outside 0-" +
                                std::to_string(force_N.rows() - 1));
  if (!(std::isfinite(rate_hz) && rate_hz > 0)) throw std::invalid_argument("stance_parameters: rate must be positive");
  StanceParameters p;
  const double dt = 1.0 / rate_hz;
  const auto fx = force_N.col(0), fy = force_N.col(1);
  p.duration_s = static_cast<double>(last - first + 1) * dt;

  const Eigen::Index mid = stance_second_half(first, last);
  const Eigen::Index peak = argmax(fy, first, last);
  if (peak >= 0) p.vertical_peak_N = fy[peak];
  const Eigen::Index p1 = mid > first ? argmax(fy, first, mid - 1) : -1, p2 = argmax(fy, mid, last);
  if (p1 >= 0) p.vertical_first_peak_N = fy[p1];
  if (p2 >= 0) p.vertical_second_peak_N = fy[p2];
  if (p1 >= 0 && p2 >= 0) {
    double valley = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = p1; i <= p2; ++i)
      if (std::isfinite(fy[i]) && fy[i] < valley) valley = fy[i];
    p.vertical_valley_N = valley;
  }

  // The anterior force's extremes and every impulse (trapezoids; an anterior step that crosses
  // zero is split at the crossing, so that braking and propulsion each get their own part).
  bool any_x = false;
  double lo = 0, hi = 0, jy = 0, brake = 0, push = 0;
  bool any_step_y = false, any_step_x = false;
  for (Eigen::Index i = first; i <= last; ++i) {
    if (std::isfinite(fx[i])) {
      lo = std::min(lo, fx[i]);
      hi = std::max(hi, fx[i]);
      any_x = true;
    }
    if (i == first) continue;
    if (std::isfinite(fy[i]) && std::isfinite(fy[i - 1])) {
      jy += 0.5 * (fy[i] + fy[i - 1]) * dt;
      any_step_y = true;
    }
    const double a = fx[i - 1], b = fx[i];
    if (!(std::isfinite(a) && std::isfinite(b))) continue;
    any_step_x = true;
    if ((a >= 0) == (b >= 0)) {
      (a >= 0 ? push : brake) += 0.5 * (a + b) * dt;
    } else {
      const double t0 = a / (a - b) * dt;  // where the straight line between them crosses zero
      (a >= 0 ? push : brake) += 0.5 * a * t0;
      (b >= 0 ? push : brake) += 0.5 * b * (dt - t0);
    }
  }
  if (any_x) {
    p.braking_peak_N = lo;
    p.propulsive_peak_N = hi;
  }
  if (any_step_y) p.vertical_impulse_Ns = jy;
  if (any_step_x) {
    p.braking_impulse_Ns = brake;
    p.propulsive_impulse_Ns = push;
  }

  if (p1 >= 0 && fy[p1] > 0) {
    const double t20 = first_crossing(fy, first, p1, 0.2 * fy[p1]), t80 = first_crossing(fy, first, p1, 0.8 * fy[p1]);
    if (std::isfinite(t20) && std::isfinite(t80) && t80 > t20) p.loading_rate_N_per_s = 0.6 * fy[p1] / ((t80 - t20) * dt);
  }
  return p;
}

Eigen::MatrixXd stance_normalised(const Eigen::MatrixXd& series, Eigen::Index first, Eigen::Index last, int points) {
  if (!(first >= 0 && first <= last && last < series.rows()))
    throw std::invalid_argument("stance_normalised: frames " + std::to_string(first) + "-" + std::to_string(last) + " outside 0-" +
                                std::to_string(series.rows() - 1));
  if (points < 2) throw std::invalid_argument("stance_normalised: " + std::to_string(points) + " points (2 or more)");
  Eigen::MatrixXd out(points, series.cols());
  const double span = static_cast<double>(last - first);
  for (int k = 0; k < points; ++k) {
    // k * span / (points - 1) in frames, exact at both ends.
    const double at = span * static_cast<double>(k) / static_cast<double>(points - 1);
    const auto i = std::min(first + static_cast<Eigen::Index>(std::floor(at)), last);
    const double w = at - static_cast<double>(i - first);
    if (w <= 0.0 || i == last) out.row(k) = series.row(i);
    else out.row(k) = (1.0 - w) * series.row(i) + w * series.row(i + 1);
  }
  return out;
}

}  // namespace kin2grf
