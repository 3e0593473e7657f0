// Tests of kinematics/motion: model coordinates from the landmarks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

using kin2grf::test::run;
using kin2grf::test::synthetic_landmarks;

TEST(Kinematics, ReconstructionSatisfiesTheBilateralConstraints) {
  const Trial t = make_synthetic_trial({});
  SyntheticOptions so;
  const auto r = run(so);
  // Rebuild the motion and check Phi(q) ~ 0 via Phi_q qd = 0 and finite differences of q.
  const SagittalLandmarks lm = synthetic_landmarks(t);
  const ModelMotion mm = compute_motion(r.model(), lm, 6.0);
  const auto tc = test::contact_frames(r.model(), r.calibration.contact, ContactModelOptions{}, mm);
  ContactSolver solver(r.model(), r.calibration, {});
  for (Eigen::Index i = 5; i < mm.frames(); i += 37) {
    const MotionFrame& f = tc.frames[static_cast<std::size_t>(i)];
    const Eigen::MatrixXd Phi = solver.bilateral_jacobian(f.q);
    // Velocity level: Phi_q qd = 0 except the rheonomic rows (their time derivative is phi_dot).
    Eigen::VectorXd v = Phi * f.qd;
    v.segment(row::kDriving, kJointCount) -= f.qd.segment(coord::kPhi, 8);
    EXPECT_LT(v.cwiseAbs().maxCoeff(), 1e-9) << "frame " << i;
  }
}

TEST(Kinematics, ReconstructedPositionsKeepTheSegmentLengths) {
  SyntheticOptions so;
  so.left_leg_raised_rad = 0.3;
  const Trial t = make_synthetic_trial(so);
  const auto r = run(so);
  const ModelMotion mm = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
  // Position level: every landmark attached to a body stays at its body-fixed place, so the
  // distance to the proximal landmark is the same in every frame (fixed-length model).
  for (int s = 0; s < kSegmentCount; ++s) {
    const Body& b = r.model().bodies[s];
    for (int k = 0; k < 2; ++k) {
      if (b.points[k] < 0) continue;
      const double L = b.points_local[k].norm();
      for (Eigen::Index i = 0; i < mm.frames(); i += 13) {
        const MotionFrame f = mm.frame(i);
        const Eigen::Vector2d p = f.q.segment<2>(coord::point_x(b.points[k]));
        const Eigen::Vector2d o = f.q.segment<2>(coord::point_x(b.proximal));
        EXPECT_NEAR((p - o).norm(), L, 1e-12) << "segment " << s << " frame " << i;
      }
    }
  }
}

// The torso takes its measured hip-shoulder length (TorsoLength::Measured): the shoulders
// moving 2 cm up and down against the hip make the reconstructed torso follow, and its points'
// accelerations are the second derivatives of their positions (the k' and k'' terms).
TEST(Kinematics, MeasuredTorsoLengthIsFollowedAndDifferentiated) {
  Trial t = make_synthetic_trial({});
  const auto r = run({});
  const Eigen::ArrayXd bob = 0.02 * (2.0 * M_PI * 1.5 * t.markers.time_s.array()).sin();
  for (const char* s : {"RSHO", "LSHO"}) t.markers.positions_m[static_cast<std::size_t>(t.markers.find(s))].col(2).array() += bob;
  const SagittalLandmarks lm = synthetic_landmarks(t);
  const ModelMotion measured = compute_motion(r.model(), lm, 6.0, TorsoLength::Measured);
  const ModelMotion fixed = compute_motion(r.model(), lm, 6.0, TorsoLength::Fixed);
  const double dt = 1.0 / lm.rate_hz, L0 = r.model().bodies[kTorso].length_m;
  auto point = [](const ModelMotion& m, int col, Eigen::Index i) { return Eigen::Vector2d(m.frame(i).q.segment<2>(col)); };
  double worst_len = 0, worst_acc = 0, fixed_spread = 0, acc_scale = 0;
  const int sh = coord::point_x(kShoulder), hip = coord::point_x(kHip), com = coord::com_x(kTorso);
  for (Eigen::Index i = 20; i < measured.frames() - 20; ++i) {
    const double len = (point(measured, sh, i) - point(measured, hip, i)).norm();
    const double truth = (lm.p[kShoulder].row(i) - lm.p[kHip].row(i)).norm();
    worst_len = std::max(worst_len, std::abs(len - truth));
    fixed_spread = std::max(fixed_spread, std::abs((point(fixed, sh, i) - point(fixed, hip, i)).norm() - L0));
    // Second central difference of the torso COM position against its reconstructed acceleration.
    const Eigen::Vector2d fd = (point(measured, com, i + 1) - 2 * point(measured, com, i) + point(measured, com, i - 1)) / (dt * dt);
    const Eigen::Vector2d a = measured.frame(i).qdd.segment<2>(com);
    worst_acc = std::max(worst_acc, (fd - a).norm());
    acc_scale = std::max(acc_scale, a.norm());
  }
  EXPECT_LT(worst_len, 2e-3);           // follows the measured length (6 Hz filtered, 1.5 Hz bob)
  EXPECT_LT(fixed_spread, 1e-12);       // the paper's rigid torso does not
  EXPECT_LT(worst_acc, 0.02 * acc_scale);  // the scaled kinematics are differentiated consistently
  EXPECT_GT(acc_scale, 0.5);
}

// The upper body's fore-aft lag (lag_torso_fore_aft): only the HAT COM's fore-aft acceleration
// changes, causally (nothing before a step moves), delayed whole (a delay, not a filter); tau = 0
// changes nothing. In the whole estimate the vertical force sum is untouched and the fore-aft one
// is not.
TEST(Kinematics, TorsoLagDelaysOnlyTheTorsosForeAftAcceleration) {
  const Trial t = make_synthetic_trial({});
  const auto r = run({});
  const ModelMotion base = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
  const int c = coord::com_x(kTorso);
  ModelMotion step = base;
  const Eigen::Index i0 = 100;
  for (Eigen::Index i = 0; i < step.frames(); ++i) step.torso_ax_mps2[i] = i < i0 ? 0.0 : 1.0;
  const ModelMotion before = step;
  const double tau = 0.03;
  ASSERT_EQ(step.rate_hz, 100.0);
  // A delay of 3 frames: the step arrives whole at frame i0 + 3, nothing before (causal), no
  // overshoot, no attenuation.
  lag_torso_fore_aft(step, tau);
  for (Eigen::Index i = 0; i < step.frames(); ++i) ASSERT_EQ(step.frame(i).qdd(c), i < i0 + 3 ? 0.0 : 1.0) << i;
  // 25 ms, between frames: half the step at frame i0 + 2 (linear interpolation).
  ModelMotion half = before;
  lag_torso_fore_aft(half, 0.025);
  EXPECT_EQ(half.torso_ax_mps2[i0 + 1], 0.0);
  EXPECT_NEAR(half.torso_ax_mps2[i0 + 2], 0.5, 1e-12);
  EXPECT_EQ(half.torso_ax_mps2[i0 + 3], 1.0);
  // A sine comes out as itself, later: a delay, not a filter.
  ModelMotion sine = before;
  for (Eigen::Index i = 0; i < sine.frames(); ++i) sine.torso_ax_mps2[i] = std::sin(2 * M_PI * 1.5 * static_cast<double>(i) / 100.0);
  lag_torso_fore_aft(sine, tau);
  for (Eigen::Index i = 3; i < sine.frames(); ++i)
    ASSERT_NEAR(sine.torso_ax_mps2[i], std::sin(2 * M_PI * 1.5 * (static_cast<double>(i) / 100.0 - tau)), 1e-12) << i;
  for (Eigen::Index i = 0; i < step.frames(); ++i) {
    const MotionFrame a = step.frame(i), b = before.frame(i);
    Eigen::VectorXd others = a.qdd - b.qdd;
    others(c) = 0.0;
    ASSERT_EQ(others.cwiseAbs().maxCoeff(), 0.0) << i;  // vertical, angles, every other segment
    ASSERT_EQ(a.q, b.q) << i;
    ASSERT_EQ(a.qd, b.qd) << i;
  }
  ModelMotion same = base;
  lag_torso_fore_aft(same, 0.0);
  EXPECT_EQ(same.torso_ax_mps2, base.torso_ax_mps2);

  EstimateOptions none, lagged;
  none.torso_lag_s = 0.0;
  lagged.torso_lag_s = tau;
  const auto a = run({}, none), b = run({}, lagged);
  EXPECT_EQ(a.kinematic_total.col(1), b.kinematic_total.col(1));
  EXPECT_GT((a.kinematic_total.col(0) - b.kinematic_total.col(0)).cwiseAbs().maxCoeff(), 1.0);  // N
}

namespace {
/// Two frames of one motion, one of them with a rule applied that writes one series: q, qd and
/// every entry of qdd but `entry` are the same bit for bit.
::testing::AssertionResult only_qdd_entry_differs(const MotionFrame& a, const MotionFrame& b, int entry) {
  Eigen::VectorXd others = a.qdd - b.qdd;
  others(entry) = 0.0;
  if (others.cwiseAbs().maxCoeff() != 0.0) return ::testing::AssertionFailure() << "another qdd entry moved";
  if (a.q != b.q) return ::testing::AssertionFailure() << "q moved";
  if (a.qd != b.qd) return ::testing::AssertionFailure() << "qd moved";
  return ::testing::AssertionSuccess();
}
}  // namespace

// The thigh's fore-aft lag (lag_thigh_fore_aft): that side's thigh COM fore-aft acceleration
// becomes the chain's own, delayed whole (a delay: the series shifted by tau), and nothing else
// of the frame moves: the other thigh, the torso, the vertical and angular accelerations, q, qd.
TEST(Kinematics, ThighLagDelaysOnlyThatThighsForeAftAcceleration) {
  SyntheticWalkOptions wo;
  const SyntheticWalk w = make_synthetic_walk(wo);
  const auto r = estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), {});
  const ModelMotion base = compute_motion(r.model(), r.landmarks, 6.0);
  ASSERT_EQ(base.rate_hz, 100.0);
  ModelMotion lagged = base;
  lag_thigh_fore_aft(lagged, 1, 0.02);  // the left thigh, 2 frames
  EXPECT_TRUE(lagged.thigh_ax_mps2[0].size() == 0);
  const int left = coord::com_x(segment(1, kThigh));
  double swing = 0;
  for (Eigen::Index i = 2; i < base.frames(); ++i) {
    const MotionFrame a = lagged.frame(i), b = base.frame(i), early = base.frame(i - 2);
    ASSERT_NEAR(a.qdd(left), early.qdd(left), 1e-9) << i;
    swing = std::max(swing, std::abs(b.qdd(left) - early.qdd(left)));
    ASSERT_TRUE(only_qdd_entry_differs(a, b, left)) << i;
  }
  EXPECT_GT(swing, 0.5);  // m/s^2: a swinging thigh's acceleration changes within 20 ms
  ModelMotion same = base;
  lag_thigh_fore_aft(same, 0, 0.0);
  EXPECT_TRUE(same.thigh_ax_mps2[0].size() == 0);
}

// The upper body's vertical smoothing (smooth_torso_vertical): the HAT COM's vertical
// acceleration becomes the zero-lag low-pass of the chain's, and nothing else of any frame moves.
TEST(Kinematics, TorsoVerticalSmoothingLowPassesOnlyTheHatsVerticalAcceleration) {
  const SyntheticWalk w = make_synthetic_walk({});
  const auto r = estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), {});
  const ModelMotion base = compute_motion(r.model(), r.landmarks, 6.0);
  ModelMotion smoothed = base;
  smooth_torso_vertical(smoothed, 2.0);
  const int hat_y = coord::com_x(kTorso) + 1;
  Eigen::VectorXd chain(base.frames());
  for (Eigen::Index i = 0; i < base.frames(); ++i) chain[i] = base.frame(i).qdd(hat_y);
  const Eigen::VectorXd expected = butterworth_filtfilt(chain, base.rate_hz, 2.0);
  double moved = 0;
  for (Eigen::Index i = 0; i < base.frames(); ++i) {
    const MotionFrame a = smoothed.frame(i), b = base.frame(i);
    ASSERT_NEAR(a.qdd(hat_y), expected[i], 1e-12) << i;
    moved = std::max(moved, std::abs(a.qdd(hat_y) - b.qdd(hat_y)));
    ASSERT_TRUE(only_qdd_entry_differs(a, b, hat_y)) << i;
  }
  EXPECT_GT(moved, 0.05);  // m/s^2: the walk's vertical acceleration has content above 2 Hz
  ModelMotion same = base;
  smooth_torso_vertical(same, 0.0);
  EXPECT_EQ(same.torso_ay_mps2.size(), 0);
}

// How late the trunk already follows the hip (measured_torso_lag_s): a HAT whose fore-aft
// acceleration is the hip's 20 ms later (a trunk-marker set whose shoulders lag the pelvis) is
// measured at 20 ms, between frames too; in phase 0, ahead negative; too short a trial 0. The
// torso lag adds only the rest (the pipeline's lag_torso_stage).
TEST(Kinematics, TheTrunksOwnLagBehindTheHipIsMeasured) {
  const auto r = run({});
  ModelMotion m = compute_motion(r.model(), synthetic_landmarks(make_synthetic_trial({})), 6.0);
  auto with_delay = [&](double delay_s) {
    ModelMotion d = m;
    d.xd = Eigen::MatrixXd::Zero(d.frames(), d.x.cols());  // stored derivatives, set below
    d.xdd = Eigen::MatrixXd::Zero(d.frames(), d.x.cols());
    for (Eigen::Index i = 0; i < d.frames(); ++i) {
      const double t = static_cast<double>(i) / d.rate_hz;
      d.xdd(i, 0) = std::sin(2 * M_PI * 1.8 * t) + 0.4 * std::sin(2 * M_PI * 3.6 * t + 0.7);  // the hip's fore-aft
      d.torso_ax_mps2[i] = std::sin(2 * M_PI * 1.8 * (t - delay_s)) + 0.4 * std::sin(2 * M_PI * 3.6 * (t - delay_s) + 0.7);
    }
    return measured_torso_lag_s(d);
  };
  ASSERT_GE(m.rate_hz, 50.0);
  EXPECT_NEAR(with_delay(0.0), 0.0, 1e-3);
  EXPECT_NEAR(with_delay(0.02), 0.02, 2e-3);
  EXPECT_NEAR(with_delay(0.025), 0.025, 2e-3);  // between frames
  EXPECT_NEAR(with_delay(-0.015), -0.015, 2e-3);
  ModelMotion short_trial = m;
  short_trial.time_s = short_trial.time_s.head(10).eval();
  short_trial.x = short_trial.x.topRows(10).eval();
  short_trial.torso_ax_mps2 = short_trial.torso_ax_mps2.head(10).eval();
  EXPECT_EQ(measured_torso_lag_s(short_trial), 0.0);
}

// A trial's motion is held as what determines it (independent coordinates, the torso's fore-aft
// acceleration, D*): at most 16 numbers a frame, not the 3 x 63 of q, qd, qdd nor the x, xd, xdd
// of the 12 independent coordinates (issue 10's memory). Each frame takes x's central differences,
// the very doubles of the whole-trial central_difference and second_difference (at the ends too),
// and every frame() is rebuilt the same, however often it is asked for.
TEST(Kinematics, TheMotionHoldsFewNumbersAFrameAndRebuildsEachFrameAlike) {
  const auto r = run({});
  const ModelMotion m = compute_motion(r.model(), synthetic_landmarks(make_synthetic_trial({})), 6.0);
  const Eigen::Index n = m.frames();
  ASSERT_GT(n, 100);
  const auto held = m.x.size() + m.xd.size() + m.xdd.size() + m.torso_ax_mps2.size() + m.time_s.size();
  EXPECT_LE(held, 16 * n);
  EXPECT_GE(held, 12 * n);  // x of the 12 independent coordinates at least
  const Eigen::MatrixXd xd = central_difference(m.x, 1.0 / m.rate_hz), xdd = second_difference(m.x, 1.0 / m.rate_hz);
  ModelMotion stored = m;
  stored.xd = xd;
  stored.xdd = xdd;
  for (const Eigen::Index i : {Eigen::Index{0}, Eigen::Index{1}, n / 2, n - 2, n - 1}) {
    const MotionFrame a = m.frame(i), b = m.frame(i), c = stored.frame(i);
    EXPECT_EQ(a.q, b.q);
    EXPECT_EQ(a.qdd, b.qdd);
    EXPECT_EQ(a.qd, c.qd) << i;
    EXPECT_EQ(a.qdd, c.qdd) << i;
    EXPECT_EQ(a.qdd(coord::com_x(kTorso)), m.torso_ax_mps2[i]);
    EXPECT_EQ(a.qdd.segment<2>(coord::point_x(kHip)), Eigen::Vector2d(xdd(i, 0), xdd(i, 1))) << i;
    EXPECT_EQ(a.qd.segment<2>(coord::point_x(kHip)), Eigen::Vector2d(xd(i, 0), xd(i, 1))) << i;
  }
  EXPECT_EQ(m.xdd_column(0), xdd.col(0));
}

// The noise-limited cut-off reads at most a minute of frames (the noise of a recording does not
// change along it), and gathers only those (a long trial's memory, issue 10): on a 70 s trial
// with noisy markers it is the residual analysis of all the landmarks' columns.
TEST(Kinematics, TheNoiseLimitedCutOffOfALongTrialIsTheResidualAnalysisOfItsFirstMinute) {
  SyntheticOptions so;
  so.duration_s = 70.0;
  SagittalLandmarks lm = synthetic_landmarks(make_synthetic_trial(so));
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.004);
  for (auto& P : lm.p)
    for (Eigen::Index i = 0; i < P.rows(); ++i) P(i, 0) += noise(rng), P(i, 1) += noise(rng);
  Eigen::MatrixXd all(lm.frames(), 2 * kLandmarkCount);
  for (int k = 0; k < kLandmarkCount; ++k) all.middleCols(2 * k, 2) = lm.p[static_cast<std::size_t>(k)];
  const double fc = noise_limited_cutoff(lm, 6.0);
  EXPECT_LT(fc, 6.0);  // the noise lowers it
  EXPECT_EQ(fc, residual_analysis_cutoff(all, lm.rate_hz, 6.0));
}

// The COP function's foot angle at its own cut-off (min_kinematic_cycles): the foot's theta as the
// chain builds it, filtered at that cut-off, i.e. what compute_motion at that cut-off gives.
TEST(Kinematics, TheCopsFootAngleAtItsOwnCutoffIsTheFootsThetaFilteredThere) {
  const Trial t = make_synthetic_trial({});
  const auto r = run(SyntheticOptions{});
  const SagittalLandmarks lm = synthetic_landmarks(t);
  const ModelMotion at4 = compute_motion(r.model(), lm, 4.0);
  const ModelMotion mixed = compute_motion(r.model(), lm, 6.0, TorsoLength::Measured, 4.0);
  const ModelMotion plain = compute_motion(r.model(), lm, 6.0);
  ASSERT_EQ(mixed.cop_foot_angle_rad.rows(), lm.frames());
  EXPECT_EQ(plain.cop_foot_angle_rad.size(), 0);
  MotionFrame f4, fm, fp;
  for (Eigen::Index i = 0; i < lm.frames(); i += 7) {
    at4.frame(i, f4);
    mixed.frame(i, fm);
    plain.frame(i, fp);
    for (int s = 0; s < 2; ++s) {
      EXPECT_NEAR(fm.cop_foot_angle_rad[static_cast<std::size_t>(s)], f4.q(coord::theta(segment(s, kFoot))), 1e-12) << i;
      EXPECT_TRUE(std::isnan(fp.cop_foot_angle_rad[static_cast<std::size_t>(s)]));
    }
    EXPECT_EQ(fm.q, fp.q);  // the model's own motion stays at 6 Hz
  }
}
