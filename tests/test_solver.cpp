// Tests of dynamics/inverse_dynamics: the per-frame solve (Eqs. 5-10).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

// The structured factorisation (normal equations, compiled L D L^T) and a dense rank-revealing one give the same
// multipliers on every frame of a squat (double support) and a single-support trial.
TEST(Solver, StructuredAndDenseFactorisationsAgree) {
  for (double raised : {0.0, 0.6}) {
    SyntheticOptions so;
    so.left_leg_raised_rad = raised;
    const Trial t = make_synthetic_trial(so);
    const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), {});
    const ModelMotion mm = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
    const auto tc = test::contact_frames(r.model(), r.calibration.contact, ContactModelOptions{}, mm);
    const auto& contacts = tc.contacts;
    SolverOptions structured_opt, dense_opt;
    dense_opt.dense_factorisation = true;
    ContactSolver structured(r.model(), r.calibration, structured_opt), dense(r.model(), r.calibration, dense_opt);
    for (Eigen::Index i = 0; i < mm.frames(); i += 11) {
      const MotionFrame& f = tc.frames[static_cast<std::size_t>(i)];
      const Eigen::VectorXd q = f.q, qdd = f.qdd;
      const auto a = structured.solve(q, qdd, contacts[static_cast<std::size_t>(i)]);
      const auto b = dense.solve(q, qdd, contacts[static_cast<std::size_t>(i)]);
      ASSERT_EQ(a.contact_active, b.contact_active) << "frame " << i;
      EXPECT_LT((a.contact_lambda - b.contact_lambda).cwiseAbs().maxCoeff(), 1e-6) << "frame " << i;
      EXPECT_LT((a.joint_torque_Nm - b.joint_torque_Nm).cwiseAbs().maxCoeff(), 1e-6) << "frame " << i;
    }
  }
}

// A slow walker's swing foot (issue 9): 0.4 m/s, the swing foot's sole 8 mm above the floor and
// moving at 1 m/s, slower than the old fixed 1.5 m/s gate. The kinematics carry a small moment the
// stance foot alone cannot balance (a torso angular acceleration error, as real marker data do);
// the least squares then hands the swing foot a share. With the gate relative to the progression
// speed the swing foot must carry exactly nothing and the stance foot must stay in contact.
TEST(Solver, SlowWalkSwingFootCarriesNothing) {
  SyntheticOptions so;
  so.left_leg_raised_rad = 0.6;
  const Trial t = make_synthetic_trial(so);
  EstimateOptions eo;
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
  const ModelMotion mm = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
  const auto tc = test::contact_frames(r.model(), r.calibration.contact, ContactModelOptions{}, mm);
  const std::size_t i = 120;
  FrameContacts fc = tc.contacts[i];
  ASSERT_EQ(fc.points.size(), 2u);
  fc.points[0].velocity.setZero();                 // the stance foot's D* is still
  fc.points[1].gap_m = 0.008;                      // low swing clearance
  fc.points[1].velocity = Eigen::Vector2d(1.0, 0);  // a slow walker's swing foot
  const MotionFrame& f = tc.frames[i];
  const Eigen::VectorXd q = f.q;
  Eigen::VectorXd qdd = f.qdd;
  qdd[coord::theta(kTorso)] += 20.0;  // rad/s^2: about 30 N m that no single contact point balances

  TrialCalibration fixed = r.calibration;  // the old fixed gate
  fixed.speed_gate_mps = 1.5;
  const FrameSolution before = ContactSolver(r.model(), fixed, SolverOptions{}).solve(q, qdd, fc);
  ASSERT_TRUE(test::foot_active(before, fc, 1)) << "the failure this test guards: the fixed gate lets the swing foot in";
  ASSERT_GT(test::foot_force(before, fc, 1).y(), 20.0);

  TrialCalibration rule = r.calibration;  // the defaults: 0.7 x the progression speed
  rule.speed_gate_mps = speed_gate_for(SpeedGateRule{}, 0.4);
  EXPECT_NEAR(rule.speed_gate_mps, 0.28, 1e-12);
  const FrameSolution after = ContactSolver(r.model(), rule, SolverOptions{}).solve(q, qdd, fc);
  EXPECT_FALSE(test::foot_active(after, fc, 1));
  EXPECT_EQ(test::foot_force(after, fc, 1).y(), 0.0);
  EXPECT_EQ(test::foot_force(after, fc, 1).x(), 0.0);
  EXPECT_TRUE(test::foot_active(after, fc, 0));
  EXPECT_GT(test::foot_force(after, fc, 0).y(), 0.8 * 70 * 9.81);
}

// A slow walker's landing foot (issue 29: a 0.36 m/s walk whose swing foot hovered 7-10 mm up
// for 200 ms took load 180 ms before it landed): in terminal swing the foot, 8 mm up, still moves
// at 0.5 m/s, slower than the 0.75 m/s floor that held everywhere until then but faster than
// 0.7 x 0.35 m/s. The floor now holds only near a flight phase (a jump's landing, whose feet the
// filtered kinematics still show moving): there the same foot may take load.
TEST(Solver, ASlowWalkersHoveringFootIsGatedByTheWalkersOwnSpeed) {
  SyntheticOptions so;
  so.left_leg_raised_rad = 0.6;
  const Trial t = make_synthetic_trial(so);
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  const ModelMotion mm = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
  const auto tc = test::contact_frames(r.model(), r.calibration.contact, ContactModelOptions{}, mm);
  const std::size_t i = 120;
  FrameContacts fc = tc.contacts[i];
  ASSERT_EQ(fc.points.size(), 2u);
  fc.points[0].velocity.setZero();
  fc.points[1].gap_m = 0.008;                       // hovering
  fc.points[1].velocity = Eigen::Vector2d(0.5, 0);  // terminal swing, slowing to its landing
  Eigen::VectorXd qdd = tc.frames[i].qdd;
  qdd[coord::theta(kTorso)] += 20.0;  // a moment the stance foot alone cannot balance (as above)

  TrialCalibration cal = r.calibration;
  cal.speed_gate_mps = speed_gate_for(SpeedGateRule{}, 0.35);
  cal.flight_speed_gate_mps = speed_gate_for(SpeedGateRule{}, 0.35, true);
  EXPECT_NEAR(cal.speed_gate_mps, 0.245, 1e-12);
  EXPECT_NEAR(cal.flight_speed_gate_mps, 0.75, 1e-12);
  const FrameSolution walking = ContactSolver(r.model(), cal, SolverOptions{}).solve(tc.frames[i].q, qdd, fc);
  EXPECT_FALSE(test::foot_active(walking, fc, 1));
  EXPECT_EQ(test::foot_force(walking, fc, 1).y(), 0.0);
  EXPECT_TRUE(test::foot_active(walking, fc, 0));

  fc.near_flight = true;  // the same frame near a flight: the floor lets the landing foot in
  const FrameSolution landing = ContactSolver(r.model(), cal, SolverOptions{}).solve(tc.frames[i].q, qdd, fc);
  ASSERT_TRUE(test::foot_active(landing, fc, 1)) << "the failure this test guards: the floor lets a hovering foot in";
  EXPECT_GT(test::foot_force(landing, fc, 1).y(), 20.0);
}

TEST(Solver, SpeedGateScalesWithTheProgressionSpeed) {
  SpeedGateRule o;  // defaults
  EXPECT_NEAR(speed_gate_for(o, 0.0), 0.1, 1e-12);    // standing, squatting: at standstill
  EXPECT_NEAR(speed_gate_for(o, 0.4), 0.28, 1e-12);   // a slow walk: 0.7 x v
  EXPECT_NEAR(speed_gate_for(o, 0.0, true), 0.75, 1e-12);  // near a flight: the floor
  EXPECT_NEAR(speed_gate_for(o, 1.0, true), 0.75, 1e-12);  // 0.7 x 1.0 is under it
  EXPECT_NEAR(speed_gate_for(o, 3.0, true), 2.1, 1e-12);   // a run: 0.7 x v
  EXPECT_NEAR(speed_gate_for(o, 1.3), 0.91, 1e-12);   // walking: 0.7 x v
  EXPECT_NEAR(speed_gate_for(o, 9.0), 6.3, 1e-12);    // sprinting: the landing foot is not cut
  EXPECT_NEAR(speed_gate_for(o, -3.5), 2.45, 1e-12);  // a treadmill belt's sign does not matter
  o.ratio = 0;
  o.fixed_mps = 1.5;
  EXPECT_NEAR(speed_gate_for(o, 9.0), 1.5, 1e-12);    // a fixed gate stays fixed
  // The hip's progression speed, through a step's oscillation (+-0.1 m/s at 2 Hz).
  SagittalLandmarks lm;
  lm.rate_hz = 100;
  lm.time_s = Eigen::VectorXd::LinSpaced(400, 0, 3.99);
  for (auto& p : lm.p) p = Eigen::MatrixX2d::Zero(400, 2);
  for (Eigen::Index k = 0; k < 400; ++k)
    lm.p[kHip](k, 0) = 0.4 * lm.time_s[k] + 0.1 / (4 * M_PI) * std::sin(4 * M_PI * lm.time_s[k]);
  EXPECT_NEAR(progression_speed(lm), 0.4, 0.01);
}
