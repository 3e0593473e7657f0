// Tests of kinematics/filter: the Butterworth filter and the noise-limited cut-off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <random>

#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

using kin2grf::test::run;
using kin2grf::test::synthetic_landmarks;

TEST(Filter, PassesDcAndHalvesPowerAtCutoff) {
  const double fs = 200, fc = 6;
  Eigen::VectorXd dc = Eigen::VectorXd::Constant(400, 3.5);
  EXPECT_NEAR((butterworth_filtfilt(dc, fs, fc) - dc).cwiseAbs().maxCoeff(), 0.0, 1e-9);
  Eigen::VectorXd s(2000);
  for (int i = 0; i < s.size(); ++i) s[i] = std::sin(2 * M_PI * fc * i / fs);
  const Eigen::VectorXd y = butterworth_filtfilt(s, fs, fc);
  const double gain = y.segment(500, 1000).cwiseAbs().maxCoeff();
  EXPECT_NEAR(gain, std::sqrt(0.5), 0.03) << "the zero-lag filter's -3 dB point is the given cut-off";
  // A ramp keeps no start-up transient at the ends (odd reflection + steady-state start).
  Eigen::VectorXd ramp = Eigen::VectorXd::LinSpaced(300, 0.0, 3.0);
  EXPECT_NEAR((butterworth_filtfilt(ramp, fs, fc) - ramp).cwiseAbs().maxCoeff(), 0.0, 1e-6);
}

// The ends' acceleration (FilterEdge): a body in free fall, y = y0 + v t - g t^2 / 2, over 0.4 s at
// 250 Hz. The odd reflection extends it point-symmetrically, whose acceleration flips sign past
// the end, so the filtered acceleration at the ends falls towards zero; the curvature extension
// extends a parabola as itself and keeps -g there.
TEST(Filter, TheCurvatureEdgeKeepsTheEndsAcceleration) {
  const double fs = 250, fc = 6, g = 9.81;
  Eigen::VectorXd y(100);
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    const double t = static_cast<double>(i) / fs;
    y[i] = 1.0 + 1.5 * t - 0.5 * g * t * t;
  }
  const auto acceleration = [&](FilterEdge e) -> Eigen::VectorXd { return second_difference(butterworth_filtfilt(y, fs, fc, e), 1.0 / fs).col(0); };
  const Eigen::VectorXd odd = acceleration(FilterEdge::OddReflection), curved = acceleration(FilterEdge::Curvature);
  for (const Eigen::Index i : {Eigen::Index{1}, y.size() - 2}) {
    EXPECT_NEAR(curved[i], -g, 1e-3 * g) << "frame " << i;
    EXPECT_GT(odd[i], -0.5 * g) << "frame " << i << ": the odd reflection reads the end as (nearly) unaccelerated";
  }
  // With 1 mm of white noise the kept ends stay within 15 % of g (the curvature is fitted over half
  // a cut-off period, 21 samples here).
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.001);
  Eigen::VectorXd noisy = y;
  for (Eigen::Index i = 0; i < noisy.size(); ++i) noisy[i] += noise(rng);
  const Eigen::VectorXd a = second_difference(butterworth_filtfilt(noisy, fs, fc, FilterEdge::Curvature), 1.0 / fs).col(0);
  EXPECT_NEAR(a[1], -g, 0.15 * g);
  EXPECT_NEAR(a[y.size() - 2], -g, 0.15 * g);
  // A ramp passes unchanged with either rule.
  for (const FilterEdge e : {FilterEdge::OddReflection, FilterEdge::Curvature}) {
    const Eigen::VectorXd ramp = Eigen::VectorXd::LinSpaced(300, 0.0, 3.0);
    EXPECT_NEAR((butterworth_filtfilt(ramp, fs, fc, e) - ramp).cwiseAbs().maxCoeff(), 0.0, 1e-6);
  }
}

// The matrix filter runs four (then two, then one) columns side by side; each column must come out
// bit for bit as the one-column filter gives it, whatever its place in the matrix, so that results
// do not depend on how many columns a trial has or on the number of threads.
TEST(Filter, ColumnsSideBySideGiveEachColumnsOwnFilterBitForBit) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  for (const Eigen::Index rows : {2, 3, 17, 250}) {
    Eigen::MatrixXd x(rows, 11);  // 4 + 4 + 2 + 1 columns
    for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = g(rng) + 0.01 * static_cast<double>(i % rows);
    const Eigen::MatrixXd y = butterworth_filtfilt(x, 100.0, 6.0);
    ASSERT_EQ(y.rows(), rows);
    ASSERT_EQ(y.cols(), x.cols());
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      const Eigen::VectorXd one = butterworth_filtfilt(Eigen::VectorXd(x.col(c)), 100.0, 6.0);
      for (Eigen::Index i = 0; i < rows; ++i) ASSERT_EQ(y(i, c), one[i]) << "row " << i << " column " << c << " of " << rows;
    }
  }
}

// A long trial's coordinates are filtered where they lie (issue 10's memory): a matrix given up
// with std::move comes back in the same storage, with the numbers a copy gets. (On several
// threads, in place too: Parallel.FilteringAndEstimatingGiveTheSameNumbersOnOneOrFourThreads.)
TEST(Filter, AMovedMatrixIsFilteredInPlaceWithTheSameNumbers) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd x(4000, 13);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = g(rng);
  const Eigen::MatrixXd copied = butterworth_filtfilt(x, 100.0, 6.0);
  EXPECT_FALSE(copied == x);  // the copy's caller keeps its unfiltered series
  const double* storage = x.data();
  const Eigen::MatrixXd y = butterworth_filtfilt(std::move(x), 100.0, 6.0);
  EXPECT_EQ(y.data(), storage);
  EXPECT_TRUE(y == copied);
}

// Noisy markers (issue 10): double differentiation multiplies noise by (2 pi f)^2, so 2 mm of
// white noise at 100 Hz through the paper's fixed 6 Hz puts tens of newtons of noise into the
// forces. The residual analysis lowers the cut-off for such markers only: the clean walk keeps
// 6 Hz exactly, and the noisy walk's forces stay nearer the clean ones than with 6 Hz.
TEST(NoisyMarkers, TheCutoffFallsToWhatTheNoiseAllowsAndOnlyThen) {
  const kin2grf::SyntheticWalk clean = kin2grf::make_synthetic_walk({});
  const auto* set = kin2grf::find_marker_set("kin2grf-example");
  const kin2grf::EstimateResult c = kin2grf::estimate(clean.trial, nullptr, *set, {});
  EXPECT_EQ(c.kinematic_cutoff_hz, 6.0);
  for (const auto& m : c.messages) EXPECT_EQ(m.find("cut-off lowered"), std::string::npos) << m;

  kin2grf::Trial noisy = clean.trial;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  for (auto& p : noisy.markers.positions_m)
    for (Eigen::Index i = 0; i < p.size(); ++i) p.data()[i] += noise(rng);
  // The torso's vertical smoothing (torso_vertical_cutoff_hz) takes the HAT's vertical noise out
  // at 4 Hz whatever the cut-off: off in both, so that the comparison is the noise rule's alone.
  kin2grf::EstimateOptions rule_options;
  rule_options.torso_vertical_cutoff_hz = 0.0;
  const kin2grf::EstimateResult rule = kin2grf::estimate(noisy, nullptr, *set, rule_options);
  kin2grf::EstimateOptions fixed_options = rule_options;
  fixed_options.cutoff_from_noise = false;
  const kin2grf::EstimateResult fixed = kin2grf::estimate(noisy, nullptr, *set, fixed_options);
  EXPECT_LT(rule.kinematic_cutoff_hz, 5.0) << rule.kinematic_cutoff_hz;
  EXPECT_GT(rule.kinematic_cutoff_hz, 2.0);
  EXPECT_EQ(fixed.kinematic_cutoff_hz, 6.0);
  // The whole-body vertical force (what the feet carry together) against the clean walk's.
  auto rms_error = [&](const kin2grf::EstimateResult& r) {
    const Eigen::VectorXd d = r.kinematic_total.col(1) - c.kinematic_total.col(1);
    return std::sqrt(d.squaredNorm() / static_cast<double>(d.size()));
  };
  EXPECT_LT(rms_error(rule), 0.8 * rms_error(fixed)) << rms_error(rule) << " N against " << rms_error(fixed) << " N";
}

namespace {
/// The walk with Gaussian noise of sigma_m on every marker coordinate (seeded).
kin2grf::Trial with_noise(const kin2grf::Trial& clean, double sigma_m, unsigned seed) {
  kin2grf::Trial noisy = clean;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_m);
  for (auto& p : noisy.markers.positions_m)
    for (Eigen::Index i = 0; i < p.size(); ++i) p.data()[i] += noise(rng);
  return noisy;
}
}  // namespace

// The failure mode (issue 10, 2 mm of noise on the Plug-in Gait walks): the residual analysis
// lowers the cut-off for positions, and the forces, second derivatives, lose the stance's own
// harmonics. The dynamics keep min_kinematic_cycles per stance; the COP function's angle (a
// position) keeps the lowered cut-off; the floor follows the walk's stance duration.
TEST(NoisyMarkers, TheDynamicsKeepTheStancesHarmonicsAndTheCopAngleTheLoweredCutoff) {
  const auto* set = kin2grf::find_marker_set("kin2grf-example");
  kin2grf::EstimateOptions no_floor;
  no_floor.min_kinematic_cycles = 0;
  // The mechanism at 3.5 cycles (the default until session 25, now 3.0, which the development
  // trials with 2 mm of noise choose held out): on this exact synthetic walk with 3 mm of white
  // noise 3.0 cycles' floor lies within a few tenths of a hertz of the lowered cut-off.
  EXPECT_EQ(kin2grf::EstimateOptions{}.min_kinematic_cycles, 3.0);
  kin2grf::EstimateOptions with_floor;
  with_floor.min_kinematic_cycles = 3.5;
  std::array<double, 2> dynamics_hz{};
  int walk = 0;
  for (const double stride_s : {1.0, 1.3}) {  // a brisk walk and a slow one, the same step length
    kin2grf::SyntheticWalkOptions wo;
    wo.stride_time_s = stride_s;
    wo.speed_mps = 1.32 / stride_s;
    wo.duration_s = 6.0;
    const kin2grf::SyntheticWalk w = kin2grf::make_synthetic_walk(wo);
    const kin2grf::EstimateResult clean = kin2grf::estimate(w.trial, nullptr, *set, with_floor);
    // Clean markers: nothing lowered, so nothing raised; the COP reads the foot's own angle.
    EXPECT_EQ(clean.kinematic_cutoff_hz, 6.0);
    EXPECT_EQ(clean.position_cutoff_hz, 6.0);
    EXPECT_EQ(clean.motion.cop_foot_angle_rad.size(), 0);
    double err_floor = 0, err_none = 0;  // per-foot anterior force against the clean estimate's, N^2
    for (unsigned seed = 1; seed <= 4; ++seed) {
      const kin2grf::Trial noisy = with_noise(w.trial, 0.003, seed);
      const kin2grf::EstimateResult a = kin2grf::estimate(noisy, nullptr, *set, no_floor);
      // The progress: one count over both passes (twice the frames), which ends complete.
      kin2grf::EstimateOptions with_progress = with_floor;
      std::vector<std::pair<long, long>> progress;
      std::mutex mu;
      with_progress.progress = [&](long done, long total) {
        const std::lock_guard<std::mutex> lock(mu);
        progress.emplace_back(done, total);
      };
      const kin2grf::EstimateResult b = kin2grf::estimate(noisy, nullptr, *set, with_progress);
      ASSERT_FALSE(progress.empty());
      long most = 0;
      for (const auto& [done, total] : progress) {
        EXPECT_EQ(total, progress.front().second);
        most = std::max(most, done);
      }
      EXPECT_EQ(progress.back().first, progress.back().second);
      EXPECT_EQ(most, progress.front().second);
      EXPECT_EQ(progress.front().second, 2 * b.time_s.size());
      EXPECT_LT(a.kinematic_cutoff_hz, 5.0);
      EXPECT_EQ(a.kinematic_cutoff_hz, a.position_cutoff_hz);
      // The same positions' cut-off; the dynamics' raised to 3 cycles over the first solve's
      // median stance (0.6-0.9 s here), never above the 6 Hz the user asked for.
      EXPECT_EQ(b.position_cutoff_hz, a.position_cutoff_hz);
      EXPECT_GT(b.kinematic_cutoff_hz, b.position_cutoff_hz + 0.2);
      EXPECT_LE(b.kinematic_cutoff_hz, 6.0);
      const auto stance = kin2grf::median_stance_s({a.feet[0].contact, a.feet[1].contact}, a.motion.rate_hz);
      ASSERT_TRUE(stance);
      EXPECT_NEAR(b.kinematic_cutoff_hz, std::min(6.0, with_floor.min_kinematic_cycles / *stance), 0.15) << "median stance " << *stance << " s";
      EXPECT_EQ(b.motion.cop_foot_angle_rad.rows(), b.motion.frames());
      const bool said = std::any_of(b.messages.begin(), b.messages.end(),
                                    [](const std::string& m) { return m.find("raised to") != std::string::npos; });
      EXPECT_TRUE(said);
      for (int s = 0; s < 2; ++s) {
        err_none += (a.feet[s].force_N.col(0) - clean.feet[s].force_N.col(0)).squaredNorm();
        err_floor += (b.feet[s].force_N.col(0) - clean.feet[s].force_N.col(0)).squaredNorm();
      }
      if (seed == 1) dynamics_hz[static_cast<std::size_t>(walk)] = b.kinematic_cutoff_hz;
    }
    // Measured with 8 draws: 15.2 -> 9.5 N RMS (brisk), 12.6 -> 7.8 N (slow).
    EXPECT_LT(std::sqrt(err_floor), 0.8 * std::sqrt(err_none)) << "stride " << stride_s << " s";
    ++walk;
  }
  // The floor follows the motion: the slow walk's longer stances get a lower one.
  EXPECT_LT(dynamics_hz[1], dynamics_hz[0] - 0.5) << dynamics_hz[0] << " and " << dynamics_hz[1] << " Hz";
}
