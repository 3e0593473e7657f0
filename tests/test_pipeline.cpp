// Tests of pipeline: estimate() on synthetic and shared trials.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/dynamics/mediolateral.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/json.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

using kin2grf::test::run;
using kin2grf::test::said;
using kin2grf::test::synthetic_landmarks;

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

// The ground shift (the paper's robustness study) is one floor for every stage: the contacts'
// gaps, the calibration the result reports, and the COP's height in the lab frame.
TEST(Estimate, AGroundShiftIsTheFloorOfEveryStage) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  EstimateOptions shifted;
  shifted.contact.ground_shift_m = -0.005;
  const auto r0 = run(so), rs = run(so, shifted);
  EXPECT_NEAR(rs.ground_level_m(), r0.ground_level_m() - 0.005, 1e-12);
  const Eigen::Index i = r0.time_s.size() / 2;
  ASSERT_TRUE(r0.feet[0].contact[static_cast<std::size_t>(i)] && rs.feet[0].contact[static_cast<std::size_t>(i)]);
  const double h0 = r0.frame.up.dot(lab_foot_frame(r0, 0, i).cop_m), hs = rs.frame.up.dot(lab_foot_frame(rs, 0, i).cop_m);
  EXPECT_NEAR(hs - h0, -0.005, 1e-9);
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

// A capture that ends in flight (a run leaving a short capture volume, a jump): the synthetic
// jump cut 0.25 s into its 0.49 s flight. The body falls freely there, so the kinematic total
// sum m (a + g) is 0 N. The kinematics' filter extended past the window's end by the end's own
// curvature (--kinematic-edges curvature, the default) keeps that; the odd reflection reads the
// end's acceleration as zero, the body weight. The stance before the flight is the same either way.
TEST(Estimate, ACaptureThatEndsInFlightEndsInFreeFall) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;  // flight 1.253-1.747 s
  Trial t = make_synthetic_trial(so);
  t.markers = cropped(t.markers, 0, 150);  // to 1.49 s
  const double bw = 70 * 9.81;
  const auto with = [&](FilterEdge e) {
    EstimateOptions eo;
    eo.kinematic_edges = e;
    return estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
  };
  EXPECT_EQ(EstimateOptions{}.kinematic_edges, FilterEdge::Curvature);
  const auto curved = with(FilterEdge::Curvature), odd = with(FilterEdge::OddReflection);
  const Eigen::Index last = curved.time_s.size() - 1;
  ASSERT_EQ(last, 149);
  EXPECT_LT(std::abs(curved.kinematic_total(last, 1)), 0.05 * bw) << curved.kinematic_total(last, 1);
  EXPECT_GT(odd.kinematic_total(last, 1), 0.5 * bw) << odd.kinematic_total(last, 1);
  // Standing, well before the take-off: body weight either way.
  EXPECT_NEAR(curved.feet[0].force_N(30, 1) + curved.feet[1].force_N(30, 1), bw, 0.01 * bw);
  EXPECT_NEAR(odd.feet[0].force_N(30, 1) + odd.feet[1].force_N(30, 1), bw, 0.01 * bw);
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
  eo.contact.speed_gate.fixed_mps = 0.0;
  eo.contact.speed_gate.ratio = 0.0;
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
  const ModelMotion mm = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
  const auto tc = test::contact_frames(r.model(), r.calibration.contact, ContactModelOptions{}, mm);
  const std::size_t i = 120;
  const FrameContacts& fc = tc.contacts[i];
  ASSERT_EQ(fc.points.size(), 2u);
  ASSERT_GT(fc.points[1].gap_m, 0.05) << "the left foot is lifted";
  const Eigen::VectorXd q = tc.frames[i].q;
  SolverOptions sopt;
  sopt.r_N_per_m = 1e5;
  ContactSolver solver(r.model(), r.calibration, sopt);  // no speed gate (eo's)
  const Eigen::MatrixXd Phi = solver.bilateral_jacobian(q);
  Eigen::MatrixXd A(kBilateralCount + 2, coord::kCount);
  A << Phi, fc.points[0].jac_normal.dense().transpose(), fc.points[0].jac_tangent.dense().transpose();
  Eigen::VectorXd c = Eigen::VectorXd::Zero(kBilateralCount + 2);
  const double phidd[kJointCount] = {0.8, -1.5, 2.0, 0.3, -0.4, 0.9, 0.0, -0.2};  // rad/s^2 (qd = 0)
  for (int j = 0; j < kJointCount; ++j) c[48 + j] = phidd[j];
  const Eigen::VectorXd Mdiag = r.model().mass_diagonal();
  const int n = coord::kCount, m = kBilateralCount + 2;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = Mdiag.asDiagonal();
  K.topRightCorner(n, m) = -A.transpose();
  K.bottomLeftCorner(m, n) = A;
  Eigen::VectorXd rhs(n + m);
  rhs << r.model().gravity_force(), c;
  const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);
  ASSERT_LT((K * sol - rhs).norm(), 1e-8);
  const Eigen::VectorXd qdd = sol.head(n);
  const double lambda_n = sol[n + kBilateralCount], lambda_t = sol[n + kBilateralCount + 1];
  ASSERT_GT(lambda_n, 100.0) << "a compressive contact force";
  const FrameSolution s = solver.solve(q, qdd, fc);
  EXPECT_TRUE(test::foot_active(s, fc, 0));
  EXPECT_FALSE(test::foot_active(s, fc, 1));
  EXPECT_NEAR(test::foot_force(s, fc, 0).y(), lambda_n, 1e-6 * lambda_n);
  EXPECT_NEAR(test::foot_force(s, fc, 0).x(), lambda_t, 1e-6 * lambda_n);
  EXPECT_DOUBLE_EQ(test::foot_force(s, fc, 1).y(), 0.0);
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

namespace {
/// `leaving` is `walk` with what is seen from frame `cut` on changed, and the processed window
/// ends there: its forces must be those of `walk` cut at `cut`, to round-off. Returns its estimate.
EstimateResult expect_the_cut_walks_forces(const Trial& walk, const Trial& leaving, Eigen::Index cut) {
  Trial cut_walk = walk;
  cut_walk.markers = cropped(walk.markers, 0, cut);
  cut_walk.plates.reset();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  const auto a = estimate(cut_walk, nullptr, set, {});
  auto b = estimate(leaving, nullptr, set, {});
  EXPECT_EQ(a.time_s.size(), b.time_s.size());
  if (a.time_s.size() == b.time_s.size()) {
    for (int side = 0; side < 2; ++side) {
      EXPECT_LT((a.feet[side].force_N - b.feet[side].force_N).cwiseAbs().maxCoeff(), 1e-6) << "side " << side;
    }
  }
  return b;
}
}  // namespace

// A straight walk whose subject leaves the capture volume: from frame 300 on, the pelvis, the legs
// and the right foot are lost, and the left foot, still seen, turns 90 degrees away (a walker
// turning round out of view, or a foot's markers come and go). The processed window is frames
// 0-299. The heading is measured over the span where the body is seen: no turn, and the forces
// are those of the same walk cut at frame 300. Measured over the whole trial instead, that one
// foot's direction, spread by the heading's 0.5 Hz trend, turned the frame within the window (two
// straight UWA overground runs: 50 degrees within their stance, vertical rRMSE 44 and 38 %).
TEST(Estimate, AFootSeenOutsideTheWindowDoesNotTurnTheFrame) {
  const Trial walk = make_example_walk();
  const Eigen::Index cut = 300;
  ASSERT_GT(walk.markers.frames(), cut + 100);
  Trial leaving = walk;
  for (std::size_t k = 0; k < leaving.markers.names.size(); ++k) {
    const std::string& name = leaving.markers.names[k];
    auto& P = leaving.markers.positions_m[k];
    if (name == "LHEE" || name == "LMT1" || name == "LHLX") continue;
    P.bottomRows(P.rows() - cut).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  const auto heel = static_cast<std::size_t>(leaving.markers.find("LHEE"));
  for (const char* name : {"LMT1", "LHLX"}) {
    auto& P = leaving.markers.positions_m[static_cast<std::size_t>(leaving.markers.find(name))];
    for (Eigen::Index i = cut; i < P.rows(); ++i) {
      const Eigen::RowVector3d d = P.row(i) - leaving.markers.positions_m[heel].row(i);
      P.row(i) = leaving.markers.positions_m[heel].row(i) + Eigen::RowVector3d(-d(1), d(0), d(2));  // 90 degrees left
    }
  }
  const auto b = expect_the_cut_walks_forces(walk, leaving, cut);
  EXPECT_FALSE(b.frame.turning()) << b.frame.how;
  EXPECT_EQ(b.first_index, 0);
}

// The same walk, its legs lost from frame 300 on while the pelvis and shoulders, still seen, turn
// 90 degrees to the left and walk on 1.7 m (a walker turning away from the plates, the feet behind
// the walkway's furniture). The progression is the pelvis's travel over the span where the body is
// seen (frames 0-299): from its first to its last frame in the file, the turn tilted the frame 25
// degrees, past the 10 degrees a heading is snapped to the lab axis within.
TEST(Estimate, APelvisSeenTurningAfterTheFeetAreLostDoesNotTiltTheFrame) {
  const Trial walk = make_example_walk();
  const Eigen::Index cut = 300;
  Trial leaving = walk;
  for (std::size_t k = 0; k < leaving.markers.names.size(); ++k) {
    const std::string& name = leaving.markers.names[k];
    auto& P = leaving.markers.positions_m[k];
    if (name == "RHJC" || name == "LHJC" || name == "RSHO" || name == "LSHO") {
      for (Eigen::Index i = cut; i < P.rows(); ++i) {
        const double ahead = P(i, 0) - P(cut, 0);  // walked on to the left: x held, y grows
        P(i, 0) = P(cut, 0);
        P(i, 1) += ahead;
      }
    } else {
      P.bottomRows(P.rows() - cut).setConstant(std::numeric_limits<double>::quiet_NaN());
    }
  }
  const auto b = expect_the_cut_walks_forces(walk, leaving, cut);
  EXPECT_FALSE(b.frame.turning()) << b.frame.how;
  EXPECT_NEAR(b.frame.forward.x(), 1.0, 1e-9) << b.frame.forward.transpose();
}

// A heel marker lost for 0.3 s in the middle of the example walk (hidden by the other foot over a
// plate): the gap, longer than the cubic fill's 10 frames, ended the processed window there and
// half the walk's stances with it. The walk's right foot carries a technical marker on its dorsum
// besides its ankle and MT markers, so three markers move rigidly with the heel: the gap is filled
// from them, the whole walk is processed, and the forces are the intact walk's. With --rigid-fill
// off, the window stops at the gap as before.
TEST(Estimate, AHeelLostForATenthOfAStrideIsFilledFromItsFoot) {
  Trial walk = make_example_walk();
  MarkerTrajectories& m = walk.markers;
  const auto at = [&](const char* name) -> Eigen::MatrixX3d& { return m.positions_m[static_cast<std::size_t>(m.find(name))]; };
  const Eigen::MatrixX3d ajc = at("RAJC"), mt = at("RMT1");
  Eigen::MatrixX3d dorsum(ajc.rows(), 3);
  for (Eigen::Index i = 0; i < ajc.rows(); ++i) {
    const Eigen::Vector3d along = (mt.row(i) - ajc.row(i)).transpose();
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY().cross(along).normalized();  // in the foot's sagittal plane
    dorsum.row(i) = (ajc.row(i).transpose() + 0.5 * along + 0.03 * up + Eigen::Vector3d(0, 0.02, 0)).transpose();
  }
  m.names.push_back("RFT1");
  m.descriptions.push_back("");
  m.positions_m.push_back(dorsum);
  Trial gapped = walk;
  const Eigen::Index first = m.frames() / 2, frames = 30;
  ASSERT_EQ(m.rate_hz, 100.0);
  gapped.markers.positions_m[static_cast<std::size_t>(m.find("RHEE"))].middleRows(first, frames).setConstant(
      std::numeric_limits<double>::quiet_NaN());
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  const EstimateResult intact = estimate(walk, nullptr, set, {});
  const EstimateResult filled = estimate(gapped, nullptr, set, {});
  ASSERT_EQ(filled.time_s.size(), intact.time_s.size());
  for (int side = 0; side < 2; ++side)
    EXPECT_LT((filled.feet[side].force_N - intact.feet[side].force_N).cwiseAbs().maxCoeff(), 1e-6) << "side " << side;
  const auto said = std::find_if(filled.messages.begin(), filled.messages.end(),
                                 [](const std::string& x) { return x.find("RHEE: filled a gap of 30 frames") != std::string::npos; });
  ASSERT_NE(said, filled.messages.end());
  for (const char* partner : {"RAJC", "RMT1", "RFT1"}) EXPECT_NE(said->find(partner), std::string::npos) << *said;
  EstimateOptions off;
  off.landmarks.rigid_fill = false;
  const EstimateResult cut = estimate(gapped, nullptr, set, off);
  EXPECT_LE(cut.time_s.size(), first + 1);
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

/// estimate() refuses each bad value of one setting with an InputError that names the setting.
template <class Set>
void expect_refused_naming(Set set, std::initializer_list<double> bad, const std::string& named) {
  for (const double v : bad) {
    EstimateOptions o;
    set(o, v);
    try {
      run({}, o);
      ADD_FAILURE() << "no error for " << named << " " << v;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  }
}

TEST(Estimate, ATorsoLagOutsideItsRangeIsRefusedNamingTheSetting) {
  expect_refused_naming([](EstimateOptions& o, double v) { o.torso_lag_s = v; }, {-0.01, 0.5, std::nan("")}, "torso lag");
}

namespace {
/// A foot's contact states over n frames: true on each [first, end) given.
std::vector<bool> runs(std::initializer_list<std::pair<int, int>> on, int n) {
  std::vector<bool> c(static_cast<std::size_t>(n), false);
  for (const auto& [a, b] : on)
    for (int i = a; i < b; ++i) c[static_cast<std::size_t>(i)] = true;
  return c;
}
}  // namespace

TEST(Pipeline, MedianStanceBridgesFlickersAndLeavesOutRunsCutByTheWindow) {
  // 100 Hz: a flicker of 2 frames (20 ms) is bridged, 3 frames are not; runs under 5 frames and
  // runs touching either end of the window do not count.
  // Right: 0-30 (cut by the start), 50-110 with a 2-frame flicker at 70: one stance of 0.60 s.
  // Left: 120-180 (0.60 s), 200-203 (too short), 250-300 (cut by the end).
  std::array<std::vector<bool>, 2> c{runs({{0, 30}, {50, 70}, {72, 110}}, 300), runs({{120, 180}, {200, 203}, {250, 300}}, 300)};
  auto s = median_stance_s(c, 100.0);
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(*s, 0.6);
  // A gap of 3 frames splits the right stance in two (0.20 and 0.37 s): median of 0.2, 0.37, 0.6.
  c[0] = runs({{0, 30}, {50, 70}, {73, 110}}, 300);
  s = median_stance_s(c, 100.0);
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(*s, 0.37);
  // Standing throughout, or only runs cut by the window: no stance to measure.
  EXPECT_FALSE(median_stance_s({std::vector<bool>(300, true), std::vector<bool>(300, true)}, 100.0));
  EXPECT_FALSE(median_stance_s({runs({{0, 100}}, 300), runs({{200, 300}}, 300)}, 100.0));
  EXPECT_FALSE(median_stance_s({std::vector<bool>{}, std::vector<bool>{}}, 100.0));
}

// A model torso (no trunk markers) sways fore-aft by the runner's measured share of the hip's
// oscillation (kTrunkSwayGainRunning) in a trial with flight phases, by the walker's elsewhere;
// a measured trunk is never touched. Here a jump whose whole body also oscillates fore-aft.
TEST(Estimate, AModelTorsoSwaysAsARunnersInATrialWithFlightPhases) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;
  Trial jump = make_synthetic_trial(so);
  for (auto& p : jump.markers.positions_m)
    for (Eigen::Index i = 0; i < p.rows(); ++i) p(i, 0) += 0.01 * std::sin(2 * std::numbers::pi * 2.5 * jump.markers.time_s[i]);
  const MarkerSet& measured = *find_marker_set("kin2grf-example");
  std::string why;
  const std::optional<MarkerSet> model_torso = without_trunk_markers(measured, why);
  ASSERT_TRUE(model_torso) << why;
  EstimateOptions runner;
  runner.keep_all_series = true;
  EstimateOptions walker = runner;
  walker.running_sway_gain = kTrunkSwayGain;  // the set's own: no change
  const EstimateResult r = estimate(jump, nullptr, *model_torso, runner), w = estimate(jump, nullptr, *model_torso, walker);
  const SagittalLandmarks& lm = r.landmarks;
  ASSERT_EQ(lm.frames(), w.landmarks.frames());
  const Eigen::VectorXd hx = lm.p[kHip].col(0);
  const Eigen::VectorXd oscillation = hx - butterworth_filtfilt(hx, lm.rate_hz, 0.5);
  EXPECT_GT(oscillation.cwiseAbs().maxCoeff(), 0.005);
  for (Eigen::Index i = 0; i < lm.frames(); ++i)
    EXPECT_NEAR(lm.p[kShoulder](i, 0) - w.landmarks.p[kShoulder](i, 0), (kTrunkSwayGainRunning - kTrunkSwayGain) * oscillation[i], 1e-9)
        << "frame " << i;
  double moved = 0;
  for (int f = 0; f < 2; ++f) moved = std::max(moved, (r.feet[f].force_N - w.feet[f].force_N).cwiseAbs().maxCoeff());
  EXPECT_GT(moved, 1.0);  // N: the heavy HAT's fore-aft inertia
  EXPECT_TRUE(said(r, "runner's"));
  EXPECT_FALSE(said(w, "runner's"));
  // A measured trunk, and a walk (no flight phase), are not touched: the same forces bit for bit.
  const auto same = [&](const Trial& t, const MarkerSet& set) {
    const EstimateResult a = estimate(t, nullptr, set, runner), b = estimate(t, nullptr, set, walker);
    EXPECT_FALSE(said(a, "runner's"));
    for (int f = 0; f < 2; ++f) EXPECT_EQ(a.feet[f].force_N, b.feet[f].force_N) << set.name << " " << side_name(f);
  };
  same(jump, measured);
  same(make_example_walk({}), *model_torso);
}

namespace {
/// The synthetic jump (a 30 cm flight) estimated with `off` and with `on`, for a rule that does not
/// act on a trial with flight phases: every foot's force is the same bit for bit, and `on`'s
/// messages say why (`message`).
void expect_jump_untouched(const MarkerSet& set, const EstimateOptions& off, const EstimateOptions& on, const std::string& message) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;
  const Trial jump = make_synthetic_trial(so);
  SCOPED_TRACE("the jump, for: " + message);
  const EstimateResult a = estimate(jump, nullptr, set, off), b = estimate(jump, nullptr, set, on);
  for (int f = 0; f < 2; ++f) EXPECT_EQ(a.feet[f].force_N, b.feet[f].force_N) << side_name(f);
  EXPECT_TRUE(said(b, message));
}
}  // namespace

// The thighs' fore-aft lag (EstimateOptions::thigh_lag_s) in a walk whose knee points are markers
// on the bone (the example set's KJC): the whole body's fore-aft inertial force changes by exactly
// each thigh's m (a(t - tau) - a(t)), its vertical force not at all, the feet's forces follow, and
// the message says so. A trial with flight phases (a jump) keeps the thighs' timing, bit for bit.
TEST(Estimate, AThighOnTheBoneBrakesLateInAWalkButNotInAJump) {
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  const Trial walk = make_example_walk({});
  EstimateOptions none, lagged;
  none.keep_all_series = lagged.keep_all_series = true;
  none.thigh_lag_s = 0.0;
  lagged.thigh_lag_s = 0.02;
  const EstimateResult a = estimate(walk, nullptr, set, none), b = estimate(walk, nullptr, set, lagged);
  ASSERT_EQ(a.motion.rate_hz, 100.0);
  EXPECT_EQ(a.kinematic_total.col(1), b.kinematic_total.col(1));
  double swing = 0;
  for (Eigen::Index i = 2; i < a.motion.frames(); ++i) {
    double expected = 0;
    for (int side = 0; side < 2; ++side) {
      const int c = coord::com_x(segment(side, kThigh));
      expected += a.model().bodies[static_cast<std::size_t>(segment(side, kThigh))].mass_kg * (a.motion.frame(i - 2).qdd(c) - a.motion.frame(i).qdd(c));
    }
    ASSERT_NEAR(b.kinematic_total(i, 0) - a.kinematic_total(i, 0), expected, 1e-6) << i;
    swing = std::max(swing, std::abs(expected));
  }
  EXPECT_GT(swing, 5.0);  // N: a thigh's braking moved by 20 ms
  double moved = 0;
  for (int f = 0; f < 2; ++f) moved = std::max(moved, (a.feet[f].force_N - b.feet[f].force_N).cwiseAbs().maxCoeff());
  EXPECT_GT(moved, 2.0);
  EXPECT_TRUE(said(b, "each thigh's fore-aft inertial force delayed by 20 ms"));
  EXPECT_FALSE(said(a, "thigh lag"));
  expect_jump_untouched(set, none, lagged, "thigh lag: none, the trial has flight phases");
}

// The upper body's vertical smoothing (EstimateOptions::torso_vertical_cutoff_hz), the failure
// mode it is for: pelvis markers that jolt at each heel strike (skin over the iliac crests moving
// with the soft tissue: here the hip markers drop and ring at 10 Hz, 10 mm, dying in 30 ms) while
// the body's mass does not. The reference is the clean walk's own total vertical force. Without
// the smoothing the jolt reaches the whole body's vertical force; with it most of it does not,
// while the clean walk's force (its content below 4 Hz) is kept. In the walk the whole body's
// vertical force changes by exactly the HAT's m (a_f - a) and its fore-aft force not at all; a
// jump (flight phases) is the same bit for bit.
TEST(Estimate, APelvisMarkersHeelStrikeJoltDoesNotReachTheBodysVerticalForce) {
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  const SyntheticWalk clean = make_synthetic_walk({});
  Trial jolted = clean.trial;
  const Eigen::Index n = jolted.markers.frames();
  for (const char* name : {"RHJC", "LHJC"}) {
    const int k = jolted.markers.find(name);
    ASSERT_GE(k, 0) << name;
    for (int side = 0; side < 2; ++side)
      for (Eigen::Index i0 = 1; i0 < n; ++i0) {
        if (!clean.stance[side][static_cast<std::size_t>(i0)] || clean.stance[side][static_cast<std::size_t>(i0 - 1)]) continue;
        for (Eigen::Index i = i0; i < n; ++i) {  // a heel strike: the hip markers ring
          const double t = static_cast<double>(i - i0) / clean.trial.markers.rate_hz;
          jolted.markers.positions_m[static_cast<std::size_t>(k)](i, 2) -= 0.01 * std::exp(-t / 0.03) * std::sin(2 * std::numbers::pi * 10 * t);
        }
      }
  }
  EstimateOptions none, smoothed;
  none.keep_all_series = smoothed.keep_all_series = true;
  none.torso_vertical_cutoff_hz = 0.0;
  smoothed.torso_vertical_cutoff_hz = 4.0;
  const EstimateResult reference = estimate(clean.trial, nullptr, set, none);
  const EstimateResult a = estimate(jolted, nullptr, set, none), b = estimate(jolted, nullptr, set, smoothed);
  const EstimateResult c = estimate(clean.trial, nullptr, set, smoothed);
  const double bw = 70.0 * 9.81;
  const auto rms_off = [&](const EstimateResult& e) {
    const Eigen::Index m = reference.kinematic_total.rows();
    const Eigen::VectorXd d = (e.kinematic_total.col(1) - reference.kinematic_total.col(1)).segment(20, m - 40);
    return std::sqrt(d.squaredNorm() / static_cast<double>(d.size())) / bw;
  };
  // 4.2 % body weight RMS without the smoothing, 2.8 % with it (a jolt a step apart has
  // harmonics of the step frequency below 4 Hz too, which stay), 0.2 % on the clean walk.
  EXPECT_GT(rms_off(a), 0.03);  // the jolt as the 6 Hz kinematics see it
  EXPECT_LT(rms_off(b), 0.75 * rms_off(a));
  EXPECT_LT(rms_off(c), 0.005);  // the clean walk's vertical force is kept
  // Exactly the HAT's vertical inertial force, nothing else of the totals.
  const double hat_kg = a.model().bodies[kTorso].mass_kg;
  const int hat_y = coord::com_x(kTorso) + 1;
  EXPECT_EQ(a.kinematic_total.col(0), b.kinematic_total.col(0));
  for (Eigen::Index i = 0; i < a.motion.frames(); ++i)
    ASSERT_NEAR(b.kinematic_total(i, 1) - a.kinematic_total(i, 1), hat_kg * (b.motion.frame(i).qdd(hat_y) - a.motion.frame(i).qdd(hat_y)),
                1e-6) << i;
  EXPECT_TRUE(said(b, "torso: its vertical inertial force low-passed at 4.0 Hz"));
  EXPECT_FALSE(said(a, "low-passed"));
  expect_jump_untouched(set, none, smoothed, "torso: its vertical inertial force as the markers give it, the trial has flight phases");
  // The flight test does not depend on another rule wanting it: without the thighs' lag, the
  // running COP function and a speed-gate floor of its own near flights (whose options once
  // decided whether it ran) the jump is kept too.
  for (EstimateOptions* eo : {&none, &smoothed}) {
    eo->thigh_lag_s = 0.0;
    eo->contact.running_cop.reset();
    eo->contact.speed_gate.floor_mps = eo->contact.speed_gate.standstill_mps;
  }
  expect_jump_untouched(set, none, smoothed, "the trial has flight phases");
}

TEST(Estimate, ThePostFilterFollowsTheStanceDuration) {
  // A slow and a brisk synthetic walk: each post-filter cut-off is 4 cycles over its own median
  // stance, close to the walk's stance by construction, so the brisk walk's is higher in
  // proportion.
  double cutoff[2], stance[2];
  const double stride[2] = {1.4, 0.9};
  for (int k = 0; k < 2; ++k) {
    SyntheticWalkOptions wo;
    wo.stride_time_s = stride[k];
    wo.speed_mps = 1.3 * 1.1 / stride[k] * 0.8;
    wo.duration_s = 4 * stride[k];
    const SyntheticWalk w = make_synthetic_walk(wo);
    EstimateOptions cycles;  // the cycles-per-stance rule alone (the slow walk's 4.2 Hz is under the default floor)
    cycles.post_cutoff_floor_ratio = 0.0;
    const auto r = estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), cycles);
    const auto measured = median_stance_s({r.feet[0].contact, r.feet[1].contact}, 100.0);
    const auto built = median_stance_s(w.stance, 100.0);
    ASSERT_TRUE(measured && built);
    // The estimate's stances run a little long (0.96 against 0.84 s on the slow walk, 0.60 against
    // 0.55 s on the brisk one: the landing foot is taken up early), not by a fixed amount.
    EXPECT_NEAR(*measured, *built, 0.15 * *built) << stride[k];
    EXPECT_DOUBLE_EQ(r.post_cutoff_hz, 4.0 / *measured);
    bool said = false;
    for (const auto& m : r.messages) said = said || m.find("post-filter cut-off") != std::string::npos;
    EXPECT_TRUE(said);
    cutoff[k] = r.post_cutoff_hz, stance[k] = *built;
    // The paper's fixed cut-off when asked for.
    EstimateOptions fixed;
    fixed.post_cutoff_cycles = 0;
    EXPECT_EQ(estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), fixed).post_cutoff_hz, 12.0);
  }
  EXPECT_GT(cutoff[1], cutoff[0]);
  EXPECT_NEAR(cutoff[1] / cutoff[0], stance[0] / stance[1], 0.1 * stance[0] / stance[1]);
}

// A slow walker (2.2 s strides, stances near 1.4 s): 4 cycles per stance is under 3 Hz; with the
// default floor of 0.75 x the 6 Hz kinematic cut-off the post-filter stays at 4.5 Hz, and says why;
// the feet's sum then follows the whole body's kinematic total more closely (what the floor is for:
// the post-filter is there for the solve's switching, not to remove what the kinematics kept).
TEST(Estimate, APostFilterFloorKeepsASlowWalksCutOffAtTheKinematics) {
  SyntheticWalkOptions wo;
  wo.stride_time_s = 2.2;
  wo.speed_mps = 0.4;
  wo.duration_s = 4 * wo.stride_time_s;
  const SyntheticWalk w = make_synthetic_walk(wo);
  EstimateOptions none, o;
  none.post_cutoff_floor_ratio = 0.0;
  none.keep_all_series = o.keep_all_series = true;
  ASSERT_EQ(o.post_cutoff_floor_ratio, 0.75);  // the default
  const auto plain = estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), none);
  EXPECT_LT(plain.post_cutoff_hz, 3.5);
  const auto floored = estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), o);
  EXPECT_DOUBLE_EQ(floored.post_cutoff_hz, 0.75 * floored.kinematic_cutoff_hz);
  const auto total_rms = [](const EstimateResult& r) {
    const Eigen::Index n = r.time_s.size();
    double ss = 0;
    for (Eigen::Index i = n / 8; i < n - n / 8; ++i)
      ss += std::pow(r.feet[0].force_N(i, 1) + r.feet[1].force_N(i, 1) - r.kinematic_total(i, 1), 2);
    return std::sqrt(ss / static_cast<double>(n - 2 * (n / 8)));
  };
  EXPECT_LT(total_rms(floored), 0.8 * total_rms(plain));
  bool said = false;
  for (const auto& m : floored.messages) said = said || m.find("x the kinematic cut-off") != std::string::npos;
  EXPECT_TRUE(said);
  o.post_cutoff_floor_ratio = -1;
  EXPECT_THROW(estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), o), InputError);
}

TEST(Estimate, AStandingTrialKeepsTheFixedPostFilterAndSaysWhy) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  const auto r = run(so);
  EXPECT_EQ(r.post_cutoff_hz, 12.0);
  bool said = false;
  for (const auto& m : r.messages) said = said || m.find("no complete stance") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(Estimate, PostFilterCyclesOutsideTheirRangeAreRefusedNamingTheSetting) {
  expect_refused_naming([](EstimateOptions& o, double v) { o.post_cutoff_cycles = v; }, {-1.0, 60.0, std::nan("")},
                        "post-filter cycles per stance");
}

// A long trial's memory (issue 10): estimate(Trial&&) releases the markers once the landmarks are
// made, and keep_all_series = false leaves out what only validation reads and the per-frame
// totals, remade as the writers go. Neither may change an output. The walk has a one-frame marker spike, so the cleaned copy's path is taken.
TEST(Estimate, ReleasingTheMarkersAndTheValidationSeriesChangesNoOutput) {
  SyntheticWalkOptions wo;
  wo.duration_s = 6.0;
  Trial walk = make_synthetic_walk(wo).trial;
  walk.markers.positions_m[static_cast<std::size_t>(walk.markers.find("RKJC"))].row(300).array() += 0.5;
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  const EstimateResult full = estimate(walk, nullptr, set, EstimateOptions{});
  EstimateOptions lean;
  lean.keep_all_series = false;
  Trial given = walk;
  const EstimateResult r = estimate(std::move(given), nullptr, set, lean);
  EXPECT_EQ(format_results_csv(r), format_results_csv(full));
  EXPECT_EQ(r.messages, full.messages);
  EXPECT_TRUE(std::any_of(r.messages.begin(), r.messages.end(),
                          [](const std::string& m) { return m.rfind("RKJC: 1 sample(s) no body can produce", 0) == 0; }));
  EXPECT_EQ(r.post_cutoff_hz, full.post_cutoff_hz);
  // What was released or left out.
  for (const auto& p : given.markers.positions_m) EXPECT_EQ(p.rows(), 0);
  EXPECT_EQ(given.markers.frames(), walk.markers.frames());
  EXPECT_EQ(given.markers.names, walk.markers.names);
  EXPECT_EQ(r.landmarks.p[kHip].rows(), 0);
  EXPECT_EQ(r.landmarks.frames(), full.landmarks.frames());
  EXPECT_EQ(r.feet[0].sole_m.rows(), 0);
  EXPECT_EQ(r.kinematic_total.rows(), 0);
  // The totals are remade frame by frame (frame_totals), the very numbers held otherwise.
  EXPECT_EQ(r.grm_Nm.size(), 0);
  EXPECT_EQ(r.joint_force_N.rows(), 0);
  EXPECT_EQ(results_summary(r, {})["residual_rms"], results_summary(full, {})["residual_rms"]);
  for (const Eigen::Index i : {Eigen::Index{0}, full.time_s.size() / 2}) {
    const FrameTotals t = frame_totals(r, i);
    EXPECT_EQ(t.grm_Nm, full.grm_Nm[i]);
    EXPECT_EQ(t.kinematic_total, full.kinematic_total.row(i).transpose());
  }
  EXPECT_EQ(full.feet[0].sole_m.rows(), full.time_s.size());
  // A trial given up keeps what an error message names.
  EXPECT_EQ(given.path, walk.path);
}

// The double supports the transition prior applies to (EstimateOptions::double_support_sta_weight):
// a step's handover only, not standing, a two-footed landing or a run cut by the window.
TEST(Pipeline, WalkingDoubleSupportsAreTheHandoversBetweenSteps) {
  // Right: 0-70, 120-190, 230-400; left: 0-10 (both from the first frame: cut by the window),
  // 60-130, 180-260 and 300-400 (both to the last frame: cut). Handovers at 60-69 (right
  // trailing), 120-129 (left), 180-189 (right) and 230-259 (left; 30 frames).
  const std::array<std::vector<bool>, 2> c{runs({{0, 70}, {120, 190}, {230, 400}}, 400),
                                           runs({{0, 10}, {60, 130}, {180, 260}, {300, 400}}, 400)};
  const auto ds = walking_double_supports(c, 20);
  ASSERT_EQ(ds.size(), 3u);
  EXPECT_EQ(ds[0].first, 60);
  EXPECT_EQ(ds[0].last, 69);
  EXPECT_EQ(ds[0].trailing, 0);
  EXPECT_EQ(ds[1].first, 120);
  EXPECT_EQ(ds[1].last, 129);
  EXPECT_EQ(ds[1].trailing, 1);
  EXPECT_EQ(ds[2].first, 180);
  EXPECT_EQ(ds[2].last, 189);
  EXPECT_EQ(ds[2].trailing, 0);
  // 230-259 is longer than the limit of 20 frames (standing, shuffling): left as solved. With a
  // limit of 30 it counts; 300-399, cut by the window, never does.
  EXPECT_EQ(walking_double_supports(c, 30).size(), 4u);
  EXPECT_EQ(walking_double_supports(c, 1000).size(), 4u);
  EXPECT_DOUBLE_EQ(smooth_transition_share(0.0), 1.0);
  EXPECT_DOUBLE_EQ(smooth_transition_share(0.5), 0.5);
  EXPECT_DOUBLE_EQ(smooth_transition_share(1.0), 0.0);
  EXPECT_DOUBLE_EQ(smooth_transition_share(1.5), 0.0);
}

// In double support the split between the feet follows the sagittal moment, i.e. the body COP
// GRM / F, which moves from the trailing foot to the leading one faster than 6 Hz kinematics can
// follow (76 % of the development walks' per-foot vertical squared error lies there). The prior
// moves the trailing foot's share exactly `w` of the way to the smooth handover, keeps the two
// feet's sum and each foot's COP, and touches no frame outside a double support.
TEST(Estimate, TheDoubleSupportTransitionMovesOnlyTheSplitAndByItsWeight) {
  const SyntheticWalk walk = make_synthetic_walk({});
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  EstimateOptions off, on;
  off.double_support_sta_weight = 0.0;
  on.double_support_sta_weight = 0.2;
  off.double_support_angle = on.double_support_angle = 0.0;  // the vertical split alone (its angle rule: the next test)
  const EstimateResult a = estimate(walk.trial, nullptr, set, off), b = estimate(walk.trial, nullptr, set, on);
  const Eigen::Index n = a.time_s.size();
  ASSERT_EQ(b.time_s.size(), n);
  const auto rate = walk.trial.markers.rate_hz;
  const auto stance = median_stance_s({a.feet[0].contact, a.feet[1].contact}, rate);
  ASSERT_TRUE(stance);
  const auto supports = walking_double_supports({a.feet[0].contact, a.feet[1].contact}, static_cast<Eigen::Index>(0.5 * *stance * rate));
  ASSERT_GE(supports.size(), 4u);
  std::vector<int> in_support(static_cast<std::size_t>(n), -1);
  for (std::size_t d = 0; d < supports.size(); ++d)
    for (Eigen::Index i = supports[d].first; i <= supports[d].last; ++i) in_support[static_cast<std::size_t>(i)] = static_cast<int>(d);
  int moved = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int s = 0; s < 2; ++s) {
      EXPECT_EQ(a.feet[s].contact[static_cast<std::size_t>(i)], b.feet[s].contact[static_cast<std::size_t>(i)]);
      EXPECT_EQ(a.feet[s].force_N(i, 0), b.feet[s].force_N(i, 0)) << "the anterior force is left as solved";
      if (std::isfinite(a.feet[s].cop_x_m[i])) {
        EXPECT_EQ(a.feet[s].cop_x_m[i], b.feet[s].cop_x_m[i]);
      }
    }
    const double sum_a = a.feet[0].force_N(i, 1) + a.feet[1].force_N(i, 1), sum_b = b.feet[0].force_N(i, 1) + b.feet[1].force_N(i, 1);
    ASSERT_NEAR(sum_a, sum_b, 1e-9 * std::max(1.0, std::abs(sum_a))) << "frame " << i;
    const int d = in_support[static_cast<std::size_t>(i)];
    if (d < 0) {
      for (int s = 0; s < 2; ++s) ASSERT_EQ(a.feet[s].force_N(i, 1), b.feet[s].force_N(i, 1)) << "frame " << i;
      for (int j = 0; j < kJointCount; ++j) ASSERT_EQ(a.joint_torque_Nm(i, j), b.joint_torque_Nm(i, j)) << "frame " << i;
      continue;
    }
    const auto& ds = supports[static_cast<std::size_t>(d)];
    const double u = (static_cast<double>(i - ds.first) + 0.5) / static_cast<double>(ds.last - ds.first + 1);
    const double share_a = a.feet[ds.trailing].force_N(i, 1) / sum_a, share_b = b.feet[ds.trailing].force_N(i, 1) / sum_b;
    EXPECT_NEAR(share_b, 0.8 * share_a + 0.2 * smooth_transition_share(u), 1e-9) << "frame " << i;
    if (std::abs(share_b - share_a) > 1e-3) {
      ++moved;
      // The torques follow the contact forces (the solve's own linear map), so they change too.
      EXPECT_NE(a.joint_torque_Nm.row(i), b.joint_torque_Nm.row(i)) << "frame " << i;
    }
  }
  EXPECT_GT(moved, 10);
  const bool said = std::any_of(b.messages.begin(), b.messages.end(), [](const std::string& m) { return m.find("double support") != std::string::npos; });
  EXPECT_TRUE(said);
}

// The transition moves load between the feet; with double_support_angle 1 it does not turn either
// foot's force: each foot's fore-aft force is scaled with its vertical one, so in every double
// support frame each foot's force angle is the solve's (the run without the transition), the
// vertical split is the previous test's, and frames outside a double support are untouched. At
// 0.5 the fore-aft force moves half as far.
TEST(Estimate, TheDoubleSupportTransitionKeepsEachFootsForceAngle) {
  const SyntheticWalk walk = make_synthetic_walk({});
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  EstimateOptions solved, vertical_only, kept, half;
  solved.double_support_sta_weight = 0.0;
  vertical_only.double_support_sta_weight = kept.double_support_sta_weight = half.double_support_sta_weight = 0.4;
  vertical_only.double_support_angle = 0.0;
  kept.double_support_angle = 1.0;
  half.double_support_angle = 0.5;
  const EstimateResult s = estimate(walk.trial, nullptr, set, solved), v = estimate(walk.trial, nullptr, set, vertical_only),
                       k = estimate(walk.trial, nullptr, set, kept), h = estimate(walk.trial, nullptr, set, half);
  const Eigen::Index n = s.time_s.size();
  ASSERT_EQ(k.time_s.size(), n);
  int turned = 0;
  for (Eigen::Index i = 0; i < n; ++i)
    for (int f = 0; f < 2; ++f) {
      const double fy_s = s.feet[f].force_N(i, 1), fx_s = s.feet[f].force_N(i, 0);
      const double fy_k = k.feet[f].force_N(i, 1), fx_k = k.feet[f].force_N(i, 0);
      ASSERT_EQ(fy_k, v.feet[f].force_N(i, 1)) << "the vertical split is the transition's, frame " << i;
      if (v.feet[f].force_N(i, 1) == fy_s) {
        ASSERT_EQ(fx_k, fx_s) << "a frame the transition left alone, frame " << i;
        continue;
      }
      ASSERT_GT(fy_s, 1.0);
      // The angle: fx / fy as solved (to rounding).
      EXPECT_NEAR(fx_k / fy_k, fx_s / fy_s, 1e-9 * std::max(1.0, std::abs(fx_s / fy_s))) << "frame " << i << " foot " << f;
      // Half the rule: half the change of the fore-aft force.
      EXPECT_NEAR(h.feet[f].force_N(i, 0) - fx_s, 0.5 * (fx_k - fx_s), 1e-9 * std::max(1.0, std::abs(fx_k))) << "frame " << i;
      if (std::abs(fx_k - fx_s) > 1.0) {
        ++turned;
        // The torques follow the fore-aft multipliers too (the solve's torque_per_tangent).
        EXPECT_NE(k.joint_torque_Nm.row(i), v.joint_torque_Nm.row(i)) << "frame " << i;
      }
    }
  EXPECT_GT(turned, 10) << "the synthetic walk's double supports move fore-aft force by more than 1 N on a few frames";
}

// The angle rule's arithmetic, and its guard: a lightly loaded foot whose solved force leans
// further than any walking foot's friction allows (here 1.5 N fore-aft on 1 N) does not carry that
// angle onto the 60 N the transition gives it; growing, the fore-aft force stops at the new
// vertical force (a 45-degree lean) unless the solve's own was larger, which it keeps. Shrinking
// is never bounded.
TEST(Estimate, TheTransitionsForeAftForceKeepsTheAngleButGrowsNoFurtherThanItsNewVerticalForce) {
  EXPECT_DOUBLE_EQ(transition_tangent(-30.0, 300.0, 450.0, 1.0), -45.0);   // the angle kept
  EXPECT_DOUBLE_EQ(transition_tangent(-30.0, 300.0, 450.0, 0.5), -37.5);   // half the change
  EXPECT_DOUBLE_EQ(transition_tangent(-30.0, 300.0, 450.0, 0.0), -30.0);   // as solved
  EXPECT_DOUBLE_EQ(transition_tangent(50.0, 500.0, 300.0, 1.0), 30.0);     // unloading: the angle kept
  EXPECT_DOUBLE_EQ(transition_tangent(1.5, 1.0, 60.0, 1.0), 60.0);         // capped at the new normal force
  EXPECT_DOUBLE_EQ(transition_tangent(-1.5, 1.0, 60.0, 1.0), -60.0);
  EXPECT_DOUBLE_EQ(transition_tangent(80.0, 10.0, 40.0, 1.0), 80.0);       // never below the solve's own
  EXPECT_DOUBLE_EQ(transition_tangent(5.0, 0.0, 40.0, 1.0), 5.0);          // no normal force to scale by
}

// The touchdown rule (issue 29) on a walk whose contact the solve begins 40-50 ms before the
// plates load: the landing foot's first frames carry nothing, the load dropped there is exactly
// what the feet's sum loses, the residual shows it, and frames the rule does not touch keep their
// forces and torques.
TEST(SharedEstimate, ALandingFootsLoadBeforeItsHeelHasStoppedIsDroppedNotMoved) {
  KIN2GRF_REQUIRE_DATA();
  const Trial t = load_trial(test::data_file("btk_plugingait_walk/PiG_Motion3_FF.c3d"));
  EstimateOptions off, on;
  off.keep_all_series = on.keep_all_series = true;
  off.double_support_sta_weight = on.double_support_sta_weight = 0.0;  // the drop alone (the handover would move the split too)
  off.touchdown_stop_fraction = 0.0;
  on.touchdown_stop_fraction = 0.1;
  const MarkerSet& set = *recognise_marker_set(t.markers);
  const EstimateResult a = estimate(t, nullptr, set, off), b = estimate(t, nullptr, set, on);
  const Eigen::Index n = a.time_s.size();
  ASSERT_EQ(b.time_s.size(), n);
  int dropped = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    double lost = 0.0;
    for (int s = 0; s < 2; ++s) {
      ASSERT_FALSE(b.feet[s].contact[k] && !a.feet[s].contact[k]) << "frame " << i << ": the rule only ends contact";
      if (a.feet[s].contact[k] && !b.feet[s].contact[k]) {
        ++dropped;
        lost += a.feet[s].force_N(i, 1);
        EXPECT_EQ(b.feet[s].force_N(i, 1), 0.0);
        EXPECT_EQ(b.feet[s].raw_force_N(i, 1), 0.0);
      }
    }
    for (int s = 0; s < 2; ++s) {
      if (b.feet[s].contact[k]) {
        EXPECT_EQ(a.feet[s].force_N.row(i), b.feet[s].force_N.row(i)) << "frame " << i;
      }
    }
    const double sum_a = a.feet[0].force_N(i, 1) + a.feet[1].force_N(i, 1), sum_b = b.feet[0].force_N(i, 1) + b.feet[1].force_N(i, 1);
    ASSERT_NEAR(sum_a - sum_b, lost, 1e-6 * std::max(1.0, sum_a)) << "frame " << i;
    EXPECT_NEAR(b.residual(i, 1) - a.residual(i, 1), lost, 1e-6 * std::max(1.0, sum_a)) << "frame " << i;
    for (int j = 0; j < kJointCount; ++j) {
      if (lost == 0.0) {
        EXPECT_EQ(a.joint_torque_Nm(i, j), b.joint_torque_Nm(i, j)) << "frame " << i;
      }
    }
    if (lost > 1.0) {
      EXPECT_NE(a.joint_torque_Nm.row(i), b.joint_torque_Nm.row(i)) << "frame " << i << ": the torques lose the load too";
    }
  }
  EXPECT_GE(dropped, 12);  // 6 landings, 40-50 ms early at 100 Hz
  EXPECT_LE(dropped, 40);
  const bool said = std::any_of(b.messages.begin(), b.messages.end(), [](const std::string& m) { return m.find("touchdown:") != std::string::npos; });
  EXPECT_TRUE(said);
}

// The failure mode: the touchdown rule ran before the double-support transition, so each
// handover began at the rule's touchdown instead of the solve's contact and the landing foot took
// its load more slowly after it (UWA's walk: 306 against 440 N 12 ms after the plate's onset, 512
// measured). A synthetic walk whose heels land descending at 0.3 m/s (the zero-lag filter spreads
// the stop over the frames before it): with the rule, each landing foot carries nothing before its
// heel strike; from the heel strike on, both feet's forces and the joint torques are the run's
// without the rule, with the transition at its default weight; the sum loses only the dropped load.
TEST(Estimate, TheTouchdownRuleDropsTheLoadBeforeHeelStrikeAndLeavesTheHandoverAsSolved) {
  SyntheticWalkOptions wo;
  wo.heel_strike_descent_mps = 0.3;
  const SyntheticWalk w = make_synthetic_walk(wo);
  const MarkerSet& set = *recognise_marker_set(w.trial.markers);
  EstimateOptions off, on;
  off.keep_all_series = on.keep_all_series = true;
  off.touchdown_stop_fraction = 0.0;
  on.touchdown_stop_fraction = 0.1;
  // The function of the angle alone (kin2grf's default before session 46): with the default's
  // centre-of-mass term this synthetic walk's landings take no load before their heel strikes
  // even without the rule, which would then have nothing to drop here.
  off.contact.cop = on.contact.cop = CopFunction{-0.20, -0.06, 0.08, 1.08, 0.138, 0.260, 0.761, 1.012, 0.0};
  ASSERT_GT(off.double_support_sta_weight, 0.0);  // the default's handover
  const EstimateResult a = estimate(w.trial, nullptr, set, off), b = estimate(w.trial, nullptr, set, on);
  const Eigen::Index n = a.time_s.size();
  ASSERT_EQ(b.time_s.size(), n);
  int early_off = 0, early_on = 0, compared = 0;
  for (int f = 0; f < 2; ++f)
    for (Eigen::Index i = 1; i + 1 < n; ++i) {
      const auto k = static_cast<std::size_t>(i + a.first_index);
      if (!w.stance[f][k] || w.stance[f][k - 1]) continue;
      // The frames just before this heel strike: loaded without the rule, not with it.
      for (Eigen::Index j = std::max<Eigen::Index>(0, i - 10); j < i; ++j) {
        early_off += a.feet[f].force_N(j, 1) > 10.0;
        early_on += b.feet[f].force_N(j, 1) > 0.0;
      }
      // From the heel strike through the double support: as without the rule.
      for (Eigen::Index j = i; j < std::min(n, i + 20); ++j, ++compared) {
        for (int g = 0; g < 2; ++g)
          for (int c = 0; c < 2; ++c)
            EXPECT_NEAR(b.feet[g].force_N(j, c), a.feet[g].force_N(j, c), 1e-9 * std::max(1.0, std::abs(a.feet[g].force_N(j, c))))
                << "foot " << g << " frame " << j << " (heel strike at " << i << ")";
        for (int q = 0; q < kJointCount; ++q)
          EXPECT_NEAR(b.joint_torque_Nm(j, q), a.joint_torque_Nm(j, q), 1e-9 * std::max(1.0, std::abs(a.joint_torque_Nm(j, q)))) << "frame " << j;
      }
    }
  EXPECT_GE(early_off, 5) << "the walk's landings are loaded before their heel strikes without the rule";
  EXPECT_EQ(early_on, 0);
  EXPECT_GE(compared, 100);
  for (Eigen::Index i = 0; i < n; ++i) {
    double lost = 0.0;
    for (int f = 0; f < 2; ++f)
      if (a.feet[f].contact[static_cast<std::size_t>(i)] && !b.feet[f].contact[static_cast<std::size_t>(i)]) lost += a.feet[f].force_N(i, 1);
    const double sa = a.feet[0].force_N(i, 1) + a.feet[1].force_N(i, 1), sb = b.feet[0].force_N(i, 1) + b.feet[1].force_N(i, 1);
    ASSERT_NEAR(sa - sb, lost, 1e-6 * std::max(1.0, sa)) << "frame " << i;
  }
}

TEST(Estimate, ADoubleSupportWeightOrStanceFloorOutsideItsRangeIsRefusedNamingTheSetting) {
  expect_refused_naming([](EstimateOptions& o, double v) { o.double_support_sta_weight = v; }, {-0.1, 1.5, std::nan("")},
                        "double-support");
  expect_refused_naming([](EstimateOptions& o, double v) { o.double_support_angle = v; }, {-0.1, 1.5, std::nan("")},
                        "double-support force angle");
  expect_refused_naming([](EstimateOptions& o, double v) { o.min_kinematic_cycles = v; }, {-1.0, 25.0, std::nan("")},
                        "kinematic cycles per stance");
}

// The failure mode: a trial cut mid-stance (a capture started late, a gap trimmed) gave that
// stance's filter-edge forces with no word. Now each stance within half a period of the
// kinematic cut-off of the window's ends is named, with its frames, and no other.
TEST(Pipeline, AStanceAtTheWindowsEdgeIsNamedWithItsFramesAndNoOther) {
  SyntheticWalkOptions wo;
  wo.duration_s = 5.0;
  const SyntheticWalk w = make_synthetic_walk(wo);
  // The right foot's second stance, cut 0.2 s after it begins: the trial starts there.
  const auto& st = w.stance[0];
  Eigen::Index k = -1;
  int begun = 0;
  for (Eigen::Index i = 1; i < static_cast<Eigen::Index>(st.size()); ++i)
    if (st[static_cast<std::size_t>(i)] && !st[static_cast<std::size_t>(i - 1)] && ++begun == 2) {
      k = i + 20;
      break;
    }
  ASSERT_GT(k, 0);
  Trial t = w.trial;
  const Eigen::Index n = t.markers.frames() - k;
  for (auto& P : t.markers.positions_m) P = Eigen::MatrixX3d(P.bottomRows(n));
  t.markers.time_s = Eigen::VectorXd(t.markers.time_s.tail(n));
  t.markers.first_frame += static_cast<int>(k);
  t.plates.reset();
  const EstimateResult r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), {});
  ASSERT_EQ(r.first_index, 0);
  const auto reach = static_cast<Eigen::Index>(std::ceil(0.5 / r.kinematic_cutoff_hz * r.motion.rate_hz));  // 9 frames at 100 Hz
  std::vector<std::string> expected;
  for (int s = 0; s < 2; ++s)
    for (const IndexRun& run : merge_close_runs(runs_where(r.time_s.size(), [&](Eigen::Index i) {
                                                  return static_cast<bool>(r.feet[static_cast<std::size_t>(s)].contact[static_cast<std::size_t>(i)]);
                                                }), 2))
      if (run.first < reach || run.last > r.time_s.size() - 1 - reach)
        expected.push_back(std::string(s ? "left" : "right") + " foot: the stance at frames " +
                           std::to_string(r.first_frame_number + run.first) + "-" + std::to_string(r.first_frame_number + run.last));
  std::vector<std::string> said;
  for (const auto& m : r.messages)
    if (m.find("of the window's") != std::string::npos) said.push_back(m);
  ASSERT_EQ(said.size(), expected.size());
  for (std::size_t i = 0; i < said.size(); ++i) EXPECT_EQ(said[i].rfind(expected[i], 0), 0u) << said[i];
  // The cut stance is among them, named from the trial's first frame, as beginning at the start.
  ASSERT_FALSE(said.empty());
  EXPECT_NE(said.front().find("right foot: the stance at frames " + std::to_string(t.markers.first_frame) + "-"), std::string::npos)
      << said.front();
  EXPECT_NE(said.front().find("begins within 83 ms of the window's start"), std::string::npos) << said.front();
}

// Gait events from the contact states: a strike at each stance's first frame and a foot off at
// the first frame after it; a flicker under 20 ms is bridged, a run under 50 ms is no stance, and
// a stance cut by the window's ends gives no event at that end.
TEST(Pipeline, GaitEventsAreTheStancesEndsInsideTheWindow) {
  const double rate = 100.0;
  const Eigen::Index n = 200;
  Eigen::VectorXd t(n);
  for (Eigen::Index i = 0; i < n; ++i) t[i] = static_cast<double>(i) / rate;
  std::array<std::vector<bool>, 2> c{std::vector<bool>(n, false), std::vector<bool>(n, false)};
  for (Eigen::Index i = 0; i < 40; ++i) c[0][static_cast<std::size_t>(i)] = true;     // cut by the start: a foot off at 40
  for (Eigen::Index i = 100; i < 170; ++i) c[0][static_cast<std::size_t>(i)] = true;  // strike 100, off 170
  c[0][130] = false;                                                                  // a 10 ms flicker, bridged
  for (Eigen::Index i = 60; i < 63; ++i) c[1][static_cast<std::size_t>(i)] = true;    // 30 ms: no stance
  for (Eigen::Index i = 150; i < n; ++i) c[1][static_cast<std::size_t>(i)] = true;    // strike 150, cut by the end
  const auto ev = gait_events(c, t, rate);
  ASSERT_EQ(ev.size(), 4u);
  EXPECT_EQ(ev[0].label, "Foot Off");
  EXPECT_EQ(ev[0].index, 40);
  EXPECT_EQ(ev[1].label, "Foot Strike");
  EXPECT_EQ(ev[1].index, 100);
  EXPECT_EQ(ev[1].side, 0);
  EXPECT_EQ(ev[2].index, 150);
  EXPECT_EQ(ev[2].side, 1);
  EXPECT_EQ(ev[3].label, "Foot Off");
  EXPECT_EQ(ev[3].index, 170);
  EXPECT_DOUBLE_EQ(ev[3].time_s, 1.7);
}

namespace {

/// Every landmark swaying sideways alike, A sin(w t) along y (the mediolateral tests' body).
std::array<Eigen::MatrixX3d, kLandmarkCount> swaying_landmarks(const Eigen::VectorXd& time_s, double A, double w) {
  std::array<Eigen::MatrixX3d, kLandmarkCount> lab;
  for (auto& p : lab) {
    p = Eigen::MatrixX3d::Zero(time_s.size(), 3);
    for (Eigen::Index i = 0; i < time_s.size(); ++i) p(i, 1) = A * std::sin(w * time_s[i]);
  }
  return lab;
}

double total_mass(const Model& model) {
  double mass = 0;
  for (const Body& b : model.bodies) mass += b.mass_kg;
  return mass;
}

}  // namespace

// The mediolateral force (dynamics/mediolateral.hpp): the whole body's lateral acceleration,
// carried by the feet in proportion to their vertical loads.
TEST(Mediolateral, TheFeetCarryTheBodysLateralAccelerationSharedByLoad) {
  const auto r = run({});  // a squat: both feet on the ground throughout
  const Eigen::Index n = r.time_s.size();
  const double A = 0.03, w = 2 * M_PI * 1.0;  // a 3 cm sway at 1 Hz, every landmark alike
  const std::array<Eigen::MatrixX3d, kLandmarkCount> lab = swaying_landmarks(r.time_s, A, w);
  const Eigen::MatrixX3d lateral = Eigen::RowVector3d(0, 1, 0).replicate(n, 1);
  std::array<Eigen::VectorXd, 2> fy{r.feet[0].force_N.col(1), r.feet[1].force_N.col(1)};
  const std::array<FootLoad, 2> loads{FootLoad{&fy[0], &r.feet[0].contact}, FootLoad{&fy[1], &r.feet[1].contact}};
  const MediolateralForces ml = mediolateral_forces(r.motion, lab, lateral, 6.0, loads);
  const double mass = total_mass(r.model());
  const double peak = mass * A * w * w;  // 83 N for 70 kg
  for (Eigen::Index i = n / 4; i < 3 * n / 4; ++i) {
    EXPECT_NEAR(ml.total_N[i], -peak * std::sin(w * r.time_s[i]), 0.01 * peak) << "frame " << i;
    EXPECT_NEAR(ml.foot_N[0][i] + ml.foot_N[1][i], ml.total_N[i], 1e-9 * peak);
    // Each foot its own lower leg's inertia, the rest by load.
    const double rest = ml.total_N[i] - ml.lower_leg_N[0][i] - ml.lower_leg_N[1][i];
    EXPECT_NEAR(ml.foot_N[0][i], ml.lower_leg_N[0][i] + rest * fy[0][i] / (fy[0][i] + fy[1][i]), 1e-9 * peak);
  }
  // A foot off the ground carries none of it, the other all.
  std::vector<bool> off(static_cast<std::size_t>(n), false);
  const std::array<FootLoad, 2> one{FootLoad{&fy[0], &r.feet[0].contact}, FootLoad{&fy[1], &off}};
  const MediolateralForces single = mediolateral_forces(r.motion, lab, lateral, 6.0, one);
  EXPECT_EQ(single.foot_N[1].cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT((single.foot_N[0] - single.total_N).cwiseAbs().maxCoeff(), 1e-9 * peak);
}

// The frontal split's whole-body balance (whole_body_lateral, from com_landmark_weights' sums, which
// sagittal_landmarks makes without holding each landmark's lab position) is the lateral model's:
// the same centre of mass and lateral force as mediolateral_forces', each landmark swaying with its
// own amplitude and phase so that every weight counts.
TEST(Mediolateral, TheFrontalBalancesCentreOfMassIsTheLateralModels) {
  const auto r = run({});
  const Eigen::Index n = r.time_s.size();
  std::array<Eigen::MatrixX3d, kLandmarkCount> lab;
  for (int id = 0; id < kLandmarkCount; ++id) {
    lab[static_cast<std::size_t>(id)] = Eigen::MatrixX3d::Zero(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double t = r.time_s[i];
      lab[static_cast<std::size_t>(id)].row(i) << 0.1 * id + 0.2 * t, (0.01 + 0.005 * id) * std::sin(2 * M_PI * t + 0.3 * id), 0.05 * id;
    }
  }
  const Eigen::MatrixX3d lateral = Eigen::RowVector3d(0, 1, 0).replicate(n, 1);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const std::vector<bool> off(static_cast<std::size_t>(n), false);
  const std::array<FootLoad, 2> none{FootLoad{&zero, &off}, FootLoad{&zero, &off}};
  const MediolateralForces ml = mediolateral_forces(r.motion, lab, lateral, 3.0, none);
  // The sums as sagittal_landmarks makes them, with the weights of a model of other lengths (the
  // table's fractions alone enter).
  const auto weights = com_landmark_weights(build_model(BodyGeometry{}, 1.0, anthropometric_table(EstimateOptions{}.anthropometry)));
  ASSERT_EQ(weights.size(), 2u);
  double hat = 0;
  for (double w : weights[1]) hat += w;
  EXPECT_NEAR(hat, 1.0, 1e-12);  // the HAT's own COM
  std::vector<Eigen::MatrixX3d> sums(2, Eigen::MatrixX3d::Zero(n, 3));
  for (std::size_t k = 0; k < 2; ++k)
    for (int id = 0; id < kLandmarkCount; ++id) sums[k] += weights[k][static_cast<std::size_t>(id)] * lab[static_cast<std::size_t>(id)];
  const WholeBodyLateral wb = whole_body_lateral(r.model(), sums, nullptr, lateral, r.motion.rate_hz, 3.0);
  EXPECT_LT((wb.com_lateral_m - ml.com_lateral_m).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((wb.total_N - ml.total_N).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT(ml.total_N.cwiseAbs().maxCoeff(), 1.0);  // a force there is to compare
}

// The torso's lateral lag (EstimateOptions::lateral_torso_lag): the body sways at 1 Hz, every
// landmark alike; with a delay tau the trunk's share of the mass (the HAT, here with no arm or
// head of its own) accelerates tau late, the rest on time, so the total is
// -M_rest A w^2 sin(w t) - M_trunk A w^2 sin(w (t - tau)). Frames near a flight phase take the
// total as measured.
TEST(Mediolateral, TheTorsosShareSwaysLateAwayFromFlightPhases) {
  const auto r = run({});
  const Eigen::Index n = r.time_s.size();
  const double A = 0.03, w = 2 * M_PI * 1.0, tau = 0.03;
  const std::array<Eigen::MatrixX3d, kLandmarkCount> lab = swaying_landmarks(r.time_s, A, w);
  const Eigen::MatrixX3d lateral = Eigen::RowVector3d(0, 1, 0).replicate(n, 1);
  std::array<Eigen::VectorXd, 2> fy{r.feet[0].force_N.col(1), r.feet[1].force_N.col(1)};
  const std::array<FootLoad, 2> loads{FootLoad{&fy[0], &r.feet[0].contact}, FootLoad{&fy[1], &r.feet[1].contact}};
  const double mass = total_mass(r.model());
  const double trunk = r.model().bodies[kTorso].mass_kg, peak = mass * A * w * w;
  std::vector<bool> near(static_cast<std::size_t>(n), false);
  for (Eigen::Index i = n / 2; i < n; ++i) near[static_cast<std::size_t>(i)] = true;  // a flight in the second half
  const MediolateralForces lagged = mediolateral_forces(r.motion, lab, lateral, 6.0, loads, 0.0, true, nullptr, tau, &near);
  const MediolateralForces plain = mediolateral_forces(r.motion, lab, lateral, 6.0, loads);
  for (Eigen::Index i = n / 8; i < 3 * n / 8; ++i) {
    const double t = r.time_s[i];
    const double expected = -(mass - trunk) * A * w * w * std::sin(w * t) - trunk * A * w * w * std::sin(w * (t - tau));
    EXPECT_NEAR(lagged.total_N[i], expected, 0.01 * peak) << "frame " << i;
    EXPECT_NEAR(lagged.foot_N[0][i] + lagged.foot_N[1][i], lagged.total_N[i], 1e-9 * peak);
  }
  // The delay matters: the trunk is over half the mass, and 30 ms is 11 degrees of a 1 Hz sway.
  double largest = 0;
  for (Eigen::Index i = n / 8; i < 3 * n / 8; ++i) largest = std::max(largest, std::abs(lagged.total_N[i] - plain.total_N[i]));
  EXPECT_GT(largest, 0.05 * peak);
  for (Eigen::Index i = n / 2; i < n; ++i) EXPECT_EQ(lagged.total_N[i], plain.total_N[i]) << "frame " << i;
}

// The lateral force's cut-off (EstimateOptions::lateral_cutoff_hz, 2.5 Hz): the body's sway is slow,
// the markers' noise is not. A 3 cm sway at 1 Hz seen through 1 mm of noise on every landmark
// coordinate: at 2.5 Hz the total follows M a within a few % of its peak, at the 6 Hz kinematic
// cut-off the doubly differentiated noise is several times larger.
TEST(Mediolateral, ALowerCutoffKeepsTheSwayAndDropsTheMarkersNoise) {
  const auto r = run({});
  const Eigen::Index n = r.time_s.size();
  const double A = 0.03, w = 2 * M_PI * 1.0;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.001);
  std::array<Eigen::MatrixX3d, kLandmarkCount> lab;
  for (auto& p : lab) {
    p = Eigen::MatrixX3d::Zero(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) p.row(i) << noise(rng), A * std::sin(w * r.time_s[i]) + noise(rng), noise(rng);
  }
  const Eigen::MatrixX3d lateral = Eigen::RowVector3d(0, 1, 0).replicate(n, 1);
  std::array<Eigen::VectorXd, 2> fy{r.feet[0].force_N.col(1), r.feet[1].force_N.col(1)};
  const std::array<FootLoad, 2> loads{FootLoad{&fy[0], &r.feet[0].contact}, FootLoad{&fy[1], &r.feet[1].contact}};
  const double mass = total_mass(r.model());
  const double peak = mass * A * w * w;
  const auto rms_error = [&](double cutoff_hz) {
    const MediolateralForces ml = mediolateral_forces(r.motion, lab, lateral, cutoff_hz, loads);
    double se = 0;
    int k = 0;
    for (Eigen::Index i = n / 4; i < 3 * n / 4; ++i, ++k) se += std::pow(ml.total_N[i] + peak * std::sin(w * r.time_s[i]), 2);
    return std::sqrt(se / k);
  };
  const double at_default = rms_error(EstimateOptions{}.lateral_cutoff_hz), at6 = rms_error(6.0);
  EXPECT_EQ(EstimateOptions{}.lateral_cutoff_hz, 2.5);  // since session 36 (3 Hz before)
  EXPECT_LT(at_default, 0.05 * peak) << at_default << " " << peak;
  EXPECT_LT(2 * at_default, at6) << at_default << " " << at6 << " " << peak;
}

// A turning walk's lateral axis rotates: a body moving straight at constant speed in the lab has
// no lateral acceleration, whatever the axis does (differentiating the projected coordinate
// instead would read x(t) times the turn as a force).
TEST(Mediolateral, ARotatingFrameAddsNoForce) {
  const auto r = run({});
  const Eigen::Index n = r.time_s.size();
  std::array<Eigen::MatrixX3d, kLandmarkCount> lab;
  Eigen::MatrixX3d lateral(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = r.time_s[i], phi = 0.3 * t;  // turning at 0.3 rad/s
    lateral.row(i) = Eigen::RowVector3d(-std::sin(phi), std::cos(phi), 0);
  }
  for (auto& p : lab) {
    p = Eigen::MatrixX3d::Zero(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) p(i, 0) = 5.0 + 1.2 * r.time_s[i];  // 5 m from the origin, 1.2 m/s
  }
  std::array<Eigen::VectorXd, 2> fy{r.feet[0].force_N.col(1), r.feet[1].force_N.col(1)};
  const std::array<FootLoad, 2> loads{FootLoad{&fy[0], &r.feet[0].contact}, FootLoad{&fy[1], &r.feet[1].contact}};
  const MediolateralForces ml = mediolateral_forces(r.motion, lab, lateral, 6.0, loads);
  EXPECT_LT(ml.total_N.segment(n / 4, n / 2).cwiseAbs().maxCoeff(), 0.5);
}

// The split's own-leg rule (dynamics/mediolateral.hpp): a landing foot brakes its own shank's and
// foot's sideways swing while it takes little weight. Only the left lower leg (knee, ankle, heel,
// MT, toes) swings sideways, 2 cm at 2 Hz, with the left foot carrying a tenth of the weight: the
// left foot carries that leg's inertia m a (shank, foot and toes) and a tenth of the rest (the
// thigh's share, its distal end moving with the knee); shared by load alone it would carry a
// tenth of all.
TEST(Mediolateral, ALandingFootCarriesItsOwnLowerLegsInertia) {
  const auto r = run({});
  const Eigen::Index n = r.time_s.size();
  const double A = 0.02, w = 2 * M_PI * 2.0;
  std::array<Eigen::MatrixX3d, kLandmarkCount> lab;
  for (auto& p : lab) p = Eigen::MatrixX3d::Zero(n, 3);
  for (LegLandmark l : {kKnee, kAnkle, kHeel, kMt, kHallux})
    for (Eigen::Index i = 0; i < n; ++i) lab[static_cast<std::size_t>(landmark(kLeft, l))](i, 1) = A * std::sin(w * r.time_s[i]);
  const Eigen::MatrixX3d lateral = Eigen::RowVector3d(0, 1, 0).replicate(n, 1);
  std::array<Eigen::VectorXd, 2> fy{Eigen::VectorXd::Constant(n, 630.0), Eigen::VectorXd::Constant(n, 70.0)};
  const std::vector<bool> both(static_cast<std::size_t>(n), true);
  const std::array<FootLoad, 2> loads{FootLoad{&fy[0], &both}, FootLoad{&fy[1], &both}};
  const MediolateralForces own = mediolateral_forces(r.motion, lab, lateral, 3.0, loads, 8.0);
  const MediolateralForces load = mediolateral_forces(r.motion, lab, lateral, 3.0, loads, 8.0, false);
  double lower_leg_kg = 0;
  for (LegSegment s : {kShank, kFoot, kToes}) lower_leg_kg += r.model().bodies[static_cast<std::size_t>(segment(kLeft, s))].mass_kg;
  const double peak = lower_leg_kg * A * w * w;  // about 11 N for 70 kg
  for (Eigen::Index i = n / 4; i < 3 * n / 4; ++i) {
    const double ma = -peak * std::sin(w * r.time_s[i]);
    EXPECT_NEAR(own.lower_leg_N[1][i], ma, 0.03 * peak) << "frame " << i;
    EXPECT_EQ(own.lower_leg_N[0][i], 0.0);
    const double rest = own.total_N[i] - own.lower_leg_N[1][i];
    EXPECT_NEAR(own.foot_N[1][i], own.lower_leg_N[1][i] + 0.1 * rest, 1e-9 * peak);
    EXPECT_NEAR(own.foot_N[0][i] + own.foot_N[1][i], own.total_N[i], 1e-9 * peak);
    EXPECT_NEAR(load.foot_N[1][i], 0.1 * load.total_N[i], 1e-9 * peak);
  }
  // The left foot's force: near the leg's own inertia, where the load share gives it a tenth.
  double own_error = 0, load_error = 0;
  for (Eigen::Index i = n / 4; i < 3 * n / 4; ++i) {
    const double ma = -peak * std::sin(w * r.time_s[i]);
    own_error = std::max(own_error, std::abs(own.foot_N[1][i] - ma));
    load_error = std::max(load_error, std::abs(load.foot_N[1][i] - ma));
  }
  EXPECT_LT(own_error, 0.25 * peak);
  EXPECT_GT(load_error, 0.7 * peak);
}

// The arms as segments of their own (--upper-body segments, MarkerSet::upper_body): the squat's
// body still sideways, its right forearm and hand swinging 10 cm sideways at 1 Hz about the
// elbow. The lateral force is then that arm's m a (forearm at its COM fraction, hand at the
// wrist), through the whole chain (the set's markers, the landmarks, the window, the force);
// lumped into the torso it is nothing. A marker the file lacks lumps its arm, and says so.
TEST(Mediolateral, AnArmOfItsOwnCarriesItsSidewaysSwing) {
  Trial t = make_synthetic_trial({});
  const Eigen::Index n = t.markers.frames();
  const auto& S = t.markers.positions_m[static_cast<std::size_t>(t.markers.find("RSHO"))];
  const double A = 0.10, w = 2 * M_PI * 1.0;
  Eigen::MatrixX3d elbow = S, wrist = S;
  for (Eigen::Index i = 0; i < n; ++i) {
    elbow(i, 2) -= 0.30;
    wrist(i, 2) -= 0.55;
    wrist(i, 1) += A * std::sin(w * t.markers.time_s[i]);
  }
  t.markers.names.insert(t.markers.names.end(), {"RELB", "RWRI"});
  t.markers.positions_m.push_back(elbow);
  t.markers.positions_m.push_back(wrist);
  MarkerSet set = *find_marker_set("kin2grf-example");
  set.upper_body[kShoulderR] = {"RSHO"};
  set.upper_body[kElbowR] = {"RELB"};
  set.upper_body[kWristR] = {"RWRI"};
  set.upper_body[kShoulderL] = {"LSHO"};
  set.upper_body[kElbowL] = {"LELB"};  // not in the file
  set.upper_body[kWristL] = {"LWRI"};
  EstimateOptions eo;
  eo.model = ModelKind::ThreeD;
  // The standing frames' frontal split (FeetSideBySideShareTheLoadByTheFrontalBalance) sees the
  // arm too; this test is the lateral force's.
  eo.frontal_split_weight = 0.0;
  const auto r = estimate(t, nullptr, set, eo);
  eo.upper_body_segments = false;
  const auto lumped = estimate(t, nullptr, set, eo);
  const auto& table = anthropometric_table(EstimateOptions{}.anthropometry);
  const double mass = total_mass(r.model());
  // The forearm's COM moves by its fraction of the wrist's swing, the hand's by all of it.
  const double swing_kg = mass * (table.forearm.mass_fraction * table.forearm.com_fraction + table.hand.mass_fraction);
  const double peak = swing_kg * A * w * w;  // about 5 N; Y is the walker's left, the lateral axis its right
  double worst = 0, lumped_worst = 0;
  for (Eigen::Index i = n / 4; i < 3 * n / 4; ++i) {
    const double expected = peak * std::sin(w * r.time_s[i]);  // -(m a) along +Y, with a = -A w^2 sin
    const double total = r.feet[0].force_lateral_N[i] + r.feet[1].force_lateral_N[i];
    worst = std::max(worst, std::abs(total - expected));
    lumped_worst = std::max(lumped_worst, std::abs(lumped.feet[0].force_lateral_N[i] + lumped.feet[1].force_lateral_N[i]));
  }
  EXPECT_GT(peak, 3.0);
  EXPECT_LT(worst, 0.1 * peak);
  EXPECT_LT(lumped_worst, 0.01 * peak);
  bool said_arm = false, said_lumped = false;
  for (const auto& m : r.messages) {
    said_arm = said_arm || m == "upper body: the right arm is a segment of its own in the lateral force";
    said_lumped = said_lumped || (m.find("elbow_l: marker LELB") != std::string::npos && m.find("lumped into the torso") != std::string::npos);
  }
  EXPECT_TRUE(said_arm);
  EXPECT_TRUE(said_lumped);
  EXPECT_EQ(r.feet[0].force_N, lumped.feet[0].force_N);  // the sagittal model keeps its HAT
}

// --mediolateral adds the lateral force and changes nothing else; without lateral motion (the
// synthetic squat) it is near zero, and the lab-frame outputs carry it.
// A two-footed landing with the feet wider than the hips (EstimateOptions::lateral_least_squares):
// the whole body has no sideways acceleration, so the split of one total gives each foot nothing,
// while the paper's least squares with the legs' 3D joint moments directs each foot's force up its
// spread leg, toward the midline: the feet push toward each other, as a landing's plates show. The
// sum stays the whole body's, the moments are those of the new forces (linearity), and quiet
// standing away from the flight keeps the split.
TEST(Mediolateral, ALandingsSpreadFeetPushTowardEachOtherByTheLeastSquares) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;  // flight 1.253-1.747 s
  Trial t = make_synthetic_trial(so);
  const int up = static_cast<int>(t.markers.up_axis);
  const int across = up == 2 ? 1 : 2;  // the trial's feet lie apart along this lab axis
  const double outward = t.markers.positions_m[t.markers.find("RHEE")](0, across) > t.markers.positions_m[t.markers.find("LHEE")](0, across) ? 1 : -1;
  for (const char* side : {"R", "L"})
    for (const char* name : {"KJC", "AJC", "HEE", "MT1", "HLX"}) {
      auto& p = t.markers.positions_m[t.markers.find(std::string(side) + name)];
      const double knee = std::string(name) == "KJC" ? 0.5 : 1.0;  // the knee half as far: a straight leg
      p.col(across).array() += (side[0] == 'R' ? 1 : -1) * outward * 0.08 * knee;
    }
  EstimateOptions o;
  o.model = ModelKind::ThreeD;
  const auto* set = find_marker_set("kin2grf-example");
  const EstimateResult ls = estimate(t, nullptr, *set, o);
  o.lateral_least_squares = false;
  const EstimateResult split = estimate(t, nullptr, *set, o);
  ASSERT_TRUE(ls.legs_3d.has_value());
  int landing = 0;
  for (Eigen::Index i = 0; i < ls.time_s.size(); ++i) {
    const double time = ls.time_s[i], fz = ls.feet[0].force_N(i, 1);
    const double sum = ls.feet[0].force_lateral_N[i] + ls.feet[1].force_lateral_N[i];
    EXPECT_NEAR(sum, split.feet[0].force_lateral_N[i] + split.feet[1].force_lateral_N[i], 1e-9) << time;
    if (time > 1.75 && time < 2.0 && fz > 400) {  // the landing's loaded frames
      ++landing;
      // The right foot's force points to the walker's left (-), the left foot's to the right (+),
      // by about the legs' spread over their length times the load (8 cm / 0.85 m x 400-600 N).
      EXPECT_LT(ls.feet[0].force_lateral_N[i], -0.04 * fz) << time;
      EXPECT_GT(ls.feet[1].force_lateral_N[i], 0.04 * fz) << time;
      EXPECT_LT(std::abs(split.feet[0].force_lateral_N[i]), 0.02 * fz) << time;
    }
    if (time < 0.7) {  // quiet standing
      EXPECT_EQ(ls.feet[0].force_lateral_N[i], split.feet[0].force_lateral_N[i]) << time;
    }
  }
  EXPECT_GT(landing, 5);
  // The moments are the new forces' own: a direct run on the same legs gives them.
  const JointMoments3D direct = joint_moments_3d(ls.legs_3d->motion, estimated_wrenches(ls));
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT((direct.knee_Nm[k] - ls.legs_3d->moments.knee_Nm[k]).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((direct.hip_lab_Nm[k] - ls.legs_3d->moments.hip_lab_Nm[k]).cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(Mediolateral, TheFrontalBalanceSharesTheLoadByTheCentreOfMassAcrossTheFeet) {
  // Still: the COP under the COM, a quarter of the way from the right foot to the left.
  EXPECT_NEAR(frontal_balance_right_share(-0.05, 0.9, 0.0, 700.0, 0.0, -0.2), 0.75, 1e-12);
  // Accelerating to +z (the lateral force +70 N at 0.9 m): the COP moves 0.09 m to -z, towards
  // the left foot.
  EXPECT_NEAR(frontal_balance_right_share(-0.05, 0.9, 70.0, 700.0, 0.0, -0.2), 0.3, 1e-12);
  // Clamped: the COP beyond a foot puts the whole load on that foot.
  EXPECT_EQ(frontal_balance_right_share(0.1, 0.9, 0.0, 700.0, 0.0, -0.2), 1.0);
  EXPECT_EQ(frontal_balance_right_share(-0.3, 0.9, 0.0, 700.0, 0.0, -0.2), 0.0);
  // Feet on one line across the plane, or no load: it cannot tell.
  EXPECT_TRUE(std::isnan(frontal_balance_right_share(0.0, 0.9, 0.0, 700.0, 0.0, -0.03)));
  EXPECT_TRUE(std::isnan(frontal_balance_right_share(0.0, 0.9, 0.0, 0.0, 0.0, -0.2)));
}

TEST(Mediolateral, FeetSideBySideShareTheLoadByTheFrontalBalance) {
  // Quiet standing with the left foot set 16 cm further out than the right: the body's centre of
  // mass stands nearer the right foot, which carries more. The sagittal model cannot see it
  // (the feet side by side: the minimum norm shares the load equally); the frontal balance can.
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;
  Trial t = make_synthetic_trial(so);
  const int up = static_cast<int>(t.markers.up_axis);
  const int across = up == 2 ? 1 : 2;
  const double outward = t.markers.positions_m[t.markers.find("LHEE")](0, across) > t.markers.positions_m[t.markers.find("RHEE")](0, across) ? 1 : -1;
  for (const char* name : {"KJC", "AJC", "HEE", "MT1", "HLX"}) {
    auto& p = t.markers.positions_m[t.markers.find(std::string("L") + name)];
    p.col(across).array() += outward * (std::string(name) == "KJC" ? 0.08 : 0.16);
  }
  const auto* set = find_marker_set("kin2grf-example");
  EstimateOptions o;
  const EstimateResult frontal = estimate(t, nullptr, *set, o);
  o.frontal_split_weight = 0.0;
  const EstimateResult sagittal = estimate(t, nullptr, *set, o);
  // The 3D model splits them alike (the example has no arms of their own to move its COM).
  EstimateOptions o3;
  o3.model = ModelKind::ThreeD;
  const EstimateResult three_d = estimate(t, nullptr, *set, o3);
  for (int k = 0; k < 2; ++k) EXPECT_LT((three_d.feet[k].force_N - frontal.feet[k].force_N).cwiseAbs().maxCoeff(), 1e-9);
  int standing = 0;
  for (Eigen::Index i = 0; i < frontal.time_s.size(); ++i) {
    const double total = frontal.feet[0].force_N(i, 1) + frontal.feet[1].force_N(i, 1);
    EXPECT_NEAR(total, sagittal.feet[0].force_N(i, 1) + sagittal.feet[1].force_N(i, 1), 1e-6 * (1 + std::abs(total))) << i;
    for (int k = 0; k < 2; ++k) {
      const double a = frontal.feet[k].cop_x_m[i], b = sagittal.feet[k].cop_x_m[i];
      EXPECT_TRUE(std::isnan(a) ? std::isnan(b) : a == b) << i;
    }
    const double time = frontal.time_s[i];
    if (time > 0.2 && time < 0.7 && total > 500) {
      ++standing;
      EXPECT_LT(std::abs(sagittal.feet[0].force_N(i, 1) - sagittal.feet[1].force_N(i, 1)), 0.05 * total) << time;
      EXPECT_GT(frontal.feet[0].force_N(i, 1), 0.6 * total) << time;
    }
  }
  EXPECT_GT(standing, 10);
  // The joint torques follow the new split (the solve's own torque maps): each ankle's moment
  // changes where its load does, and the message says how many frames were split.
  double moved = 0;
  for (Eigen::Index i = 0; i < frontal.time_s.size(); ++i)
    if (frontal.time_s[i] > 0.2 && frontal.time_s[i] < 0.7)
      moved = std::max(moved, std::abs(frontal.joint_torque_Nm(i, 2) - sagittal.joint_torque_Nm(i, 2)));
  EXPECT_GT(moved, 1.0);
  EXPECT_TRUE(said(frontal, "feet side by side"));
}

// The lateral force and the 3D moments are added to the sagittal results, which they leave as they
// are (the frontal split of feet side by side, FeetSideBySideShareTheLoadByTheFrontalBalance, acts
// in both models alike: on the example walk's quiet standing here).
TEST(Mediolateral, TheOptionChangesNoSagittalResult) {
  EstimateOptions with;
  with.mediolateral = true;
  const auto r0 = run({}), r1 = run({}, with);
  const Eigen::Index n = r0.time_s.size();
  EXPECT_EQ(r0.feet[0].force_lateral_N.size(), 0);
  ASSERT_EQ(r1.feet[0].force_lateral_N.size(), n);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(r0.feet[k].force_N, r1.feet[k].force_N);
    const Eigen::ArrayXd c0 = r0.feet[k].cop_x_m.array(), c1 = r1.feet[k].cop_x_m.array();
    EXPECT_TRUE((c0.isNaN() == c1.isNaN()).all());
    EXPECT_TRUE((c0.isNaN() || c0 == c1).all());
    EXPECT_LT(r1.feet[k].force_lateral_N.cwiseAbs().maxCoeff(), 0.01 * 70 * 9.81);
  }
  const Eigen::Index i = n / 2;
  EXPECT_NEAR(r1.frame.lateral_at(r1.first_index + i).dot(lab_foot_frame(r1, 0, i).force_N), r1.feet[0].force_lateral_N[i], 1e-9);
  // The per-frame table gains the lateral force's and the lateral COP's columns, last; without the
  // option it has none. The COP's columns are the place of the wrench the .mot and the 3D
  // moments take (lab_foot_frame), empty where the foot is not in contact, as cop_x.
  const ResultsTable t0 = results_table(r0), t1 = results_table(r1);
  ASSERT_EQ(t1.columns.size(), t0.columns.size() + 4);
  const auto col = [&](const std::string& name) {
    return std::find(t1.columns.begin(), t1.columns.end(), name) - t1.columns.begin();
  };
  EXPECT_EQ(col("grf_lateral_r_N"), t0.values.cols());
  EXPECT_EQ(t1.columns.back(), "cop_lateral_l_m");
  EXPECT_EQ(t1.values(i, col("grf_lateral_r_N")), r1.feet[0].force_lateral_N[i]);
  EXPECT_EQ(t1.values.leftCols(t0.values.cols()).row(i), t0.values.row(i));
  int in_contact = 0;
  for (Eigen::Index f = 0; f < n; ++f)
    for (int k = 0; k < 2; ++k) {
      const double lateral = t1.values(f, col(k == 0 ? "cop_lateral_r_m" : "cop_lateral_l_m"));
      const double along = t1.values(f, col(k == 0 ? "cop_x_r_m" : "cop_x_l_m"));
      ASSERT_EQ(std::isnan(lateral), std::isnan(along)) << "frame " << f << " foot " << k;
      if (std::isnan(along)) continue;
      ++in_contact;
      EXPECT_NEAR(r1.frame.lateral_at(r1.first_index + f).dot(lab_foot_frame(r1, k, f).cop_m), lateral, 1e-9);
    }
  EXPECT_GT(in_contact, n / 2);
  // The 3D model likewise: the sagittal results and the 2D joint torques unchanged, the lateral
  // force and the joint moments added.
  EstimateOptions three_d;
  three_d.model = ModelKind::ThreeD;
  const auto r3 = run({}, three_d);
  ASSERT_TRUE(r3.legs_3d.has_value());
  EXPECT_EQ(r3.joint_torque_Nm, r0.joint_torque_Nm);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(r3.feet[k].force_N, r0.feet[k].force_N);
    EXPECT_EQ(r3.feet[k].force_lateral_N.size(), n);
  }
  EXPECT_EQ(results_table(r3).columns.back(), "knee_adduction_moment_l_Nm");
}

// The same recorded walk turned about the vertical (the lab's axes no longer along the walkway, or
// the walk the other way) gives the same forces in the walker's frame: each foot's anterior,
// vertical and mediolateral forces (issue 28's frame test). A heading within 10 degrees of a lab
// axis is snapped to it (detect_sagittal_frame), so the recorded walk (along X) and its 180-degree
// turn share a snapped frame, and its 30- and 210-degree turns the walker's own heading: each pair
// agrees to round-off, and across the pairs the forces differ only by the walker's few degrees off
// the lab's axis (under 1 % body weight).
TEST(Mediolateral, AWalkTurnedAboutTheVerticalGivesTheSameForces) {
  const std::string path = std::string(KIN2GRF_SOURCE_DIR) + "/data/example/walking2.c3d";
  const Trial walk = load_trial(path);
  ASSERT_EQ(walk.markers.up_axis, Axis::Z);
  EstimateOptions eo;
  eo.mass_kg = 64.9;
  eo.mediolateral = true;
  const MarkerSet& set = *recognise_marker_set(walk.markers);
  const double bw = 64.9 * 9.81;
  const auto turned = [&](double deg) {
    Trial t = walk;
    t.markers = rotated(walk.markers, Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix(), Axis::Z);
    return estimate(t, nullptr, set, eo);
  };
  const auto difference = [](const EstimateResult& a, const EstimateResult& b) {
    double d = 0;
    for (int k = 0; k < 2; ++k)
      d = std::max({d, (a.feet[k].force_N - b.feet[k].force_N).cwiseAbs().maxCoeff(),
                    (a.feet[k].force_lateral_N - b.feet[k].force_lateral_N).cwiseAbs().maxCoeff()});
    return d;
  };
  const auto r0 = turned(0), r180 = turned(180), r30 = turned(30), r210 = turned(210);
  ASSERT_EQ(r30.time_s.size(), r0.time_s.size());
  EXPECT_LT(difference(r0, r180), 1e-3 * bw);
  EXPECT_LT(difference(r30, r210), 1e-3 * bw);
  EXPECT_LT(difference(r0, r30), 0.01 * bw);
  EXPECT_GT(r0.feet[0].force_lateral_N.cwiseAbs().maxCoeff(), 10.0);  // the force compared is there
}

// The 3D COP's lateral place (FootResult::cop_lateral_m) follows the foot's line from the heel to
// the forefoot's midline at the COP's place along it: a COP at the heel takes the heel's lateral
// coordinate, one at the MT head the forefoot's, behind the heel it stays there; past the MT
// head it turns medially by the toe slope (the push-off's roll onto the hallux), to the walker's
// left for a right foot and to the right for a left one (the lateral axis points right).
TEST(LateralCop, TheCopsLateralPlaceFollowsTheFootsLineAtItsPlaceAlongIt) {
  Eigen::MatrixX4d line(6, 4);
  line.rowwise() = Eigen::RowVector4d(0.0, 0.10, 0.20, 0.14);  // heel x, heel lat, forefoot x, forefoot lat
  Eigen::VectorXd cop(6);
  cop << 0.0, 0.10, 0.20, -0.05, std::numeric_limits<double>::quiet_NaN(), 0.24;
  const Eigen::VectorXd lat = cop_lateral_on_foot_line(line, cop);
  EXPECT_NEAR(lat[0], 0.10, 1e-12);
  EXPECT_NEAR(lat[1], 0.12, 1e-12);
  EXPECT_NEAR(lat[2], 0.14, 1e-12);
  EXPECT_NEAR(lat[3], 0.10, 1e-12);  // behind the heel: the heel's
  EXPECT_TRUE(std::isnan(lat[4]));   // no contact
  EXPECT_NEAR(lat[5], 0.14, 1e-12);  // no slope: the forefoot end's
  const Eigen::VectorXd right = cop_lateral_on_foot_line(line, cop, 0.25, 0), left = cop_lateral_on_foot_line(line, cop, 0.25, 1);
  EXPECT_NEAR(right[5], 0.14 - 0.25 * 0.04, 1e-12);  // 4 cm past the MT head: 1 cm medial
  EXPECT_NEAR(left[5], 0.14 + 0.25 * 0.04, 1e-12);
  for (Eigen::Index i : {0, 1, 2, 3}) EXPECT_EQ(right[i], lat[i]) << "only past the MT head";
  EXPECT_NEAR(right[2], left[2], 1e-15);
  // A walker going the other way along x (a line whose forefoot lies at lower x): the same.
  Eigen::MatrixX4d back(1, 4);
  back << 0.0, 0.10, -0.20, 0.14;
  EXPECT_NEAR(cop_lateral_on_foot_line(back, Eigen::VectorXd::Constant(1, -0.24), 0.25, 0)[0], 0.13, 1e-12);
  EXPECT_THROW((void)cop_lateral_on_foot_line(line.topRows(3), cop), InputError);
}

// The medial turn past the MT head reaches each foot's estimate, medial for each (the right foot's
// to -lateral, the left's to +), on the push-off frames past its MT landmark alone, and moves
// nothing sagittal.
TEST(LateralCop, EachFootsCopTurnsMediallyPastItsMtHeadInTheEstimate) {
  const Trial t = make_example_walk(kin2grf::test::walk_3d_options());
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  EstimateOptions midline, turned;
  midline.model = turned.model = ModelKind::ThreeD;
  midline.toe_medial_slope = 0.0;
  ASSERT_EQ(turned.toe_medial_slope, 0.25);  // the default
  const EstimateResult a = estimate(t, nullptr, set, midline), b = estimate(t, nullptr, set, turned);
  for (int k = 0; k < 2; ++k) {
    const FootResult &fa = a.feet[static_cast<std::size_t>(k)], &fb = b.feet[static_cast<std::size_t>(k)];
    EXPECT_EQ(fa.force_N, fb.force_N);
    for (Eigen::Index i = 0; i < fa.cop_x_m.size(); ++i)
      ASSERT_TRUE(fa.cop_x_m[i] == fb.cop_x_m[i] || (std::isnan(fa.cop_x_m[i]) && std::isnan(fb.cop_x_m[i]))) << "frame " << i;
    const Eigen::VectorXd& mt_x = a.landmarks.p[k ? kMtL : kMtR].col(0);
    int turned_frames = 0;
    for (Eigen::Index i = 0; i < fa.cop_x_m.size(); ++i) {
      if (!std::isfinite(fa.cop_x_m[i])) continue;
      const double d = fb.cop_lateral_m[i] - fa.cop_lateral_m[i], past = fa.cop_x_m[i] - mt_x[i];
      if (past < -0.002) {
        EXPECT_EQ(d, 0.0) << side_name(k) << " frame " << i << ": behind the MT head";
        continue;
      }
      if (d != 0.0) ++turned_frames;
      EXPECT_LE(d * (k == 0 ? 1.0 : -1.0), 0.0) << side_name(k) << " frame " << i << ": medial";
      EXPECT_NEAR(std::abs(d), 0.25 * std::max(0.0, past), 1e-3) << side_name(k) << " frame " << i;
    }
    EXPECT_GT(turned_frames, 3) << side_name(k) << ": the push-off reaches past the MT head";
  }
}

// A marker set's "surface": "lateral" (issue 28's landmarks): a 5th-metatarsal marker moves the
// COP's lateral line's forefoot end medially by kLateralMtToMidline of the heel-MT length, and
// lateral knee and ankle markers move the 3D joint centres medially by half the joint's width
// plus the marker's radius; the sagittal results do not change with a COP function in sole lengths
// (with the built-in one, in heel-MT lengths, the 5th-MT marker also moves the sagittal COP ahead:
// Contact.AFifthMetatarsalMarkerLengthensTheHeelToMetatarsalHeadsUnit).
TEST(LateralCop, LateralMarkersMoveTheCopLineAndTheJointCentresMediallyOnly) {
  const Trial t = make_synthetic_trial({});
  nlohmann::json j = read_json_file(std::string(KIN2GRF_SOURCE_DIR) + "/data/presets/kin2grf-example.json");
  EstimateOptions o;
  o.model = ModelKind::ThreeD;
  o.contact.cop.length = CopLength::Sole;
  const EstimateResult centre = estimate(t, nullptr, parse_marker_set(j, "centre"), o);
  for (const char* id : {"mt_r", "mt_l", "knee_r", "knee_l", "ankle_r", "ankle_l"}) j["landmarks"][id]["surface"] = "lateral";
  const EstimateResult lateral = estimate(t, nullptr, parse_marker_set(j, "lateral"), o);
  ASSERT_TRUE(centre.legs_3d && lateral.legs_3d);
  const Eigen::Index n = centre.time_s.size();
  int compared = 0;
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    EXPECT_EQ(centre.feet[k].force_N, lateral.feet[k].force_N);
    const double to_medial = side == kRight ? -1.0 : 1.0;  // along the lateral axis (the walker's right)
    double largest = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double d = lateral.feet[k].cop_lateral_m[i] - centre.feet[k].cop_lateral_m[i];
      if (!std::isfinite(d)) continue;
      ++compared;
      EXPECT_GE(d * to_medial, -1e-12) << side_name(side) << " frame " << i;  // never laterally
      largest = std::max(largest, std::abs(d));
    }
    // At most the forefoot end's whole move, kLateralMtToMidline of a heel-MT length under 0.3 m.
    EXPECT_GT(largest, 0.01) << side_name(side);
    EXPECT_LT(largest, kLateralMtToMidline * 0.30) << side_name(side);
    // The joint centres: medially, by the same offset at every frame.
    const Eigen::Vector3d dk = (lateral.legs_3d->motion.knee_m[k] - centre.legs_3d->motion.knee_m[k]).row(n / 2).transpose();
    const Eigen::Vector3d lat_axis = centre.frame.lateral_at(centre.first_index + n / 2);
    const double shank = centre.motion.model->bodies[static_cast<std::size_t>(segment(side, kShank))].length_m;
    EXPECT_NEAR(dk.dot(lat_axis) * to_medial, 0.5 * kKneeWidthPerShank * shank + 0.5 * kDefaultMarkerDiameterM, 0.005) << side_name(side);
  }
  EXPECT_GT(compared, n / 2);
  // A "surface" on a landmark that has no lateral side is refused, naming it.
  j["landmarks"]["hip"]["surface"] = "lateral";
  try {
    (void)parse_marker_set(j, "bad.json");
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'hip'"), std::string::npos) << e.what();
  }
}

namespace {
/// The options in absolute units (m/s, m, N/m) for a subject dynamically scaled by L
/// (dynamically_scaled in trial.hpp): speeds by sqrt(L), lengths by L, r (force per gap) by L^2.
/// Not the norm's lever nor the settings in seconds and hertz: the estimate scales them with the
/// subject's leg (the latter with EstimateOptions::time_scale_leg_m).
EstimateOptions dynamically_scaled_options(EstimateOptions o, double L) {
  const double t = std::sqrt(L);
  o.contact.speed_gate.floor_mps *= t;
  o.contact.speed_gate.standstill_mps *= t;
  o.contact.still_foot_rad_per_s /= t;
  o.solver.min_split_distance_m *= L;
  o.solver.r_N_per_m *= L * L;
  o.allow_unusual_mass = true;
  return o;
}

/// The RMS difference of the two feet's fore-aft forces, in body weights, of a walk and its
/// dynamically similar copy, over the frames where both of the walk's feet carry load (over 5 %
/// body weight): how far the copy's double supports are from the walk's.
double double_support_fore_aft_rms(const EstimateResult& a, const EstimateResult& b) {
  EXPECT_EQ(a.time_s.size(), b.time_s.size());
  const double wa = a.mass_kg * 9.81, wb = b.mass_kg * 9.81;
  double sum = 0;
  int both = 0;
  for (Eigen::Index i = 0; i < std::min(a.time_s.size(), b.time_s.size()); ++i) {
    if (!(a.feet[0].force_N(i, 1) > 0.05 * wa && a.feet[1].force_N(i, 1) > 0.05 * wa)) continue;
    ++both;
    for (int side = 0; side < 2; ++side) sum += std::pow(a.feet[side].force_N(i, 0) / wa - b.feet[side].force_N(i, 0) / wb, 2);
  }
  EXPECT_GT(both, 20);
  return std::sqrt(sum / (2.0 * std::max(both, 1)));
}
}  // namespace

// A subject 0.6 times the size walking the same gait (Froude similarity: a child's walk) gets the
// same ground reactions in body weights, with every setting in absolute units scaled alike: the
// multiplier norm's lever is the subject's leg length (EstimateOptions::torque_length_legs), so
// its joint torques, one length smaller than an adult's relative to its forces, weigh against the
// contact forces as an adult's do, and (when asked) its settings in seconds and hertz follow its
// gait's time scale (EstimateOptions::time_scale_leg_m). With the fixed 0.9 m lever a child's
// torques weigh too little and the double supports' fore-aft split moves; with an adult's cut-offs
// and lags its fore-aft forces are smoothed and delayed too much.
TEST(Estimate, ADynamicallySimilarSmallerSubjectSharesItsDoubleSupportsAsTheLargerOne) {
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  const SyntheticWalk walk = make_synthetic_walk({});
  constexpr double L = 0.6;
  const Trial small = dynamically_scaled(walk.trial, L);
  ASSERT_NEAR(*small.body_mass_kg, *walk.trial.body_mass_kg * L * L * L, 1e-9);
  ASSERT_NEAR(small.markers.rate_hz, walk.trial.markers.rate_hz / std::sqrt(L), 1e-9);
  const auto fore_aft_rms = [&](const EstimateOptions& o) {
    return double_support_fore_aft_rms(estimate(walk.trial, nullptr, set, o), estimate(small, nullptr, set, dynamically_scaled_options(o, L)));
  };
  EstimateOptions legs, fixed_lever, adults_times;
  legs.time_scale_leg_m = fixed_lever.time_scale_leg_m = 0.85;  // off by default: mixed on the adults
  fixed_lever.torque_length_legs = 0.0;
  adults_times.time_scale_short_leg_m = adults_times.time_scale_long_leg_m = 0.0;  // not even outside the adults' legs
  // 0.4 % body weight RMS with the leg's lever and time scale (the rest at the trailing foot's
  // last frames, its release), 3.7 % with the fixed 0.9 m lever, 1.2 % with the adults' cut-offs
  // and lags.
  EXPECT_LT(fore_aft_rms(legs), 0.006);
  EXPECT_GT(fore_aft_rms(fixed_lever), 0.025);
  EXPECT_GT(fore_aft_rms(adults_times), 0.008);
  // The time scale says what it did.
  const EstimateResult small_scaled = estimate(small, nullptr, set, dynamically_scaled_options(legs, L));
  EXPECT_TRUE(said(small_scaled, "time scale: the leg (thigh + shank) is"));
}

// The settings in seconds and hertz were chosen on subjects whose legs (thigh + shank) are
// 0.76-0.90 m: a subject within that range keeps them as given, one outside it has them scaled
// from the range's nearer end by its gait's time scale (sqrt(leg / that end)), a child's and a
// very tall subject's alike, and the message says so. With them scaled the child's double
// supports come nearer the full-size walk's than with the adults' own cut-offs and lags.
TEST(Estimate, ALegOutsideTheDevelopmentSubjectsHasTheSettingsTimeScaledFromTheNearerEnd) {
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  const SyntheticWalk walk = make_synthetic_walk({});
  const EstimateOptions defaults;
  const EstimateResult adult = estimate(walk.trial, nullptr, set, defaults);
  const double leg = leg_length_m(adult.model());
  ASSERT_GT(leg, defaults.time_scale_short_leg_m);
  ASSERT_LT(leg, defaults.time_scale_long_leg_m);
  EXPECT_FALSE(said(adult, "time scale:"));
  EXPECT_DOUBLE_EQ(adult.kinematic_cutoff_hz, defaults.kinematic_cutoff_hz);
  for (const double L : {0.6, 1.25}) {
    const Trial scaled = dynamically_scaled(walk.trial, L);
    const EstimateResult r = estimate(scaled, nullptr, set, dynamically_scaled_options(defaults, L));
    const double end = L < 1 ? defaults.time_scale_short_leg_m : defaults.time_scale_long_leg_m;
    const double f = std::sqrt(leg_length_m(r.model()) / end);
    EXPECT_NEAR(leg_length_m(r.model()), L * leg, 1e-6 * leg);
    EXPECT_TRUE(said(r, L < 1 ? "shorter than the shortest leg the settings were chosen for (0.760 m)"
                           : "longer than the longest leg the settings were chosen for (0.900 m)"))
        << L;
    EXPECT_NEAR(r.kinematic_cutoff_hz, defaults.kinematic_cutoff_hz / f, 1e-9) << L;
    // Off on both sides: as given.
    EstimateOptions off = defaults;
    off.time_scale_short_leg_m = off.time_scale_long_leg_m = 0;
    const EstimateResult as_given = estimate(scaled, nullptr, set, dynamically_scaled_options(off, L));
    EXPECT_FALSE(said(as_given, "time scale:"));
    EXPECT_DOUBLE_EQ(as_given.kinematic_cutoff_hz, defaults.kinematic_cutoff_hz);
  }
  // The child's fore-aft forces in double support, body weights, against the full-size walk's.
  const Trial small = dynamically_scaled(walk.trial, 0.6);
  const auto fore_aft_rms = [&](const EstimateOptions& o) {
    return double_support_fore_aft_rms(adult, estimate(small, nullptr, set, dynamically_scaled_options(o, 0.6)));
  };
  EstimateOptions off = defaults;
  off.time_scale_short_leg_m = 0;
  EXPECT_LT(fore_aft_rms(defaults), 0.8 * fore_aft_rms(off));
  // A short leg longer than the long one is refused, naming both.
  EstimateOptions bad = defaults;
  bad.time_scale_short_leg_m = 0.95;
  try {
    (void)estimate(walk.trial, nullptr, set, bad);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shortest unscaled leg (0.95 m"), std::string::npos) << e.what();
  }
}

// README's MATLAB section reads the CSV with readtable, which keeps a column's name as the
// table's variable only where it is a MATLAB identifier (a letter, then letters, digits and
// underscores, at most namelengthmax = 63 characters); any other it renames. Every column of the
// sagittal and the 3D model's CSV must be one, with no two alike.
TEST(Estimate, TheCsvColumnsAreMatlabIdentifiers) {
  SyntheticWalkOptions wo;
  wo.duration_s = 3.0;
  const Trial walk = make_synthetic_walk(wo).trial;
  for (const ModelKind model : {ModelKind::Sagittal, ModelKind::ThreeD}) {
    EstimateOptions o;
    o.model = model;
    const std::string csv = format_results_csv(estimate(walk, nullptr, *find_marker_set("kin2grf-example"), o));
    const std::string header = csv.substr(0, csv.find('\n'));
    std::vector<std::string> names;
    for (std::size_t a = 0; a <= header.size();) {
      const std::size_t b = std::min(header.find(',', a), header.size());
      names.push_back(header.substr(a, b - a));
      a = b + 1;
    }
    EXPECT_GT(names.size(), 40u);
    for (const std::string& n : names) {
      const bool ok = !n.empty() && n.size() <= 63 && std::isalpha(static_cast<unsigned char>(n[0])) &&
                      std::all_of(n.begin(), n.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
      EXPECT_TRUE(ok) << "'" << n << "'";
    }
    std::sort(names.begin(), names.end());
    EXPECT_EQ(std::adjacent_find(names.begin(), names.end()), names.end());
  }
}
