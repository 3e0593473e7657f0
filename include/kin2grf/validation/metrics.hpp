// kin2grf validation: the paper's error metrics (Sect. 3, Eqs. 11-12) and the companions a
// biomechanist reads beside them.
//
//   RMSE  = sqrt( (1/n) sum_i (u_num,i - u_exp,i)^2 )                                  (Eq. 11)
//   rRMSE = 100 * RMSE / ( 0.5 * (range(u_num) + range(u_exp)) ),  range = max - min    (Eq. 12)
//
// u_num is the estimate, u_exp the force-plate measurement, over the same frames. Pairs where
// either value is NaN are left out (and counted). Pearson's r is the usual sample correlation.
#pragma once

#include <Eigen/Dense>
#include <optional>

namespace kin2grf {

struct SeriesMetrics {
  int samples = 0;               ///< pairs compared
  double rmse = 0.0;             ///< Eq. 11, in the series' unit
  double rrmse_percent = 0.0;    ///< Eq. 12; NaN when both ranges are zero
  double pearson_r = 0.0;        ///< NaN when either series is constant
  double max_abs_error = 0.0;    ///< max_i |u_num,i - u_exp,i|
  double peak_difference = 0.0;  ///< max(u_num) - max(u_exp): the error on the peak value
  double mean_error = 0.0;       ///< mean(u_num - u_exp): the bias
};

/// Compare an estimated series with a measured one of the same length. Returns nullopt when
/// fewer than 2 pairs are finite.
std::optional<SeriesMetrics> compare_series(const Eigen::VectorXd& estimated, const Eigen::VectorXd& measured);

/// Time (s) at which `v` first rises above `threshold` searching forward from `from`, with
/// linear interpolation between frames of `time_s`; nullopt when it never does before `to`.
std::optional<double> rising_crossing(const Eigen::VectorXd& v, const Eigen::VectorXd& time_s, double threshold,
                                      Eigen::Index from, Eigen::Index to);
/// Time (s) of the last fall below `threshold` in [from, to], interpolated; nullopt if none.
std::optional<double> falling_crossing(const Eigen::VectorXd& v, const Eigen::VectorXd& time_s, double threshold,
                                       Eigen::Index from, Eigen::Index to);

/// The loading ramp's onset (s): the line through the rising crossings of lo and hi times the
/// first peak P (the largest value in [from, mid]) extended back to zero,
///   t_0 = t_lo - (t_hi - t_lo) lo / (hi - lo),
/// over the loading rate's own span (20-80 % of the first peak, dynamics/stance_parameters.hpp).
/// A zero-lag low-pass filter leaves a ramp's straight part where it was and spreads only its
/// corners, so it moves t_0 less than a threshold crossing, which it moves earlier by its whole
/// spread: at 6 Hz a 50 ms ramp's 20 N crossing by 22 ms and t_0 by 14, a 90 ms ramp's by 14 and
/// 4 (test Metrics.TheLoadingRampsIntercept...). nullopt without a positive peak or either
/// crossing in [from, to].
inline constexpr double kRampLowFraction = 0.2, kRampHighFraction = 0.8;
std::optional<double> loading_ramp_onset(const Eigen::VectorXd& v, const Eigen::VectorXd& time_s, Eigen::Index from, Eigen::Index mid,
                                         Eigen::Index to, double lo = kRampLowFraction, double hi = kRampHighFraction);
/// The unloading ramp's end (s), the same rule mirrored: the last falling crossings of hi and lo
/// times the last peak (the largest value in [mid, to]) in [from, to], extended forward to zero.
std::optional<double> unloading_ramp_offset(const Eigen::VectorXd& v, const Eigen::VectorXd& time_s, Eigen::Index from, Eigen::Index mid,
                                            Eigen::Index to, double lo = kRampLowFraction, double hi = kRampHighFraction);

}  // namespace kin2grf
