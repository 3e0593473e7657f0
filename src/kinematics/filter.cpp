#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/parallel.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>
#include <stdexcept>

namespace kin2grf {

double zero_lag_correction() { return std::pow(std::sqrt(2.0) - 1.0, 0.25); }
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

/// Filtfilt of L columns side by side. A biquad's recursion is a chain of dependent
/// multiply-adds, so one column leaves the floating-point pipeline mostly idle; L independent
/// columns interleaved in `e` (sample-major) fill it. Each lane's arithmetic is that of the
/// one-column filter, operation for operation, so the result does not depend on L.
/// `e` holds the (n + 2 pad) extended samples of each lane, interleaved.
template <int L>
void filtfilt_interleaved(const Biquad& q, std::vector<double>& e) {
  const std::size_t m = e.size() / L;
  if (m == 0) return;
  double z1[L], z2[L];
  // Direct form II transposed, started from the steady state for the sample at `first` (unit DC
  // gain: output = input, so no start-up transient), run over the samples from there.
  auto pass = [&](std::size_t first, auto next) {
    for (int l = 0; l < L; ++l) {
      const double x0 = e[first * L + static_cast<std::size_t>(l)];
      z2[l] = (q.b2 - q.a2) * x0;
      z1[l] = (q.b1 - q.a1) * x0 + z2[l];
    }
    for (std::size_t k = 0, i = first; k < m; ++k, i = next(i)) {
      double* v = &e[i * L];
      for (int l = 0; l < L; ++l) {
        const double in = v[l];
        const double y = q.b0 * in + z1[l];
        z1[l] = q.b1 * in - q.a1 * y + z2[l];
        z2[l] = q.b2 * in - q.a2 * y;
        v[l] = y;
      }
    }
  };
  pass(0, [](std::size_t i) { return i + 1; });      // forward
  pass(m - 1, [](std::size_t i) { return i - 1; });  // backward (i wraps after the last sample, unused)
}

/// The single-pass section and the edge padding of a zero-lag filter at cutoff_hz (see the header).
struct ZeroLagDesign {
  Biquad q;
  Eigen::Index pad;
  /// FilterEdge::Curvature: the weights w of an end's curvature a = sum_k w_k y_k (per sample^2),
  /// y_k the k-th sample in from the end, from the least-squares quadratic through the first
  /// w.size() of them; empty: the odd reflection alone.
  Eigen::VectorXd curvature_weights;
};

/// Twice the quadratic coefficient of the least-squares quadratic through samples 0..m-1, as
/// weights on the samples: the third row of (A^T A)^-1 A^T, A = [1 t t^2], times 2.
Eigen::VectorXd curvature_weights(Eigen::Index m) {
  Eigen::MatrixXd A(m, 3);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = static_cast<double>(k);
    A.row(k) << 1.0, t, t * t;
  }
  return 2.0 * (A.transpose() * A).ldlt().solve(A.transpose()).row(2).transpose();
}

ZeroLagDesign design_zero_lag(Eigen::Index n, double rate_hz, double cutoff_hz, FilterEdge edge, double span_periods) {
  const double C = zero_lag_correction();
  const double fc = cutoff_hz / C;
  if (!(fc > 0) || fc >= 0.5 * rate_hz) {
    throw std::invalid_argument("butterworth_filtfilt: cut-off " + std::to_string(cutoff_hz) +
                                " Hz (corrected " + std::to_string(fc) + " Hz) must be below the Nyquist frequency " +
                                std::to_string(0.5 * rate_hz) + " Hz");
  }
  // Compared as doubles before the cast: a rate of 1e300 Hz must not overflow Eigen::Index.
  const double want = std::ceil(3.0 * rate_hz / cutoff_hz);
  const Eigen::Index pad = want >= static_cast<double>(n - 1) || !(want >= 0) ? n - 1 : static_cast<Eigen::Index>(want);
  ZeroLagDesign d{design_lowpass(rate_hz, fc), pad, Eigen::VectorXd()};
  if (edge == FilterEdge::Curvature) {
    // At least 5 samples, at most the series (compared as doubles: a huge rate must not overflow).
    const double span = std::min(static_cast<double>(n), std::max(5.0, std::round(span_periods * rate_hz / cutoff_hz)));
    const auto m = static_cast<Eigen::Index>(span);
    if (m >= 3) d.curvature_weights = curvature_weights(m);  // fewer samples: no quadratic, the odd reflection
  }
  return d;
}

/// Filters columns [c0, c0 + L) of x into the same columns of y (n >= 2), `e` as workspace.
template <int L>
void filtfilt_columns(const ZeroLagDesign& d, const Eigen::Ref<const Eigen::MatrixXd>& x, Eigen::Index c0,
                      Eigen::Ref<Eigen::MatrixXd> y, std::vector<double>& e) {
  const Eigen::Index n = x.rows(), pad = d.pad;
  e.resize(static_cast<std::size_t>((n + 2 * pad) * L));
  const auto at = [&](Eigen::Index i, int l) -> double& { return e[static_cast<std::size_t>(i * L + l)]; };
  for (int l = 0; l < L; ++l) {
    const auto col = x.col(c0 + l);
    // Odd (point-symmetric) reflection at both ends.
    for (Eigen::Index i = 0; i < pad; ++i) at(i, l) = 2 * col[0] - col[pad - i];
    for (Eigen::Index i = 0; i < n; ++i) at(pad + i, l) = col[i];
    for (Eigen::Index i = 0; i < pad; ++i) at(pad + n + i, l) = 2 * col[n - 1] - col[n - 2 - i];
    if (const Eigen::Index m = d.curvature_weights.size(); m > 0) {
      // Each end's curvature (time runs inward from it: a second derivative does not see the
      // direction), added as a_T s^2 at s samples beyond the end.
      double a0 = 0, a1 = 0;
      for (Eigen::Index k = 0; k < m; ++k) a0 += d.curvature_weights[k] * col[k], a1 += d.curvature_weights[k] * col[n - 1 - k];
      for (Eigen::Index i = 0; i < pad; ++i) {
        const auto s0 = static_cast<double>(pad - i), s1 = static_cast<double>(i + 1);
        at(i, l) += a0 * s0 * s0;
        at(pad + n + i, l) += a1 * s1 * s1;
      }
    }
  }
  filtfilt_interleaved<L>(d.q, e);
  for (int l = 0; l < L; ++l) {
    auto out = y.col(c0 + l);
    for (Eigen::Index i = 0; i < n; ++i) out[i] = at(pad + i, l);
  }
}

/// Columns [begin, end) of x filtered into y, four at a time.
void filtfilt_range(const ZeroLagDesign& d, const Eigen::Ref<const Eigen::MatrixXd>& x, Eigen::Index begin,
                    Eigen::Index end, Eigen::Ref<Eigen::MatrixXd> y, std::vector<double>& e) {
  Eigen::Index c = begin;
  for (; c + 4 <= end; c += 4) filtfilt_columns<4>(d, x, c, y, e);
  for (; c + 2 <= end; c += 2) filtfilt_columns<2>(d, x, c, y, e);
  for (; c < end; ++c) filtfilt_columns<1>(d, x, c, y, e);
}

}  // namespace

Eigen::VectorXd butterworth_filtfilt(const Eigen::VectorXd& x, double rate_hz, double cutoff_hz, FilterEdge edge,
                                     double curvature_span_periods) {
  const Eigen::Index n = x.size();
  if (n < 2) return x;
  const ZeroLagDesign d = design_zero_lag(n, rate_hz, cutoff_hz, edge, curvature_span_periods);
  Eigen::MatrixXd y(n, 1);
  std::vector<double> e;
  filtfilt_columns<1>(d, x, 0, y, e);
  return y.col(0);
}

Eigen::MatrixXd butterworth_filtfilt(Eigen::MatrixXd x, double rate_hz, double cutoff_hz, FilterEdge edge,
                                     double curvature_span_periods) {
  const Eigen::Index n = x.rows();
  if (n < 2 || x.cols() == 0) return x;
  const ZeroLagDesign d = design_zero_lag(n, rate_hz, cutoff_hz, edge, curvature_span_periods);
  // In place: filtfilt_columns copies its columns into the workspace before it writes them back,
  // and no two chunks share a column, so a long trial's series is never held twice.
  // Columns are independent: on the machine's cores when long enough to pay for a thread (two
  // passes of a biquad, about 3 ns a sample four columns at a time).
  const std::size_t min_columns = min_chunk_for(3e-9 * static_cast<double>(n));
  for_chunks(static_cast<std::size_t>(x.cols()), min_columns, [&](std::size_t, std::size_t begin, std::size_t end) {
    std::vector<double> e;
    filtfilt_range(d, x, static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(end), x, e);
  });
  return x;
}

Eigen::MatrixXd central_difference(const Eigen::MatrixXd& x, double dt) {
  Eigen::MatrixXd d(x.rows(), x.cols());
  for (Eigen::Index k = 0; k < x.cols(); ++k)
    for (Eigen::Index i = 0; i < x.rows(); ++i) d(i, k) = central_difference_at(x, i, k, dt);
  return d;
}

Eigen::MatrixXd second_difference(const Eigen::MatrixXd& x, double dt) {
  Eigen::MatrixXd d(x.rows(), x.cols());
  for (Eigen::Index k = 0; k < x.cols(); ++k)
    for (Eigen::Index i = 0; i < x.rows(); ++i) d(i, k) = second_difference_at(x, i, k, dt);
  return d;
}

}  // namespace kin2grf

namespace kin2grf {

namespace {

/// RMS of x - y.
double residual_rms(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  return std::sqrt((x - y).squaredNorm() / static_cast<double>(x.size()));
}

/// One column's choice for residual_analysis_cutoff (+inf: above upper_hz), given its residual
/// at the noise-region frequencies f_k and at upper_hz (residuals[k], residuals[m]).
double residual_cutoff_of(const Eigen::VectorXd& col, const double* residuals, int m, double rate_hz,
                          double upper_hz, double f_lo, double f_hi) {
  auto residual = [&](double f) { return residual_rms(col, butterworth_filtfilt(col, rate_hz, f)); };
  // The noise line R = a + b f, least squares on the m points of the noise region.
  double sf = 0, sr = 0, sff = 0, sfr = 0;
  for (int k = 0; k < m; ++k) {
    const double f = f_lo + (f_hi - f_lo) * k / (m - 1), r = residuals[k];
    sf += f, sr += r, sff += f * f, sfr += f * r;
  }
  const double b = (m * sfr - sf * sr) / (m * sff - sf * sf), a = (sr - b * sf) / m;
  // R falls as f rises: the lowest f with R(f) <= a, by bisection, only when it is below
  // upper_hz (most clean recordings stop at this one test).
  if (!(a > 0) || residuals[m] > a) return std::numeric_limits<double>::infinity();
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
  constexpr int m = 8;  // points on the noise line
  const auto head = x.topRows(n);  // a view: its columns are copied where a residual is summed
  std::vector<double> choice(static_cast<std::size_t>(x.cols()));  // per column; +inf: above upper_hz
  // Nine filtfilt passes a column (the noise line and upper_hz), four columns at a time; the
  // bisection, when a column needs it, one column at a time.
  for_chunks(choice.size(), min_chunk_for((m + 1) * 3e-9 * static_cast<double>(n)), [&](std::size_t, std::size_t begin, std::size_t end) {
    const auto b = static_cast<Eigen::Index>(begin), w = static_cast<Eigen::Index>(end - begin);
    Eigen::MatrixXd residuals(m + 1, w), y(n, w);
    std::vector<double> e;
    for (int k = 0; k <= m; ++k) {
      const double f = k < m ? f_lo + (f_hi - f_lo) * k / (m - 1) : upper_hz;
      filtfilt_range(design_zero_lag(n, rate_hz, f, FilterEdge::OddReflection, kCurvatureSpanPeriods), head.middleCols(b, w), 0, w, y, e);
      for (Eigen::Index c = 0; c < w; ++c) residuals(k, c) = residual_rms(head.col(b + c), y.col(c));
    }
    for (Eigen::Index c = 0; c < w; ++c)
      choice[static_cast<std::size_t>(b + c)] =
          residual_cutoff_of(head.col(b + c), residuals.col(c).data(), m, rate_hz, upper_hz, f_lo, f_hi);
  });
  std::nth_element(choice.begin(), choice.begin() + static_cast<long>(choice.size() / 2), choice.end());
  return std::min(upper_hz, choice[choice.size() / 2]);
}

}  // namespace kin2grf
