#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>
#include <stdexcept>

namespace kin2grf {
namespace {

struct Biquad {
  double b0, b1, b2, a1, a2;
};

Biquad design_lowpass(double rate_hz, double cutoff_hz) {
  const double K = std::tan(M_PI * cutoff_hz / rate_hz);
  const double s2 = std::sqrt(2.0);
  const double norm = 1.0 / (1.0 + s2 * K + K * K);
  Biquad q;
  q.b0 = K * K * norm;
  q.b1 = 2.0 * q.b0;
  q.b2 = q.b0;
  q.a1 = 2.0 * (K * K - 1.0) * norm;
  q.a2 = (1.0 - s2 * K + K * K) * norm;
  return q;
}

/// One pass (direct form II transposed), starting from the steady state for x[0].
void run(const Biquad& q, std::vector<double>& x) {
  if (x.empty()) return;
  // Steady state for constant input x0: output x0 (unit DC gain).
  const double x0 = x[0];
  const double z2_0 = (q.b2 - q.a2) * x0;
  double z2 = z2_0;
  double z1 = (q.b1 - q.a1) * x0 + z2_0;
  for (double& v : x) {
    const double in = v;
    const double y = q.b0 * in + z1;
    z1 = q.b1 * in - q.a1 * y + z2;
    z2 = q.b2 * in - q.a2 * y;
    v = y;
  }
}

}  // namespace

Eigen::VectorXd butterworth_filtfilt(const Eigen::VectorXd& x, double rate_hz, double cutoff_hz) {
  const Eigen::Index n = x.size();
  if (n < 2) return x;
  const double C = std::pow(std::sqrt(2.0) - 1.0, 0.25);  // Winter's two-pass correction
  const double fc = cutoff_hz / C;
  if (!(fc > 0) || fc >= 0.5 * rate_hz) {
    throw std::invalid_argument("butterworth_filtfilt: cut-off " + std::to_string(cutoff_hz) +
                                " Hz (corrected " + std::to_string(fc) + " Hz) must be below the Nyquist frequency " +
                                std::to_string(0.5 * rate_hz) + " Hz");
  }
  const Biquad q = design_lowpass(rate_hz, fc);
  // Compared as doubles before the cast: a rate of 1e300 Hz must not overflow Eigen::Index.
  const double want = std::ceil(3.0 * rate_hz / cutoff_hz);
  const Eigen::Index pad = want >= static_cast<double>(n - 1) || !(want >= 0) ? n - 1 : static_cast<Eigen::Index>(want);
  std::vector<double> e(static_cast<std::size_t>(n + 2 * pad));
  for (Eigen::Index i = 0; i < pad; ++i) e[static_cast<std::size_t>(i)] = 2 * x[0] - x[pad - i];
  for (Eigen::Index i = 0; i < n; ++i) e[static_cast<std::size_t>(pad + i)] = x[i];
  for (Eigen::Index i = 0; i < pad; ++i) e[static_cast<std::size_t>(pad + n + i)] = 2 * x[n - 1] - x[n - 2 - i];
  run(q, e);
  std::reverse(e.begin(), e.end());
  run(q, e);
  std::reverse(e.begin(), e.end());
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) y[i] = e[static_cast<std::size_t>(pad + i)];
  return y;
}

Eigen::MatrixXd butterworth_filtfilt(const Eigen::MatrixXd& x, double rate_hz, double cutoff_hz) {
  Eigen::MatrixXd y(x.rows(), x.cols());
  // Columns are independent: on the machine's cores when long enough to pay for a thread (two
  // passes of a biquad, about 10 ns a sample).
  const std::size_t min_columns = min_chunk_for(10e-9 * static_cast<double>(x.rows()));
  for_chunks(static_cast<std::size_t>(x.cols()), min_columns, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (auto c = static_cast<Eigen::Index>(begin); c < static_cast<Eigen::Index>(end); ++c)
      y.col(c) = butterworth_filtfilt(Eigen::VectorXd(x.col(c)), rate_hz, cutoff_hz);
  });
  return y;
}

Eigen::MatrixXd central_difference(const Eigen::MatrixXd& x, double dt) {
  const Eigen::Index n = x.rows();
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, x.cols());
  if (n < 2) return d;
  for (Eigen::Index i = 1; i + 1 < n; ++i) d.row(i) = (x.row(i + 1) - x.row(i - 1)) / (2 * dt);
  d.row(0) = (x.row(1) - x.row(0)) / dt;
  d.row(n - 1) = (x.row(n - 1) - x.row(n - 2)) / dt;
  return d;
}

Eigen::MatrixXd second_difference(const Eigen::MatrixXd& x, double dt) {
  const Eigen::Index n = x.rows();
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, x.cols());
  if (n < 3) return d;
  for (Eigen::Index i = 1; i + 1 < n; ++i) d.row(i) = (x.row(i + 1) - 2 * x.row(i) + x.row(i - 1)) / (dt * dt);
  d.row(0) = d.row(1);
  d.row(n - 1) = d.row(n - 2);
  return d;
}

}  // namespace kin2grf

namespace kin2grf {

namespace {

/// One column's choice for residual_analysis_cutoff (+inf: above upper_hz).
double residual_cutoff_of(const Eigen::VectorXd& col, double rate_hz, double upper_hz, double f_lo, double f_hi) {
  const auto n = static_cast<double>(col.size());
  auto residual = [&](double f) { return std::sqrt((col - butterworth_filtfilt(col, rate_hz, f)).squaredNorm() / n); };
  // The noise line R = a + b f, least squares on 8 points of the noise region.
  constexpr int m = 8;
  double sf = 0, sr = 0, sff = 0, sfr = 0;
  for (int k = 0; k < m; ++k) {
    const double f = f_lo + (f_hi - f_lo) * k / (m - 1), r = residual(f);
    sf += f, sr += r, sff += f * f, sfr += f * r;
  }
  const double b = (m * sfr - sf * sr) / (m * sff - sf * sf), a = (sr - b * sf) / m;
  // R falls as f rises: the lowest f with R(f) <= a, by bisection, only when it is below
  // upper_hz (most clean recordings stop at this one test).
  if (!(a > 0) || residual(upper_hz) > a) return std::numeric_limits<double>::infinity();
  double lo = 0.5, hi = upper_hz;
  if (residual(lo) <= a) return lo;
  for (int it = 0; it < 16; ++it) {
    const double mid = 0.5 * (lo + hi);
    (residual(mid) > a ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace

double residual_analysis_cutoff(const Eigen::MatrixXd& x, double rate_hz, double upper_hz) {
  // At most a minute of frames: the noise of a recording does not change along it.
  const Eigen::Index n = std::min<Eigen::Index>(x.rows(), static_cast<Eigen::Index>(60 * rate_hz));
  const double nyq = 0.5 * rate_hz;
  const double f_lo = 0.5 * nyq, f_hi = 0.8 * nyq;  // where the residual is mostly noise
  if (n < 20 || x.cols() == 0 || !(upper_hz > 0.5 && upper_hz < f_lo)) return upper_hz;
  std::vector<double> choice(static_cast<std::size_t>(x.cols()));  // per column; +inf: above upper_hz
  // About 30 filtfilt passes a column.
  for_chunks(choice.size(), min_chunk_for(30 * 10e-9 * static_cast<double>(n)), [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) choice[c] = residual_cutoff_of(x.col(static_cast<Eigen::Index>(c)).head(n), rate_hz, upper_hz, f_lo, f_hi);
  });
  std::nth_element(choice.begin(), choice.begin() + static_cast<long>(choice.size() / 2), choice.end());
  return std::min(upper_hz, choice[choice.size() / 2]);
}

}  // namespace kin2grf
