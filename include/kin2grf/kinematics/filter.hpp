// kin2grf kinematics: zero-lag Butterworth low-pass filter and central differences.
//
// "4th-order zero-lag Butterworth" (the paper, after Winter) is implemented as a 2nd-order
// Butterworth section run forward and backward (filtfilt). The double pass lowers the -3 dB
// point, so the single-pass cut-off is raised by Winter's correction
//   f_c,pass = f_c / C,  C = (2^(1/2) - 1)^(1/4) = 0.802,
// making f_c the -3 dB frequency of the whole zero-lag filter.
// Edges: the signal is extended at both ends by an odd (point-symmetric) reflection of
// min(N - 1, 3 fs / f_c) samples and each pass starts from the steady state of its first sample,
// so a trial's first and last frames carry no start-up transient. The odd reflection keeps the
// end's position and velocity, and flips its acceleration: x_ext''(T + s) = -x''(T - s), so the
// filtered acceleration at the end reads zero. FilterEdge::Curvature adds the end's own
// curvature, x_ext(T + s) = 2 x(T) - x(T - s) + a_T s^2, a_T the second derivative of the
// least-squares quadratic through the end's kCurvatureSpanPeriods of a cut-off period (at least
// 5 samples): the extension of a parabola is the parabola, and the end keeps its acceleration.
// Why: a short capture (a run through a small volume) ends mid-stance or in flight, where the
// body accelerates at 1-3 g, and reads as unaccelerated there: UWA's overground runs, whose 0.37 s
// window ends 20 ms after their stance, 8.7 / 8.9 % vertical with the odd reflection, 7.2 / 7.0 %
// with the curvature (the pipeline's model coordinates, EstimateOptions::kinematic_edges).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace kin2grf {

/// Winter's two-pass correction C = (2^(1/2) - 1)^(1/4) = 0.802 (see above).
double zero_lag_correction();
/// The highest cut-off a zero-lag filter takes at `rate_hz`: its single pass (cut-off / C) must be
/// below the Nyquist frequency, so every cut-off must be below 0.5 * rate * C (40.1 Hz at 100 Hz).
inline double max_zero_lag_cutoff_hz(double rate_hz) { return 0.5 * rate_hz * zero_lag_correction(); }

/// How a zero-lag filter extends a series past its ends (see above).
enum class FilterEdge {
  OddReflection,  ///< point-symmetric: position and velocity kept, the ends' acceleration read as zero
  Curvature,      ///< the odd reflection plus the ends' own curvature (a_T s^2)
};
/// The share of a cut-off period the end's curvature is fitted over (FilterEdge::Curvature), by
/// default: half a period, the filter's own resolution (shorter spans fit the markers' noise, longer
/// ones the next phase of the motion); chosen again leave-one-lab-out by the pipeline's
/// EstimateOptions::kinematic_edge_span_periods (`kin2grf study kinematic-edge-span`).
inline constexpr double kCurvatureSpanPeriods = 0.5;
/// The command line's word for each: "odd", "curvature".
inline const char* filter_edge_name(FilterEdge e) { return e == FilterEdge::Curvature ? "curvature" : "odd"; }

/// Zero-lag (forward-backward) 2nd-order Butterworth low-pass, -3 dB at cutoff_hz overall.
/// Requires finite samples; cutoff must be below the Nyquist frequency.
/// `curvature_span_periods`: FilterEdge::Curvature's span, in periods of the cut-off (above 0).
Eigen::VectorXd butterworth_filtfilt(const Eigen::VectorXd& x, double rate_hz, double cutoff_hz,
                                     FilterEdge edge = FilterEdge::OddReflection, double curvature_span_periods = kCurvatureSpanPeriods);

/// Column-wise butterworth_filtfilt. Filters x in place: pass it with std::move where the
/// unfiltered series is not needed again.
Eigen::MatrixXd butterworth_filtfilt(Eigen::MatrixXd x, double rate_hz, double cutoff_hz,
                                     FilterEdge edge = FilterEdge::OddReflection, double curvature_span_periods = kCurvatureSpanPeriods);

/// First derivative by central differences (one-sided at the ends), per column.
Eigen::MatrixXd central_difference(const Eigen::MatrixXd& x, double dt_s);
/// Second derivative (x[i+1] - 2 x[i] + x[i-1]) / dt^2 (ends copied from their neighbours).
Eigen::MatrixXd second_difference(const Eigen::MatrixXd& x, double dt_s);
/// Element (i, k) of central_difference(x, dt_s) and second_difference(x, dt_s), the same
/// doubles, without the whole matrices (a motion that keeps x only: ModelMotion::derivatives_at).
/// (Inline: ModelMotion::frame() takes them for every coordinate of every frame it rebuilds.)
inline double central_difference_at(const Eigen::MatrixXd& x, Eigen::Index i, Eigen::Index k, double dt_s) {
  const Eigen::Index n = x.rows();
  if (n < 2) return 0.0;
  if (i == 0) return (x(1, k) - x(0, k)) / dt_s;
  if (i == n - 1) return (x(n - 1, k) - x(n - 2, k)) / dt_s;
  return (x(i + 1, k) - x(i - 1, k)) / (2 * dt_s);
}
inline double second_difference_at(const Eigen::MatrixXd& x, Eigen::Index i, Eigen::Index k, double dt_s) {
  const Eigen::Index n = x.rows();
  if (n < 3) return 0.0;
  const Eigen::Index j = i < 1 ? 1 : i > n - 2 ? n - 2 : i;  // the ends take their neighbour's
  return (x(j + 1, k) - 2 * x(j, k) + x(j - 1, k)) / (dt_s * dt_s);
}

/// Winter's residual analysis (Winter 2009, Biomechanics and Motor Control of Human Movement,
/// Sect. 3.4.4.3), bounded above: per column, the residual RMS R(f) of (x - filtered at f) falls
/// as f rises and, at high frequencies (50-80 % of Nyquist), is mostly noise, a straight line
/// a + b f; the column's cut-off is the lowest f with R(f) <= a, where the signal left in the
/// residual equals the noise let through. Returns min(upper_hz, the median over the columns).
/// Clean (lab-smoothed) markers give cut-offs far above 6 Hz; 2 mm of white noise at 60-100 Hz,
/// 3-4 Hz.
double residual_analysis_cutoff(const Eigen::MatrixXd& x, double rate_hz, double upper_hz);
}  // namespace kin2grf
