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

}  // namespace kin2grf
