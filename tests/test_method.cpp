// Tests of the method's core on synthetic trials of the project's own making.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

namespace {

/// The synthetic trial's markers are the landmarks themselves (x forward, z up).
SagittalLandmarks synthetic_landmarks(const Trial& t) {
  SagittalLandmarks lm;
  lm.rate_hz = t.markers.rate_hz;
  lm.time_s = t.markers.time_s;
  for (int k = 0; k < kLandmarkCount; ++k) lm.p[k].resize(lm.frames(), 2);
  for (int side = 0; side < 2; ++side)
    for (int k = 2; k < 7; ++k) {
      const auto& P = t.markers.positions_m[static_cast<std::size_t>(7 * side + k)];
      lm.p[landmark(side, static_cast<LegLandmark>(k - 2))].col(0) = P.col(0);
      lm.p[landmark(side, static_cast<LegLandmark>(k - 2))].col(1) = P.col(2);
    }
  for (int k : {0, 1}) {  // shoulder, hip
    lm.p[k].col(0) = t.markers.positions_m[static_cast<std::size_t>(k)].col(0);
    lm.p[k].col(1) = t.markers.positions_m[static_cast<std::size_t>(k)].col(2);
  }
  return lm;
}

EstimateResult run(const SyntheticOptions& so, EstimateOptions eo = {}) {
  const Trial t = make_synthetic_trial(so);
  return estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
}

}  // namespace

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

TEST(Model, MassMatrixSumsToBodyMass) {
  const auto r = run({});
  double m = 0;
  for (const auto& b : r.model.bodies) m += b.mass_kg;
  EXPECT_NEAR(m, 70.0 * (0.678 + 2 * (0.100 + 0.0465 + 0.0145)), 1e-9);
  EXPECT_NEAR(r.model.mass_diagonal().sum(), 2 * m + [&] { double s = 0; for (auto& b : r.model.bodies) s += b.inertia_kgm2; return s; }(), 1e-9);
}

TEST(Kinematics, ReconstructionSatisfiesTheBilateralConstraints) {
  const Trial t = make_synthetic_trial({});
  SyntheticOptions so;
  const auto r = run(so);
  // Rebuild the motion and check Phi(q) ~ 0 via Phi_q qd = 0 and finite differences of q.
  const SagittalLandmarks lm = synthetic_landmarks(t);
  ModelMotion mm = compute_motion(r.model, lm, 6.0);
  (void)prepare_contacts(r.model, r.calibration.contact, ContactModelOptions{}, mm);
  ContactSolver solver(r.model, r.calibration, {});
  for (Eigen::Index i = 5; i < mm.frames(); i += 37) {
    const Eigen::MatrixXd Phi = solver.bilateral_jacobian(mm.q.row(i).transpose());
    // Velocity level: Phi_q qd = 0 except the rheonomic rows (their time derivative is phi_dot).
    Eigen::VectorXd v = Phi * mm.qd.row(i).transpose();
    v.segment(row::kDriving, kJointCount) -= mm.qd.row(i).segment(coord::kPhi, 8).transpose();
    EXPECT_LT(v.cwiseAbs().maxCoeff(), 1e-9) << "frame " << i;
  }
}

TEST(Kinematics, ReconstructedPositionsKeepTheSegmentLengths) {
  SyntheticOptions so;
  so.left_leg_raised_rad = 0.3;
  const Trial t = make_synthetic_trial(so);
  const auto r = run(so);
  const ModelMotion mm = compute_motion(r.model, synthetic_landmarks(t), 6.0);
  // Position level: every landmark attached to a body stays at its body-fixed place, so the
  // distance to the proximal landmark is the same in every frame (fixed-length model).
  for (int s = 0; s < kSegmentCount; ++s) {
    const Body& b = r.model.bodies[s];
    for (int k = 0; k < 2; ++k) {
      if (b.points[k] < 0) continue;
      const double L = b.points_local[k].norm();
      for (Eigen::Index i = 0; i < mm.frames(); i += 13) {
        const Eigen::Vector2d p(mm.q(i, coord::point_x(b.points[k])), mm.q(i, coord::point_x(b.points[k]) + 1));
        const Eigen::Vector2d o(mm.q(i, coord::point_x(b.proximal)), mm.q(i, coord::point_x(b.proximal) + 1));
        EXPECT_NEAR((p - o).norm(), L, 1e-12) << "segment " << s << " frame " << i;
      }
    }
  }
}

TEST(Estimate, QuietStandingCarriesBodyWeightUnderTheCentreOfMass) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  const auto r = run(so);
  const double mg = 70.0 * 9.81;
  for (Eigen::Index i = 10; i < r.time_s.size() - 10; ++i) {
    const double fy = r.feet[0].force_N(i, 1) + r.feet[1].force_N(i, 1);
    EXPECT_NEAR(fy, mg, 0.005 * mg) << "frame " << i;
    EXPECT_NEAR(r.feet[0].force_N(i, 1), r.feet[1].force_N(i, 1), 1.0) << "symmetric stance";
    EXPECT_TRUE(r.feet[0].contact[static_cast<std::size_t>(i)] && r.feet[1].contact[static_cast<std::size_t>(i)]);
  }
}

TEST(Estimate, SquatTotalVerticalForceMatchesTheSegmentAccelerations) {
  const auto r = run({});
  for (Eigen::Index i = 10; i < r.time_s.size() - 10; ++i) {
    // The residual is what the contacts could not explain; in double support it must vanish.
    EXPECT_LT(std::abs(r.residual(i, 1)), 5.0) << "frame " << i;
  }
}

TEST(Estimate, BallisticFlightHasNoGroundReaction) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;  // apex 30 cm, flight of 0.49 s centred in a 3 s trial
  const auto r = run(so);
  int checked = 0;
  for (Eigen::Index i = 0; i < r.time_s.size(); ++i) {
    if (std::abs(r.time_s[i] - 1.5) > 0.15) continue;  // the middle of the flight
    EXPECT_FALSE(r.feet[0].contact[static_cast<std::size_t>(i)]) << r.time_s[i];
    EXPECT_DOUBLE_EQ(r.feet[1].force_N(i, 1), 0.0);
    ++checked;
  }
  EXPECT_GT(checked, 20);
  // Standing before the flight carries the body weight.
  EXPECT_NEAR(r.feet[0].force_N(30, 1) + r.feet[1].force_N(30, 1), 70 * 9.81, 0.01 * 70 * 9.81);
}

TEST(Estimate, TrialWithNoStanceSaysSo) {
  Trial t = make_synthetic_trial({});
  for (auto& p : t.markers.positions_m) p.col(2).array() += 0.5;  // the whole body 50 cm up
  EstimateOptions eo;
  eo.ground_level_m = 0.0;  // the lab floor
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
  EXPECT_EQ(r.feet[0].force_N.cwiseAbs().maxCoeff() + r.feet[1].force_N.cwiseAbs().maxCoeff(), 0.0);
  bool said = false;
  for (const auto& m : r.messages) said = said || m.find("no stance") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(Estimate, NoBodyMassIsAClearError) {
  Trial t = make_synthetic_trial({});
  t.body_mass_kg.reset();
  t.path = "nomass.c3d";
  try {
    (void)estimate(t, nullptr, *find_marker_set("kin2grf-example"), {});
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("no body mass"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nomass.c3d"), std::string::npos) << e.what();
  }
  // A file's implausible mass (0.5 kg) is refused, not used; allowed when asked for.
  t.body_mass_kg = 0.5;
  EXPECT_THROW((void)estimate(t, nullptr, *find_marker_set("kin2grf-example"), {}), InputError);
  EstimateOptions unusual;
  unusual.allow_unusual_mass = true;
  EXPECT_NO_THROW((void)estimate(t, nullptr, *find_marker_set("kin2grf-example"), unusual));
}

TEST(Estimate, MissingMarkerIsNamed) {
  Trial t = make_synthetic_trial({});
  t.markers.names[3] = "XXXX";  // RAJC renamed
  try {
    (void)estimate(t, nullptr, *find_marker_set("kin2grf-example"), {});
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("RAJC"), std::string::npos) << e.what();
  }
}

TEST(SharedEstimate, WalkingTrialsFindTheirStancePhases) {
  KIN2GRF_REQUIRE_DATA();
  const Trial t = load_trial(test::data_file("rajagopal2016_overground_walk/markers_walk.trc"));
  EstimateOptions eo;
  eo.mass_kg = 77.3;
  eo.solver.norm = MultiplierNorm::TorqueScaled;
  const auto r = estimate(t, nullptr, *recognise_marker_set(t.markers), eo);
  // Plates: right stance 0.268-1.023 s, left 0.837-1.589 s. Mid-stance must be in contact,
  // mid-swing must not.
  auto at = [&](double time) { return static_cast<std::size_t>(std::lround((time - r.time_s[0]) * 100)); };
  EXPECT_TRUE(r.feet[0].contact[at(0.6)]);
  EXPECT_TRUE(r.feet[1].contact[at(1.2)]);
  EXPECT_FALSE(r.feet[0].contact[at(1.2)]);
  EXPECT_FALSE(r.feet[1].contact[at(0.5)]);
  // Peak vertical force of a walking stance: 1.0-1.4 body weights.
  const double peak = r.feet[0].force_N.col(1).maxCoeff() / (77.3 * 9.81);
  EXPECT_GT(peak, 0.95);
  EXPECT_LT(peak, 1.5);
}

// Single support with an exactly known contact force: a frame of the model on one foot whose
// accelerations come from the constrained forward dynamics with a chosen set of joint-angle
// accelerations. The stance foot's D* is held (no acceleration); its multipliers are the exact
// inverse-dynamics contact force, and the solver (one contact, full column rank) must return
// them to round-off, with the lifted foot inactive.
TEST(Estimate, PrescribedSingleSupportRecoversTheExactContactForce) {
  SyntheticOptions so;
  so.left_leg_raised_rad = 0.6;
  const Trial t = make_synthetic_trial(so);
  EstimateOptions eo;
  eo.solver.speed_gate_mps = 0.0;
  eo.solver.speed_gate_ratio = 0.0;
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
  // All the load on the right foot, none on the lifted left one.
  for (Eigen::Index i = 10; i < r.time_s.size() - 10; i += 7) {
    EXPECT_FALSE(r.feet[1].contact[static_cast<std::size_t>(i)]) << "frame " << i;
    EXPECT_TRUE(r.feet[0].contact[static_cast<std::size_t>(i)]) << "frame " << i;
    // sum m (a + g) within 2 % of body weight: the squat's moment balance is not exactly that of
    // a COP at D, and the least squares of Eq. 7 spreads that inconsistency over all three
    // global equations (the exact case is the frame below).
    EXPECT_NEAR(r.feet[0].raw_force_N(i, 1), r.kinematic_total(i, 1), 0.02 * 70 * 9.81) << "frame " << i;
  }

  // One frame, forward dynamics: [M -A^T; A 0] [qdd; mu] = [f; c].
  ModelMotion mm = compute_motion(r.model, synthetic_landmarks(t), 6.0);
  auto contacts = prepare_contacts(r.model, r.calibration.contact, ContactModelOptions{}, mm);
  const Eigen::Index i = 120;
  const FrameContacts& fc = contacts[static_cast<std::size_t>(i)];
  ASSERT_EQ(fc.points.size(), 2u);
  ASSERT_GT(fc.points[1].gap_m, 0.05) << "the left foot is lifted";
  const Eigen::VectorXd q = mm.q.row(i).transpose();
  SolverOptions sopt;
  sopt.r_N_per_m = 1e5;
  ContactSolver solver(r.model, r.calibration, sopt);  // no speed gate (eo's)
  const Eigen::MatrixXd Phi = solver.bilateral_jacobian(q);
  Eigen::MatrixXd A(kBilateralCount + 2, coord::kCount);
  A << Phi, fc.points[0].jac_normal.transpose(), fc.points[0].jac_tangent.transpose();
  Eigen::VectorXd c = Eigen::VectorXd::Zero(kBilateralCount + 2);
  const double phidd[kJointCount] = {0.8, -1.5, 2.0, 0.3, -0.4, 0.9, 0.0, -0.2};  // rad/s^2 (qd = 0)
  for (int j = 0; j < kJointCount; ++j) c[48 + j] = phidd[j];
  const Eigen::VectorXd Mdiag = r.model.mass_diagonal();
  const int n = coord::kCount, m = kBilateralCount + 2;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = Mdiag.asDiagonal();
  K.topRightCorner(n, m) = -A.transpose();
  K.bottomLeftCorner(m, n) = A;
  Eigen::VectorXd rhs(n + m);
  rhs << r.model.gravity_force(), c;
  const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
  ASSERT_LT((K * sol - rhs).norm(), 1e-8);
  const Eigen::VectorXd qdd = sol.head(n);
  const double lambda_n = sol[n + kBilateralCount], lambda_t = sol[n + kBilateralCount + 1];
  ASSERT_GT(lambda_n, 100.0) << "a compressive contact force";
  const FrameSolution s = solver.solve(q, qdd, fc);
  EXPECT_TRUE(s.active[0]);
  EXPECT_FALSE(s.active[1]);
  EXPECT_NEAR(s.force_N[0].y(), lambda_n, 1e-6 * lambda_n);
  EXPECT_NEAR(s.force_N[0].x(), lambda_t, 1e-6 * lambda_n);
  EXPECT_DOUBLE_EQ(s.force_N[1].y(), 0.0);
}

// The structured factorisation (normal equations, compiled L D L^T) and a dense rank-revealing one give the same
// multipliers on every frame of a squat (double support) and a single-support trial.
TEST(Solver, StructuredAndDenseFactorisationsAgree) {
  for (double raised : {0.0, 0.6}) {
    SyntheticOptions so;
    so.left_leg_raised_rad = raised;
    const Trial t = make_synthetic_trial(so);
    const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), {});
    ModelMotion mm = compute_motion(r.model, synthetic_landmarks(t), 6.0);
    const auto contacts = prepare_contacts(r.model, r.calibration.contact, ContactModelOptions{}, mm);
    SolverOptions structured_opt, dense_opt;
    dense_opt.dense_factorisation = true;
    ContactSolver structured(r.model, r.calibration, structured_opt), dense(r.model, r.calibration, dense_opt);
    for (Eigen::Index i = 0; i < mm.frames(); i += 11) {
      const Eigen::VectorXd q = mm.q.row(i).transpose(), qdd = mm.qdd.row(i).transpose();
      const auto a = structured.solve(q, qdd, contacts[static_cast<std::size_t>(i)]);
      const auto b = dense.solve(q, qdd, contacts[static_cast<std::size_t>(i)]);
      ASSERT_EQ(a.contact_active, b.contact_active) << "frame " << i;
      EXPECT_LT((a.contact_lambda - b.contact_lambda).cwiseAbs().maxCoeff(), 1e-6) << "frame " << i;
      EXPECT_LT((a.joint_torque_Nm - b.joint_torque_Nm).cwiseAbs().maxCoeff(), 1e-6) << "frame " << i;
    }
  }
}

// A torso without trunk markers (pelvis_up) sways fore-aft by sway_gain times the hip centre's
// oscillation about its slow trend: 1 is rigid with the hip, 0 holds the shoulder on the trend.
TEST(Landmarks, UprightTorsoSwaysByItsGain) {
  SyntheticOptions so;
  so.squat_depth = 0.0;  // quiet standing, plus a 2 Hz, 2 cm fore-aft sway of the whole body
  Trial t = make_synthetic_trial(so);
  const Eigen::Index n = t.markers.frames();
  const Eigen::ArrayXd sway = 0.02 * (2.0 * M_PI * 2.0 * t.markers.time_s.array()).sin();
  for (auto& p : t.markers.positions_m) p.col(0).array() += sway;
  // Pelvis markers about the hip-centre midpoint (lab: X forward, Y left, Z up).
  const Eigen::MatrixX3d hip = 0.5 * (t.markers.positions_m[static_cast<std::size_t>(t.markers.find("RHJC"))] +
                                      t.markers.positions_m[static_cast<std::size_t>(t.markers.find("LHJC"))]);
  const std::pair<const char*, Eigen::RowVector3d> pelvis[] = {{"RASI", {0.06, -0.12, 0.08}}, {"LASI", {0.06, 0.12, 0.08}},
                                                               {"RPSI", {-0.10, -0.05, 0.10}}, {"LPSI", {-0.10, 0.05, 0.10}}};
  for (const auto& [name, offset] : pelvis) {
    t.markers.names.emplace_back(name);
    t.markers.descriptions.emplace_back();
    t.markers.positions_m.push_back(hip.rowwise() + offset);
  }
  auto shoulder_x = [&](double gain) {
    nlohmann::json j = read_json_file(std::string(KIN2GRF_SOURCE_DIR) + "/data/presets/kin2grf-example.json");
    j["landmarks"]["shoulder"] = {{"pelvis_up", 0.5}, {"sway_gain", gain},
                                  {"pelvis", {{"rasis", "RASI"}, {"lasis", "LASI"}, {"rpsis", "RPSI"}, {"lpsis", "LPSI"}}}};
    const MarkerSet set = parse_marker_set(j, "test");
    const auto e = estimate(t, nullptr, set, {});
    return Eigen::VectorXd(e.landmarks.p[kShoulder].col(0));
  };
  const Eigen::VectorXd rigid = shoulder_x(1.0), half = shoulder_x(0.5), still = shoulder_x(0.0);
  ASSERT_EQ(rigid.size(), n);
  // Away from the ends (the trend filter's edges): the rigid torso carries the whole sway, the
  // half-gain torso half of it, the zero-gain torso none.
  double worst_half = 0, worst_still = 0;
  for (Eigen::Index i = n / 5; i < n - n / 5; ++i) {
    worst_half = std::max(worst_half, std::abs((rigid[i] - half[i]) - 0.5 * sway[i]));
    worst_still = std::max(worst_still, std::abs((rigid[i] - still[i]) - sway[i]));
  }
  EXPECT_LT(worst_half, 1e-3);
  EXPECT_LT(worst_still, 2e-3);
  // A gain outside 0-1.5 is refused, naming the landmark.
  nlohmann::json bad = read_json_file(std::string(KIN2GRF_SOURCE_DIR) + "/data/presets/kin2grf-example.json");
  bad["landmarks"]["shoulder"] = {{"pelvis_up", 0.5}, {"sway_gain", 3.0}, {"pelvis", {{"rasis", "RASI"}, {"lasis", "LASI"}, {"rpsis", "RPSI"}, {"lpsis", "LPSI"}}}};
  try {
    (void)parse_marker_set(bad, "bad.json");
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sway_gain"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("shoulder"), std::string::npos) << e.what();
  }
}

// Feet side by side (a staggered squat, 3 cm apart): the sagittal moment equation cannot split
// the load, and fitting it anyway alternates the load between the feet. With kin2grf's
// side-by-side rule both feet share it; without it (the paper) one foot takes nearly all.
TEST(Estimate, FeetSideBySideShareTheLoad) {
  Trial t = make_synthetic_trial({});
  for (std::size_t k = 0; k < t.markers.names.size(); ++k)
    if (t.markers.names[k][0] == 'L' && t.markers.names[k] != "LHJC" && t.markers.names[k] != "LSHO")
      t.markers.positions_m[k].col(0).array() += 0.03;
  auto worst_share = [&](double split_m) {
    EstimateOptions eo;
    eo.solver.min_split_distance_m = split_m;
    const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
    double worst = 0.5;
    for (Eigen::Index i = 10; i < r.time_s.size() - 10; ++i) {
      const double fr = r.feet[0].raw_force_N(i, 1), fl = r.feet[1].raw_force_N(i, 1);
      if (fr + fl < 100) continue;
      worst = std::max(worst, std::max(fr, fl) / (fr + fl));
    }
    return worst;
  };
  EXPECT_LT(worst_share(SolverOptions{}.min_split_distance_m), 0.65);
  EXPECT_GT(worst_share(0.0), 0.9);
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
  const ModelMotion measured = compute_motion(r.model, lm, 6.0, TorsoLength::Measured);
  const ModelMotion fixed = compute_motion(r.model, lm, 6.0, TorsoLength::Fixed);
  const double dt = 1.0 / lm.rate_hz, L0 = r.model.bodies[kTorso].length_m;
  auto point = [](const Eigen::MatrixXd& q, int col, Eigen::Index i) {
    return Eigen::Vector2d(q(i, col), q(i, col + 1));
  };
  double worst_len = 0, worst_acc = 0, fixed_spread = 0, acc_scale = 0;
  const int sh = coord::point_x(kShoulder), hip = coord::point_x(kHip), com = coord::com_x(kTorso);
  for (Eigen::Index i = 20; i < measured.frames() - 20; ++i) {
    const double len = (point(measured.q, sh, i) - point(measured.q, hip, i)).norm();
    const double truth = (lm.p[kShoulder].row(i) - lm.p[kHip].row(i)).norm();
    worst_len = std::max(worst_len, std::abs(len - truth));
    fixed_spread = std::max(fixed_spread, std::abs((point(fixed.q, sh, i) - point(fixed.q, hip, i)).norm() - L0));
    // Second central difference of the torso COM position against its reconstructed acceleration.
    const Eigen::Vector2d fd = (point(measured.q, com, i + 1) - 2 * point(measured.q, com, i) +
                                point(measured.q, com, i - 1)) / (dt * dt);
    const Eigen::Vector2d a(measured.qdd(i, com), measured.qdd(i, com + 1));
    worst_acc = std::max(worst_acc, (fd - a).norm());
    acc_scale = std::max(acc_scale, a.norm());
  }
  EXPECT_LT(worst_len, 2e-3);           // follows the measured length (6 Hz filtered, 1.5 Hz bob)
  EXPECT_LT(fixed_spread, 1e-12);       // the paper's rigid torso does not
  EXPECT_LT(worst_acc, 0.02 * acc_scale);  // the scaled kinematics are differentiated consistently
  EXPECT_GT(acc_scale, 0.5);
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
  ModelMotion mm = compute_motion(r.model, synthetic_landmarks(t), 6.0);
  auto contacts = prepare_contacts(r.model, r.calibration.contact, ContactModelOptions{}, mm);
  const Eigen::Index i = 120;
  FrameContacts fc = contacts[static_cast<std::size_t>(i)];
  ASSERT_EQ(fc.points.size(), 2u);
  fc.points[0].velocity.setZero();                 // the stance foot's D* is still
  fc.points[1].gap_m = 0.008;                      // low swing clearance
  fc.points[1].velocity = Eigen::Vector2d(1.0, 0);  // a slow walker's swing foot
  const Eigen::VectorXd q = mm.q.row(i).transpose();
  Eigen::VectorXd qdd = mm.qdd.row(i).transpose();
  qdd[coord::theta(kTorso)] += 20.0;  // rad/s^2: about 30 N m that no single contact point balances

  TrialCalibration fixed = r.calibration;  // the old fixed gate
  fixed.speed_gate_mps = 1.5;
  const FrameSolution before = ContactSolver(r.model, fixed, SolverOptions{}).solve(q, qdd, fc);
  ASSERT_TRUE(before.active[1]) << "the failure this test guards: the fixed gate lets the swing foot in";
  ASSERT_GT(before.force_N[1].y(), 20.0);

  TrialCalibration rule = r.calibration;  // the defaults: the progression speed, at least 0.75 m/s
  rule.speed_gate_mps = speed_gate_for(SolverOptions{}, 0.4);
  EXPECT_NEAR(rule.speed_gate_mps, 0.75, 1e-12);
  const FrameSolution after = ContactSolver(r.model, rule, SolverOptions{}).solve(q, qdd, fc);
  EXPECT_FALSE(after.active[1]);
  EXPECT_EQ(after.force_N[1].y(), 0.0);
  EXPECT_EQ(after.force_N[1].x(), 0.0);
  EXPECT_TRUE(after.active[0]);
  EXPECT_GT(after.force_N[0].y(), 0.8 * 70 * 9.81);
}

TEST(Solver, SpeedGateScalesWithTheProgressionSpeed) {
  SolverOptions o;  // defaults
  EXPECT_NEAR(speed_gate_for(o, 0.0), 0.75, 1e-12);   // standing, squatting: the floor
  EXPECT_NEAR(speed_gate_for(o, 0.4), 0.75, 1e-12);   // a slow walk: the floor
  EXPECT_NEAR(speed_gate_for(o, 1.3), 1.3, 1e-12);    // walking
  EXPECT_NEAR(speed_gate_for(o, 9.0), 9.0, 1e-12);    // sprinting: the landing foot is not cut
  EXPECT_NEAR(speed_gate_for(o, -3.5), 3.5, 1e-12);   // a treadmill belt's sign does not matter
  o.speed_gate_ratio = 0;
  o.speed_gate_mps = 1.5;
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

// Running frames are told from the kinematics: near a flight the whole body's vertical force
// sum m (a_y + g) falls to about zero (free fall); standing, squatting and walking never do.
TEST(Contact, FlightFramesAreFoundFromTheKinematicsAlone) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;  // flight 1.253-1.747 s
  const Trial t = make_synthetic_trial(so);
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  ModelMotion mm = compute_motion(r.model, synthetic_landmarks(t), 6.0);
  const auto run = flight_frames(r.model, mm);
  ASSERT_EQ(run.size(), static_cast<std::size_t>(mm.frames()));
  for (Eigen::Index i = 0; i < mm.frames(); ++i) {
    const double time = mm.time_s[i];
    if (time > 1.3 && time < 1.7) {
      EXPECT_TRUE(run[static_cast<std::size_t>(i)]) << time;  // in the flight
    } else if (time < 0.7 || time > 2.3) {
      EXPECT_FALSE(run[static_cast<std::size_t>(i)]) << time;  // far from it
    }
  }
  for (const double depth : {0.0, 1.0}) {  // quiet standing and squats: never
    SyntheticOptions sq;
    sq.squat_depth = depth;
    const Trial ts = make_synthetic_trial(sq);
    const auto rs = estimate(ts, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
    ModelMotion ms = compute_motion(rs.model, synthetic_landmarks(ts), 6.0);
    const auto none = flight_frames(rs.model, ms);
    EXPECT_EQ(std::count(none.begin(), none.end(), true), 0) << depth;
  }
}

// A turning walk: Rajagopal's straight walk bent onto a circle of 2.5 m radius (about 70 degrees
// of turn over its 3 m), each frame's markers carried with the pelvis's place on the path (the
// distance walked kept as arc length, the lateral offsets across the path). The frame must follow
// the heading, and the forces must be those of the straight walk.
TEST(SharedEstimate, TurningWalkGivesTheStraightWalksForces) {
  KIN2GRF_REQUIRE_DATA();
  const Trial straight = load_trial(test::data_file("rajagopal2016_overground_walk/markers_walk.trc"));
  EstimateOptions eo;
  eo.mass_kg = 85.27;
  const MarkerSet& set = *recognise_marker_set(straight.markers);
  const auto a = estimate(straight, nullptr, set, eo);
  ASSERT_FALSE(a.frame.turning());
  // Lab: Y up, walking along +X (pelvis at z ~ 0). Bend: arc length s = x, circle centre (0, R)
  // in the X-Z plane, turning toward +Z.
  const double R = 2.5;
  Trial curved = straight;
  const int hip_ref = straight.markers.find("R.ASIS");
  ASSERT_GE(hip_ref, 0);
  for (Eigen::Index i = 0; i < straight.markers.frames(); ++i) {
    // The body's place along the path this frame: the pelvis's x (a smooth 1 Hz trend would do
    // as well; the frame's own value keeps the test simple and exact).
    const double s = 0.5 * (straight.markers.positions_m[static_cast<std::size_t>(hip_ref)](i, 0) +
                            straight.markers.positions_m[static_cast<std::size_t>(straight.markers.find("L.ASIS"))](i, 0));
    if (!std::isfinite(s)) continue;
    const double psi = s / R;
    const Eigen::Vector3d C(R * std::sin(psi), 0, R - R * std::cos(psi)), T(std::cos(psi), 0, std::sin(psi)),
        N(-std::sin(psi), 0, std::cos(psi));
    for (std::size_t k = 0; k < straight.markers.positions_m.size(); ++k) {
      const Eigen::RowVector3d p = straight.markers.positions_m[k].row(i);
      const Eigen::Vector3d q = C + (p(0) - s) * T + p(2) * N + Eigen::Vector3d(0, p(1), 0);
      curved.markers.positions_m[k].row(i) = q.transpose();
    }
  }
  const auto b = estimate(curved, nullptr, set, eo);
  ASSERT_TRUE(b.frame.turning()) << b.frame.how;
  ASSERT_EQ(a.time_s.size(), b.time_s.size());
  const double bw = 85.27 * 9.81;
  // Without following the heading (one fixed direction), the same walk goes wrong.
  EstimateOptions fixed = eo;
  fixed.landmarks.progression_axis = Axis::X;
  const auto c = estimate(curved, nullptr, set, fixed);
  auto rms = [](const Eigen::VectorXd& x, const Eigen::VectorXd& y) { return std::sqrt((x - y).array().square().mean()); };
  for (int side = 0; side < 2; ++side) {
    const auto& fa = a.feet[side].force_N;
    const auto& fb = b.feet[side].force_N;
    const auto& fc = c.feet[side].force_N;
    // Measured: turning 21-22 N vertical, 6-8 N anterior; fixed frame 36-40 N and 20-28 N.
    EXPECT_LT(rms(fa.col(1), fb.col(1)), 0.03 * bw) << "vertical, side " << side;
    EXPECT_LT(rms(fa.col(0), fb.col(0)), 0.015 * bw) << "anterior, side " << side;
    EXPECT_GT(rms(fa.col(0), fc.col(0)), 2 * rms(fa.col(0), fb.col(0))) << "the fixed frame must do worse, side " << side;
    EXPECT_GT(rms(fa.col(1), fc.col(1)), rms(fa.col(1), fb.col(1))) << "side " << side;
  }
}

// SCoRE on a synthetic knee: a thigh swinging about a moving hip and a shank flexing about a
// known knee axis (lateral, Y), clusters 6-9 cm off the bones. The functional centre must lie
// on the axis: its sagittal (X, Z) place within 1 mm of the true knee, whatever its place along
// the axis (a hinge does not tell it; the limb's midline is taken).
TEST(Landmarks, FunctionalKneeCentreOfAHingeIsOnItsAxis) {
  MarkerTrajectories m;
  const int n = 300;
  m.rate_hz = 100;
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0, (n - 1) / 100.0);
  m.up_axis = Axis::Z;
  const char* names[] = {"TH1", "TH2", "TH3", "TB1", "TB2", "TB3"};
  for (const char* nm : names) {
    m.names.emplace_back(nm);
    m.positions_m.emplace_back(n, 3);
  }
  const Eigen::Vector3d th_local[] = {{0.05, 0.08, 0.15}, {-0.04, 0.07, 0.22}, {0.02, 0.09, 0.30}};    // from the knee, thigh frame
  const Eigen::Vector3d tb_local[] = {{0.04, 0.07, -0.12}, {-0.03, 0.08, -0.20}, {0.03, 0.06, -0.27}};  // from the knee, shank frame
  Eigen::MatrixX3d knee(n, 3);
  auto rot_y = [](double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); };
  for (int i = 0; i < n; ++i) {
    const double t = m.time_s[i];
    const Eigen::Vector3d hip(0.8 * t, 0.0, 0.9 + 0.02 * std::sin(2 * M_PI * 1.8 * t));
    const Eigen::Matrix3d Rt = rot_y(0.4 * std::sin(2 * M_PI * 0.9 * t));           // thigh swing
    const Eigen::Matrix3d Rs = Rt * rot_y(-0.6 * (1 - std::cos(2 * M_PI * 0.9 * t)));  // knee flexion 0-69 deg
    const Eigen::Vector3d k = hip + Rt * Eigen::Vector3d(0, 0, -0.44);
    knee.row(i) = k.transpose();
    for (int j = 0; j < 3; ++j) {
      m.positions_m[static_cast<std::size_t>(j)].row(i) = (k + Rt * th_local[j]).transpose();
      m.positions_m[static_cast<std::size_t>(3 + j)].row(i) = (k + Rs * tb_local[j]).transpose();
    }
  }
  std::string msg;
  nlohmann::json rule = {{"functional", {{"proximal", {"TH1", "TH2", "TH3"}}, {"distal", {"TB1", "TB2", "TB3"}}}}};
  nlohmann::json j = {{"name", "t"}, {"landmarks", nlohmann::json::object()}};
  for (const char* id : {"shoulder", "hip", "knee_r", "ankle_r", "heel_r", "mt_r", "hallux_r", "knee_l", "ankle_l", "heel_l",
                         "mt_l", "hallux_l"})
    j["landmarks"][id] = std::string(id) == "knee_r" ? rule : nlohmann::json{{"marker", "TH1"}};
  const MarkerSet set = parse_marker_set(j, "test");
  const Landmarks3D lm = compute_landmarks(set, m, nullptr, {}, "synthetic");
  const auto& K = lm.p[landmark(kRight, kKnee)];
  for (int i = 0; i < n; i += 10) {
    EXPECT_NEAR(K(i, 0), knee(i, 0), 1e-3) << i;
    EXPECT_NEAR(K(i, 2), knee(i, 2), 1e-3) << i;
    EXPECT_LT(std::abs(K(i, 1) - knee(i, 1)), 0.15) << "on the limb, not far along the axis";
  }
  bool said = false;
  for (const auto& s : lm.messages) said = said || s.find("SCoRE") != std::string::npos;
  EXPECT_TRUE(said);
}

// One sample of one marker 1 m, 10 m or 1e300 m off (issue 10: a 453 N or 12,036 N spike, or NaN
// in the output): it is a gap, filled like any other, the forces are those of the clean trial,
// and a message names the marker and frame.
TEST(Estimate, AMarkerSampleNoBodyCanProduceIsAGap) {
  const Trial clean = make_synthetic_trial({});
  const auto a = estimate(clean, nullptr, *find_marker_set("kin2grf-example"), {});
  for (const double off : {1.0, 10.0, 1e300}) {
    Trial t = clean;
    const int k = t.markers.find("RHEE");
    ASSERT_GE(k, 0);
    t.markers.positions_m[static_cast<std::size_t>(k)](150, 2) += off;
    const auto b = estimate(t, nullptr, *find_marker_set("kin2grf-example"), {});
    ASSERT_EQ(a.time_s.size(), b.time_s.size());
    for (int side = 0; side < 2; ++side) {
      EXPECT_TRUE(b.feet[side].force_N.allFinite());
      EXPECT_LT((a.feet[side].force_N - b.feet[side].force_N).cwiseAbs().maxCoeff(), 0.01 * 70 * 9.81) << off;
    }
    bool said = false;
    for (const auto& m : b.messages) said = said || (m.find("RHEE") != std::string::npos && m.find("no body can") != std::string::npos);
    EXPECT_TRUE(said) << off;
  }
}

// A full Plug-in Gait file whose LSHO/RSHO labels exist but hold no sample (issue 10): the
// lower-body preset, which can run it, is chosen, and the reason lists both candidates.
TEST(Landmarks, PresetRecognitionLooksAtWhichMarkersHoldData) {
  MarkerTrajectories m;
  m.rate_hz = 100;
  m.time_s = Eigen::VectorXd::LinSpaced(50, 0, 0.49);
  std::vector<std::string> used;
  for (const char* set : {"plug-in-gait", "plug-in-gait-lower"}) {
    const auto u = find_marker_set(set)->motion_markers();
    used.insert(used.end(), u.begin(), u.end());
    used.insert(used.end(), find_marker_set(set)->signature.begin(), find_marker_set(set)->signature.end());
  }
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  for (const auto& name : used) {
    m.names.push_back(name);
    m.descriptions.emplace_back();
    const bool empty = name == "LSHO" || name == "RSHO";
    m.positions_m.push_back(Eigen::MatrixX3d::Constant(50, 3, empty ? std::nan("") : 0.5));
  }
  std::string why;
  const MarkerSet* s = recognise_marker_set(m, &why);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->name, "plug-in-gait-lower") << why;
  EXPECT_NE(why.find("plug-in-gait 0 frames"), std::string::npos) << why;
  // With the shoulders holding data, the full set (more markers) is taken.
  for (std::size_t k = 0; k < m.names.size(); ++k) m.positions_m[k].setConstant(0.5);
  EXPECT_EQ(recognise_marker_set(m)->name, "plug-in-gait");
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
  const kin2grf::EstimateResult rule = kin2grf::estimate(noisy, nullptr, *set, {});
  kin2grf::EstimateOptions fixed_options;
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
