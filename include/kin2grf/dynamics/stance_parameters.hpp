#pragma once
// kin2grf dynamics: the ground reaction parameters gait and running analysis read off one stance
// (kin2grf, not the paper: what a gait report tabulates and what a force-plate-free estimate is
// judged by beside its rRMSE).
//
// On one foot's sagittal force (anterior + forward, vertical + up; N), frames [first, last] at
// `rate_hz`:
//   vertical first / second peak: the largest vertical force in the stance's first / second half
//     (the halves split as the knee adduction moment's peaks are, dynamics/joint_moments_3d.hpp:
//     the second takes the odd frame). In walking the loading response's and the push-off's peaks;
//     in a run's single hump both halves' largest lie beside its one peak.
//   valley: the smallest vertical force between the two peaks' frames (mid-stance's minimum).
//   vertical peak: the largest over the stance.
//   braking peak: the smallest anterior force (a negative number: it acts backward); propulsive
//     peak: the largest (positive). Either is 0 where the force never takes that sign.
//   impulses, N s, by the trapezoid rule over the stance: the vertical force's; the anterior
//     force's negative part (braking, <= 0) and positive part (propulsive, >= 0), each part of a
//     step that crosses zero split at the crossing.
//   loading rate, N/s: the mean slope of the vertical force from 20 % to 80 % of the first peak
//     on its rise (the first frames at or above each level, the crossing times interpolated
//     linearly), the average loading rate of running and gait studies (Milner et al. 2006 take it
//     over the impact peak's 20-80 %; here the first half's peak: in walking the loading response,
//     in a run without an impact peak the active peak). NaN where the rise is not seen (a stance
//     that starts above 20 % of its first peak: a stance the window cuts).
// Non-finite samples are skipped (NaN where nothing is left). No division by the body weight here:
// callers give it (the JSON's *_bw keys, validate's errors in % body weight).

#include <Eigen/Core>

#include <limits>

namespace kin2grf {

/// Where a stance's second half begins: frames [first, last] split into [first, mid - 1] and
/// [mid, last], the second taking the odd frame. One rule for every per-half value: the vertical
/// force's first and second peaks, the knee adduction moment's peaks, the joint kinetic peaks.
inline Eigen::Index stance_second_half(Eigen::Index first, Eigen::Index last) { return first + (last - first + 1) / 2; }

struct StanceParameters {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double duration_s = kNaN;  ///< (last - first + 1) / rate: foot strike to foot off, as the gait events mark them
  double vertical_first_peak_N = kNaN, vertical_valley_N = kNaN, vertical_second_peak_N = kNaN;
  double vertical_peak_N = kNaN;
  double braking_peak_N = kNaN, propulsive_peak_N = kNaN;
  double vertical_impulse_Ns = kNaN, braking_impulse_Ns = kNaN, propulsive_impulse_Ns = kNaN;
  double loading_rate_N_per_s = kNaN;
};

/// `force_N`: (anterior, vertical) per frame; frames [first, last] inclusive, 0 <= first <= last <
/// rows. std::invalid_argument on frames outside it or a rate that is not positive and finite.
StanceParameters stance_parameters(const Eigen::MatrixX2d& force_N, double rate_hz, Eigen::Index first, Eigen::Index last);

/// The instants of a time-normalised stance: 0, 1, ..., 100 % (the stance-curves tables' and CSVs').
inline constexpr int kStanceCurvePoints = 101;

/// Time normalisation, as gait reports and normative data give a stance: the columns of `series`
/// over frames [first, last] at `points` equally spaced instants from the first frame (0 % of the
/// stance, foot strike) to the last (100 %, foot off), each linear between the two frames around
/// it (an instant on a frame takes that frame alone; a NaN frame beside an instant gives NaN).
/// Row k is k / (points - 1) of the stance: 101 points are 0, 1, ..., 100 %. std::invalid_argument
/// on frames outside the series or fewer than 2 points.
Eigen::MatrixXd stance_normalised(const Eigen::MatrixXd& series, Eigen::Index first, Eigen::Index last,
                                  int points = kStanceCurvePoints);

}  // namespace kin2grf
