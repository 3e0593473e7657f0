// kin2grf kinematics: zero-lag Butterworth low-pass filter and central differences.
//
// "4th-order zero-lag Butterworth" (the paper, after Winter) is implemented as a 2nd-order
// Butterworth section run forward and backward (filtfilt). The double pass lowers the -3 dB
// point, so the single-pass cut-off is raised by Winter's correction
//   f_c,pass = f_c / C,  C = (2^(1/2) - 1)^(1/4) = 0.802,
// making f_c the -3 dB frequency of the whole zero-lag filter.
// Edges: the signal is extended at both ends by an odd (point-symmetric) reflection of
// min(N - 1, 3 fs / f_c) samples and each pass starts from the steady state of its first sample,
// so a trial's first and last frames carry no start-up transient.
#pragma once

#include <Eigen/Core>

namespace kin2grf {

/// Zero-lag (forward-backward) 2nd-order Butterworth low-pass, -3 dB at cutoff_hz overall.
/// Requires finite samples; cutoff must be below the Nyquist frequency.
Eigen::VectorXd butterworth_filtfilt(const Eigen::VectorXd& x, double rate_hz, double cutoff_hz);

/// Column-wise butterworth_filtfilt.
Eigen::MatrixXd butterworth_filtfilt(const Eigen::MatrixXd& x, double rate_hz, double cutoff_hz);

/// First derivative by central differences (one-sided at the ends), per column.
Eigen::MatrixXd central_difference(const Eigen::MatrixXd& x, double dt_s);
/// Second derivative (x[i+1] - 2 x[i] + x[i-1]) / dt^2 (ends copied from their neighbours).
Eigen::MatrixXd second_difference(const Eigen::MatrixXd& x, double dt_s);

}  // namespace kin2grf
