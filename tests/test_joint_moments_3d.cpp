// Joint moments by bottom-up Newton-Euler inverse dynamics, guarded by cases whose answer is known
// without the code: the 3D ankle, knee and hip moments (dynamics/joint_moments_3d.hpp) on the legs'
// landmarks, and the sagittal model's joint torques (dynamics/joint_moments_2d.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "kin2grf/dynamics/joint_moments_2d.hpp"
#include "kin2grf/dynamics/joint_moments_3d.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/pipeline.hpp"

using namespace kin2grf;

namespace {

Model test_model() {
  BodyGeometry g;
  g.torso = 0.5;
  g.thigh = {0.42, 0.42};
  g.shank = {0.42, 0.42};
  g.foot = {0.15, 0.15};
  g.toes = {0.05, 0.05};
  return build_model(g, 70.0, de_leva_table());
}

/// A standing pose (lab: z up, x forward, the walker's right -y), `n` frames alike. Each leg
/// upright in the plane y = -+0.1, knee 0.5 m up.
std::array<Eigen::MatrixX3d, kLandmarkCount> standing(Eigen::Index n) {
  std::array<Eigen::MatrixX3d, kLandmarkCount> p;
  auto put = [&](int id, double x, double y, double z) { p[static_cast<std::size_t>(id)] = Eigen::RowVector3d(x, y, z).replicate(n, 1); };
  put(kShoulder, 0.0, 0.0, 1.4);
  put(kHip, 0.0, 0.0, 0.92);
  for (int side = 0; side < 2; ++side) {
    const double y = side == kRight ? -0.1 : 0.1;
    put(landmark(side, kKnee), 0.0, y, 0.5);
    put(landmark(side, kAnkle), 0.0, y, 0.08);
    put(landmark(side, kHeel), -0.05, y, 0.02);
    put(landmark(side, kMt), 0.12, y, 0.02);
    put(landmark(side, kHallux), 0.17, y, 0.02);
  }
  return p;
}

Eigen::MatrixX3d constant_rows(Eigen::Index n, const Eigen::Vector3d& v) { return v.transpose().replicate(n, 1); }

/// Swinging, swaying, toed-out legs walking at 1.2 m/s (each landmark moving differently), and a
/// ground reaction whose three components and COP vary: the moving, loaded legs of the frame and
/// block tests.
struct MovingLegs {
  std::array<Eigen::MatrixX3d, kLandmarkCount> p;
  Eigen::MatrixX3d force, cop;
};
MovingLegs moving_loaded_legs(Eigen::Index n, double rate) {
  MovingLegs m{standing(n), Eigen::MatrixX3d(n, 3), Eigen::MatrixX3d(n, 3)};
  for (int k = 0; k < kLandmarkCount; ++k)
    for (Eigen::Index i = 0; i < n; ++i) {
      const double t = static_cast<double>(i) / rate, s = 0.1 * k;
      m.p[static_cast<std::size_t>(k)].row(i) +=
          Eigen::RowVector3d(1.2 * t + 0.05 * std::sin(6 * t + s), 0.02 * std::sin(3 * t + s), 0.01 * std::cos(5 * t + s));
    }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate;
    m.force.row(i) << 80 * std::sin(4 * t), 30 * std::cos(2 * t), 650 + 100 * std::sin(7 * t);
    m.cop.row(i) << 1.2 * t + 0.03, -0.08, 0.0;
  }
  return m;
}

/// Each foot under a vertical force F (N) whose COP lies d (m) medial of its knee, 5 cm ahead.
std::array<FootWrench3D, 2> vertical_force_medial_of_the_knees(const std::array<Eigen::MatrixX3d, kLandmarkCount>& p, double F, double d) {
  const Eigen::Index n = p[kKneeR].rows();
  std::array<FootWrench3D, 2> feet;
  for (int side = 0; side < 2; ++side) {
    const double medial = side == kRight ? +1.0 : -1.0;  // right: +y is medial
    const Eigen::Vector3d cop(0.05, p[static_cast<std::size_t>(landmark(side, kKnee))](0, 1) + medial * d, 0.0);
    feet[static_cast<std::size_t>(side)] =
        foot_wrench(constant_rows(n, {0, 0, F}), constant_rows(n, cop), Eigen::VectorXd::Zero(n), Eigen::Vector3d::UnitZ());
  }
  return feet;
}

}  // namespace

// A still leg standing on a vertical force whose COP lies d medial of the knee: the external
// knee adduction moment is d F on either side (the segments' weights lie in the leg's plane
// and add nothing to it), the internal one its negative; the ankle's frontal moment likewise.
TEST(JointMoments3D, AStillLegsKneeAdductionMomentIsTheForceTimesItsMedialLever) {
  const Eigen::Index n = 20;
  const auto p = standing(n);
  const Model model = test_model();
  const LegMotion3D legs = leg_motion_3d(model, p, constant_rows(n, {0, -1, 0}), Eigen::Vector3d::UnitZ(), 100.0, 6.0);
  const double F = 700.0, d = 0.03;
  const std::array<FootWrench3D, 2> feet = vertical_force_medial_of_the_knees(p, F, d);
  const JointMoments3D m = joint_moments_3d(legs, feet);
  for (int side = 0; side < 2; ++side) {
    for (Eigen::Index i = 0; i < n; ++i) {
      EXPECT_NEAR(knee_adduction_moment(m, side)[i], d * F, 1e-9) << side_name(side) << " frame " << i;
      EXPECT_NEAR(m.knee_Nm[static_cast<std::size_t>(side)](i, 1), -d * F, 1e-9);
      EXPECT_NEAR(m.ankle_Nm[static_cast<std::size_t>(side)](i, 1), -d * F, 1e-9);  // the foot's frame is level here
      EXPECT_NEAR(m.knee_Nm[static_cast<std::size_t>(side)](i, 2), 0.0, 1e-9);        // no horizontal force: no axial moment
    }
  }
  // Sagittal: the COP 5 cm ahead of the knee's vertical; the weights of shank and foot (on the
  // leg's line and ahead of it) counted from the model's masses: the internal moment balances
  // all of it, counter-clockwise + about the walker's right.
  const Body& shank = model.bodies[segment(kRight, kShank)];
  const Body& foot = model.bodies[segment(kRight, kFoot)];
  const Body& toes = model.bodies[segment(kRight, kToes)];
  const double g = model.gravity_mps2;
  const double foot_com_x = 0.12 * foot.com_local.x() / foot.length_m;
  const double toes_com_x = 0.12 + 0.05 * toes.com_local.x() / toes.length_m;
  // External moment about the knee, about the right axis (-y): for a force along z at x ahead,
  // r x F . (-y) = x F_z; gravity pulls down (F_z = -m g).
  const double external = 0.05 * F - foot.mass_kg * g * foot_com_x - toes.mass_kg * g * toes_com_x - shank.mass_kg * g * 0.0;
  EXPECT_NEAR(m.knee_Nm[0](n / 2, 0), -external, 1e-6);
}

// A leg falling freely (every landmark accelerating at g, no ground reaction) needs no joint
// force or moment.
TEST(JointMoments3D, AFreelyFallingLegNeedsNoMoment) {
  const Eigen::Index n = 60;
  auto p = standing(n);
  const double rate = 100.0, g = 9.81;
  for (auto& q : p)
    for (Eigen::Index i = 0; i < n; ++i) {
      const double t = static_cast<double>(i) / rate;
      q.row(i) += Eigen::RowVector3d(1.3 * t, 0.2 * t, 0.5 * t - 0.5 * g * t * t);
    }
  const Model model = test_model();
  const LegMotion3D legs = leg_motion_3d(model, p, constant_rows(n, {0, -1, 0}), Eigen::Vector3d::UnitZ(), rate, 0.0);
  std::array<FootWrench3D, 2> none;
  for (auto& w : none) w = {Eigen::MatrixX3d::Zero(n, 3), Eigen::MatrixX3d::Zero(n, 3)};
  const JointMoments3D m = joint_moments_3d(legs, none);
  for (int side = 0; side < 2; ++side) {
    EXPECT_LT(m.knee_Nm[static_cast<std::size_t>(side)].cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT(m.ankle_Nm[static_cast<std::size_t>(side)].cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT(m.hip_Nm[static_cast<std::size_t>(side)].cwiseAbs().maxCoeff(), 1e-9);
  }
}

// The same moving, loaded legs turned about the vertical by 30 and by 180 degrees give the same
// anatomical moments: they live in the segments' frames, not the lab's.
TEST(JointMoments3D, TurningTheLabAboutTheVerticalChangesNoMoment) {
  const Eigen::Index n = 120;
  const double rate = 100.0;
  const auto [p, force, cop] = moving_loaded_legs(n, rate);
  const Eigen::VectorXd free = 3 * Eigen::VectorXd::Ones(n);
  const Model model = test_model();
  auto moments = [&](double angle) {
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    auto turn = [&](const Eigen::MatrixX3d& m) { return Eigen::MatrixX3d(m * Rz.transpose()); };
    std::array<Eigen::MatrixX3d, kLandmarkCount> q;
    for (int k = 0; k < kLandmarkCount; ++k) q[static_cast<std::size_t>(k)] = turn(p[static_cast<std::size_t>(k)]);
    const LegMotion3D legs = leg_motion_3d(model, q, turn(constant_rows(n, {0, -1, 0})), Eigen::Vector3d::UnitZ(), rate, 8.0);
    const FootWrench3D w = foot_wrench(turn(force), turn(cop), free, Eigen::Vector3d::UnitZ());
    return joint_moments_3d(legs, {w, w});
  };
  const JointMoments3D m0 = moments(0.0), m30 = moments(M_PI / 6), m180 = moments(M_PI);
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    EXPECT_GT(m0.knee_Nm[k].cwiseAbs().maxCoeff(), 10.0);  // something to compare
    for (const JointMoments3D* m : {&m30, &m180}) {
      EXPECT_LT((m->knee_Nm[k] - m0.knee_Nm[k]).cwiseAbs().maxCoeff(), 1e-6);
      EXPECT_LT((m->ankle_Nm[k] - m0.ankle_Nm[k]).cwiseAbs().maxCoeff(), 1e-6);
      EXPECT_LT((m->hip_Nm[k] - m0.hip_Nm[k]).cwiseAbs().maxCoeff(), 1e-6);
    }
  }
}

// A landmark with undefined samples, two landmarks at one place or a ground reaction of the wrong
// length: an error naming what, never NaN moments.
TEST(JointMoments3D, DegenerateInputIsAnErrorNotNaN) {
  const Eigen::Index n = 10;
  const Model model = test_model();
  const Eigen::MatrixX3d lateral = constant_rows(n, {0, -1, 0});
  auto p = standing(n);
  p[kKneeR](3, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(leg_motion_3d(model, p, lateral, Eigen::Vector3d::UnitZ(), 100.0, 0.0), InputError);
  p = standing(n);
  p[kAnkleR] = p[kKneeR];
  try {
    leg_motion_3d(model, p, lateral, Eigen::Vector3d::UnitZ(), 100.0, 0.0);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("knee and ankle at one place"), std::string::npos) << e.what();
  }
  const LegMotion3D legs = leg_motion_3d(model, standing(n), lateral, Eigen::Vector3d::UnitZ(), 100.0, 0.0);
  std::array<FootWrench3D, 2> short_one;
  for (auto& w : short_one) w = {Eigen::MatrixX3d::Zero(n - 1, 3), Eigen::MatrixX3d::Zero(n - 1, 3)};
  EXPECT_THROW(joint_moments_3d(legs, short_one), InputError);
}

// Lateral knee and ankle markers (JointCentreOffsets): the still leg of the first test, its knee
// and ankle marked 5 and 4 cm lateral of the centres and moved back by the offsets, gives the same
// moments as the centres themselves; without the offsets the knee adduction moment grows by the
// force times the 5 cm its lever gained (the error lateral markers would make).
TEST(JointMoments3D, LateralMarkersMovedToTheJointCentresGiveTheCentresMoments) {
  const Eigen::Index n = 20;
  const auto centres = standing(n);
  auto marked = centres;
  for (int side = 0; side < 2; ++side) {
    const double lateral_y = side == kRight ? -1.0 : 1.0;  // the walker's right is -y
    marked[static_cast<std::size_t>(landmark(side, kKnee))].col(1).array() += 0.05 * lateral_y;
    marked[static_cast<std::size_t>(landmark(side, kAnkle))].col(1).array() += 0.04 * lateral_y;
  }
  const Model model = test_model();
  const Eigen::MatrixX3d lateral = constant_rows(n, {0, -1, 0});
  const double F = 700.0;
  std::array<FootWrench3D, 2> feet;
  for (int side = 0; side < 2; ++side) {
    const Eigen::Vector3d cop(0.05, centres[landmark(side, kKnee)](0, 1), 0.0);
    feet[static_cast<std::size_t>(side)] =
        foot_wrench(constant_rows(n, {0, 0, F}), constant_rows(n, cop), Eigen::VectorXd::Zero(n), Eigen::Vector3d::UnitZ());
  }
  JointCentreOffsets offsets;
  offsets.knee_m = {0.05, 0.05};
  offsets.ankle_m = {0.04, 0.04};
  const JointMoments3D truth = joint_moments_3d(leg_motion_3d(model, centres, lateral, Eigen::Vector3d::UnitZ(), 100.0, 6.0), feet);
  const JointMoments3D moved = joint_moments_3d(leg_motion_3d(model, marked, lateral, Eigen::Vector3d::UnitZ(), 100.0, 6.0, offsets), feet);
  const JointMoments3D as_marked = joint_moments_3d(leg_motion_3d(model, marked, lateral, Eigen::Vector3d::UnitZ(), 100.0, 6.0), feet);
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    // Within 0.05 N m: the marked shank leans 1 cm over its 0.42 m, so its medial direction (made
    // orthogonal to it) leans by 1.4 degrees and the centres land 0.1 mm off.
    EXPECT_LT((moved.knee_Nm[k] - truth.knee_Nm[k]).cwiseAbs().maxCoeff(), 0.05) << side_name(side);
    EXPECT_LT((moved.ankle_Nm[k] - truth.ankle_Nm[k]).cwiseAbs().maxCoeff(), 0.05) << side_name(side);
    EXPECT_NEAR(knee_adduction_moment(as_marked, side)[n / 2] - knee_adduction_moment(truth, side)[n / 2], 0.05 * F, 1.0)
        << side_name(side);
  }
}

// The estimate's summary (--json) reports each stance's knee adduction moment peaks with --model 3d:
// the largest value of the KAM column in each half of the stance.
TEST(JointMoments3D, TheSummaryReportsEachStancesKneeAdductionPeaks) {
  const Trial walk = load_trial(std::string(KIN2GRF_SOURCE_DIR) + "/data/example/walking2.c3d");
  EstimateOptions o;
  o.mass_kg = 64.9;
  o.model = ModelKind::ThreeD;
  const EstimateResult r = estimate(walk, nullptr, *recognise_marker_set(walk.markers), o);
  const nlohmann::json j = results_summary(r, nlohmann::json::object());
  ASSERT_TRUE(j.contains("knee_adduction_moment"));
  int complete = 0;
  for (int side = 0; side < 2; ++side) {
    const Eigen::VectorXd kam = knee_adduction_moment(r.legs_3d->moments, side);
    for (const auto& s : j["knee_adduction_moment"][side_name(side)]) {
      Eigen::Index a = 0, b = 0;
      while (r.time_s[a] < s["start_s"].get<double>()) ++a;
      while (r.time_s[b] < s["end_s"].get<double>()) ++b;
      const Eigen::Index mid = a + (b - a + 1) / 2;
      EXPECT_DOUBLE_EQ(s["first_peak_Nm"].get<double>(), kam.segment(a, mid - a).maxCoeff());
      EXPECT_DOUBLE_EQ(s["second_peak_Nm"].get<double>(), kam.segment(mid, b - mid + 1).maxCoeff());
      EXPECT_DOUBLE_EQ(s["first_peak_Nm_per_kg"].get<double>(), s["first_peak_Nm"].get<double>() / 64.9);
      // The impulse: the KAM's positive part over the same frames, no more than its peak times the
      // stance's duration and (an adduction moment through mid-stance) more than none.
      const double impulse = s["impulse_Nm_s"].get<double>();
      EXPECT_DOUBLE_EQ(impulse, stance_impulse(kam, r.time_s, a, b));
      EXPECT_GT(impulse, 0.0);
      EXPECT_LE(impulse, std::max(s["first_peak_Nm"].get<double>(), s["second_peak_Nm"].get<double>()) * (r.time_s[b] - r.time_s[a]));
      EXPECT_DOUBLE_EQ(s["impulse_Nm_s_per_kg"].get<double>(), impulse / 64.9);
      complete += s["complete"].get<bool>();
    }
  }
  EXPECT_GE(complete, 1);  // the walk's window holds a whole stance
  EstimateOptions sagittal;
  sagittal.mass_kg = 64.9;
  EXPECT_FALSE(results_summary(estimate(walk, nullptr, *recognise_marker_set(walk.markers), sagittal), {}).contains("knee_adduction_moment"));
}

// The KAM impulse (stance_impulse): the trapezoidal integral of the KAM's positive part. A
// half-sine of amplitude A over T integrates to 2 A T / pi; a KAM that dips below zero (an
// abduction moment at heel strike or toe-off) adds nothing there; a frame without a value drops
// the two intervals beside it; a stance without two finite neighbours has none.
TEST(JointMoments3D, TheKneeAdductionImpulseIntegratesThePositivePartOverTheStance) {
  const Eigen::Index n = 201;
  const double A = 40.0, T = 0.6;
  Eigen::VectorXd t(n), kam(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    t[i] = T * static_cast<double>(i) / static_cast<double>(n - 1);
    kam[i] = A * std::sin(M_PI * t[i] / T);
  }
  EXPECT_NEAR(stance_impulse(kam, t, 0, n - 1), 2 * A * T / M_PI, 1e-4 * A * T);
  // Half of it: the second half of the stance alone.
  EXPECT_NEAR(stance_impulse(kam, t, (n - 1) / 2, n - 1), A * T / M_PI, 1e-4 * A * T);
  // A full sine: the negative half adds nothing.
  Eigen::VectorXd full(n);
  for (Eigen::Index i = 0; i < n; ++i) full[i] = A * std::sin(2 * M_PI * t[i] / T);
  EXPECT_NEAR(stance_impulse(full, t, 0, n - 1), A * T / M_PI, 2e-3 * A * T);
  // A constant KAM over 0.6 s: its value times the duration (to round-off); one frame lost drops its two
  // intervals.
  const Eigen::VectorXd flat = Eigen::VectorXd::Constant(n, 10.0);
  EXPECT_NEAR(stance_impulse(flat, t, 0, n - 1), 10.0 * T, 1e-12);
  Eigen::VectorXd gap = flat;
  gap[100] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NEAR(stance_impulse(gap, t, 0, n - 1), 10.0 * (T - 2 * T / static_cast<double>(n - 1)), 1e-12);
  EXPECT_TRUE(std::isnan(stance_impulse(gap, t, 100, 100)));
  EXPECT_TRUE(std::isnan(stance_impulse(Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN()), t, 0, n - 1)));
}

// The hip (JointCentreOffsets::hip_half_width_m): the still leg of the first test, each hip centre
// straight above its knee (0.1 m either side of the hip landmark) and the COP d medial of the
// leg's line. The segments' weights lie in the leg's plane, so the external hip adduction moment
// is d F too (internal frontal -d F), and, without the offset, the thigh leans in to the midpoint
// and the hip's lever changes: the offset is what the hip's frontal moment reads.
TEST(JointMoments3D, AStillLegsHipAdductionMomentIsTheForceTimesItsMedialLever) {
  const Eigen::Index n = 20;
  const auto p = standing(n);
  const Model model = test_model();
  const Eigen::MatrixX3d lateral = constant_rows(n, {0, -1, 0});
  const double F = 700.0, d = 0.03;
  const std::array<FootWrench3D, 2> feet = vertical_force_medial_of_the_knees(p, F, d);
  JointCentreOffsets offsets;
  offsets.hip_half_width_m = 0.1;
  const LegMotion3D legs = leg_motion_3d(model, p, lateral, Eigen::Vector3d::UnitZ(), 100.0, 6.0, offsets);
  const JointMoments3D m = joint_moments_3d(legs, feet);
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    EXPECT_NEAR(legs.hip_m[k](0, 1), p[landmark(side, kKnee)](0, 1), 1e-12) << side_name(side);
    for (Eigen::Index i = 0; i < n; ++i) {
      EXPECT_NEAR(m.hip_Nm[k](i, 1), -d * F, 1e-9) << side_name(side) << " frame " << i;
      EXPECT_NEAR(m.hip_Nm[k](i, 2), 0.0, 1e-9);
    }
  }
  const JointMoments3D midpoint = joint_moments_3d(leg_motion_3d(model, p, lateral, Eigen::Vector3d::UnitZ(), 100.0, 6.0), feet);
  EXPECT_GT(std::abs(midpoint.hip_Nm[0](n / 2, 1) - m.hip_Nm[0](n / 2, 1)), 10.0);
}

// Made a block at a time (joint_moments_3d_in_blocks, the estimate's path when nothing keeps the
// legs' kinematics: a long trial's memory), the moments are those of the whole trial at once,
// frame for frame, blocks' edges included: the filter runs over the whole trial, and each block
// carries enough of its neighbours for the differences.
TEST(JointMoments3D, BlockByBlockGivesTheWholeTrialsMoments) {
  const Eigen::Index n = 230;
  const double rate = 100.0;
  const auto [p, force, cop] = moving_loaded_legs(n, rate);
  const FootWrench3D w = foot_wrench(force, cop, 3 * Eigen::VectorXd::Ones(n), Eigen::Vector3d::UnitZ());
  const Model model = test_model();
  const Eigen::MatrixX3d lateral = constant_rows(n, {0, -1, 0});
  JointCentreOffsets offsets;
  offsets.hip_half_width_m = 0.08;
  const JointMoments3D whole =
      joint_moments_3d(leg_motion_3d(model, p, lateral, Eigen::Vector3d::UnitZ(), rate, 8.0, offsets), {w, w});
  for (Eigen::Index block : {1, 7, 50, 229, 230, 2000}) {
    const JointMoments3D blocks = joint_moments_3d_in_blocks(model, p, lateral, Eigen::Vector3d::UnitZ(), rate, 8.0, offsets, {w, w}, block);
    for (std::size_t k = 0; k < 2; ++k) {
      ASSERT_EQ(blocks.knee_Nm[k].rows(), n);
      EXPECT_LT((blocks.knee_Nm[k] - whole.knee_Nm[k]).cwiseAbs().maxCoeff(), 1e-9) << block;
      EXPECT_LT((blocks.ankle_Nm[k] - whole.ankle_Nm[k]).cwiseAbs().maxCoeff(), 1e-9) << block;
      EXPECT_LT((blocks.hip_Nm[k] - whole.hip_Nm[k]).cwiseAbs().maxCoeff(), 1e-9) << block;
      EXPECT_LT((blocks.hip_lab_Nm[k] - whole.hip_lab_Nm[k]).cwiseAbs().maxCoeff(), 1e-9) << block;
    }
  }
  EXPECT_GT(whole.knee_Nm[0].cwiseAbs().maxCoeff(), 10.0);
}

// The estimate's two paths to the 3D moments, the legs' kinematics kept (validate) or made a block
// at a time (the command line's estimate), give the same moments on a recorded walk.
TEST(JointMoments3D, TheEstimateGivesTheSameMomentsWithOrWithoutTheLegsKinematics) {
  const Trial walk = load_trial(std::string(KIN2GRF_SOURCE_DIR) + "/data/example/walking2.c3d");
  EstimateOptions eo;
  eo.mass_kg = 64.9;
  eo.model = ModelKind::ThreeD;
  const auto& set = *recognise_marker_set(walk.markers);
  const EstimateResult kept = estimate(walk, nullptr, set, eo);
  eo.keep_all_series = false;
  const EstimateResult blocks = estimate(walk, nullptr, set, eo);
  ASSERT_TRUE(kept.legs_3d && blocks.legs_3d);
  EXPECT_GT(kept.legs_3d->motion.frames(), 0);
  EXPECT_EQ(blocks.legs_3d->motion.frames(), 0);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_LT((kept.legs_3d->moments.knee_Nm[k] - blocks.legs_3d->moments.knee_Nm[k]).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((kept.legs_3d->moments.hip_Nm[k] - blocks.legs_3d->moments.hip_Nm[k]).cwiseAbs().maxCoeff(), 1e-9);
  }
}

// ---- The sagittal joint torques, bottom-up (dynamics/joint_moments_2d.hpp) ----

namespace {

/// The estimate's own ground reaction per foot as the solve applies it, as bottom_up_joint_torques
/// takes it: at model 2's point D, which a tilted foot (heel strike, push-off) holds above the
/// floor by its gap, where the outputs' COP is on the floor.
std::array<FootWrench2D, 2> estimated_wrenches_2d(const EstimateResult& r) {
  std::array<FootWrench2D, 2> w;
  const Eigen::Index n = r.time_s.size();
  for (int side = 0; side < 2; ++side) {
    const FootResult& f = r.feet[static_cast<std::size_t>(side)];
    FootWrench2D& fw = w[static_cast<std::size_t>(side)];
    fw.force_N = Eigen::MatrixX2d::Zero(n, 2);
    fw.moment_origin_Nm = Eigen::VectorXd::Zero(n);
    for (Eigen::Index i = 0; i < n; ++i)
      if (f.contact[static_cast<std::size_t>(i)]) {
        fw.force_N.row(i) = f.force_N.row(i);
        fw.moment_origin_Nm[i] = f.cop_x_m[i] * f.force_N(i, 1) - (r.ground_level_m() + f.gap_m[i]) * f.force_N(i, 0);
      }
  }
  return w;
}

}  // namespace

// Where both feet are down, Eq. 7's four contact multipliers explain the whole body's three
// equations exactly (no residual), and the least squares' joint torques are the unique ones the
// chain's equations give: bottom-up from each foot's force, to round-off. Guards the bottom-up
// formula's subtrees, its lever arms and its sign against the multipliers' (moment on the child,
// counter-clockwise +). Every step after the solve that moves forces and torques apart from one
// frame's equations (the post-filter, the double-support transition, the touchdown rule) is off.
TEST(JointMoments2D, TheLeastSquaresTorquesAreTheBottomUpOnesWhereTheContactsExplainTheMotion) {
  const SyntheticWalk walk = make_synthetic_walk({});
  EstimateOptions o;
  o.post_cutoff_cycles = 0;
  o.post_cutoff_hz = 0;
  o.double_support_sta_weight = 0;
  o.frontal_split_weight = 0;
  o.touchdown_stop_fraction = 0;
  const EstimateResult r = estimate(walk.trial, nullptr, *recognise_marker_set(walk.trial.markers), o);
  const Eigen::MatrixXd tau = bottom_up_joint_torques(r.motion, estimated_wrenches_2d(r));
  ASSERT_EQ(tau.rows(), r.joint_torque_Nm.rows());
  int compared = 0, single = 0;
  for (Eigen::Index i = 0; i < r.time_s.size(); ++i) {
    const bool right = r.feet[0].contact[static_cast<std::size_t>(i)], left = r.feet[1].contact[static_cast<std::size_t>(i)];
    if (right && left) {
      ++compared;
      for (int j = 0; j < kJointCount; ++j) EXPECT_NEAR(tau(i, j), r.joint_torque_Nm(i, j), 1e-6) << "frame " << i << ", joint " << j;
    }
    // In single support the prescribed COP leaves a moment residual, which the least squares
    // spreads over the joints and bottom-up does not: there they differ.
    if (right != left && std::abs(frame_totals(r, i).residual.z()) > 5.0) {
      ++single;
      double largest = 0;
      for (int j = 0; j < kJointCount; ++j) largest = std::max(largest, std::abs(tau(i, j) - r.joint_torque_Nm(i, j)));
      EXPECT_GT(largest, 0.1) << "frame " << i;
    }
  }
  EXPECT_GE(compared, 20);  // the walk's double supports
  EXPECT_GE(single, 20);
}

// A leg standing still under its own weight: each joint's torque is the moment, about the joint,
// of the weight below it and of the ground's force at the COP, known without the code. The foot
// flat, the ground force straight up under the ankle plus 5 cm: the ankle carries that force's
// moment less the foot's and toes' weights' moments.
TEST(JointMoments2D, AStillLegsTorquesAreItsWeightsAndTheGroundsMoments) {
  const SyntheticWalk walk = make_synthetic_walk({});
  const EstimateResult r = estimate(walk.trial, nullptr, *recognise_marker_set(walk.trial.markers), {});
  const Model& model = r.model();
  MotionFrame m = r.motion.frame(r.time_s.size() / 2);
  m.qdd.setZero();  // at rest
  const double g = model.gravity_mps2;
  for (int side = 0; side < 2; ++side) {
    const int ankle = model.bodies[static_cast<std::size_t>(segment(side, kFoot))].proximal;
    const double ax = m.q(coord::point_x(ankle));
    const double fy = 600.0, cop_x = ax + 0.05;
    const double moment_origin = cop_x * fy;  // the force straight up, its moment about the origin
    double expected = -(cop_x - ax) * fy;      // the ground's moment about the ankle, on the foot: - of it
    for (LegSegment k : {kFoot, kToes}) {
      const int s = segment(side, k);
      expected += (m.q(coord::com_x(s)) - ax) * model.bodies[static_cast<std::size_t>(s)].mass_kg * g;
    }
    EXPECT_NEAR(bottom_up_joint_torque(model, m, 4 * side + 2, {0.0, fy}, moment_origin), expected, 1e-9) << side_name(side);
    // The MTP: the toes' weight alone; the ground acts on the foot (model 2's point D).
    const int mtp = model.bodies[static_cast<std::size_t>(segment(side, kToes))].proximal, toes = segment(side, kToes);
    EXPECT_NEAR(bottom_up_joint_torque(model, m, 4 * side + 3, {0.0, fy}, moment_origin),
                (m.q(coord::com_x(toes)) - m.q(coord::point_x(mtp))) * model.bodies[static_cast<std::size_t>(toes)].mass_kg * g, 1e-9);
  }
}

// The CSV's joint powers are each joint's torque times its angular velocity, phi_j' (the child's
// angle less the parent's, differentiated as the accelerations are: central differences of the
// filtered joint angles), and the synthetic walk's ankle generates energy at push-off (its power's
// largest value in each right stance's second half is positive: the plantarflexors shorten under
// load, the A2 burst).
TEST(JointMoments2D, TheJointPowersAreTheTorquesTimesTheJointAngularVelocities) {
  const SyntheticWalk walk = make_synthetic_walk({});
  const EstimateResult r = estimate(walk.trial, nullptr, *recognise_marker_set(walk.trial.markers), {});
  const ResultsTable t = results_table(r);
  const auto col = [&](const std::string& name) {
    const auto it = std::find(t.columns.begin(), t.columns.end(), name);
    EXPECT_NE(it, t.columns.end()) << name;
    return static_cast<Eigen::Index>(it - t.columns.begin());
  };
  const double dt = 1.0 / r.motion.rate_hz;
  for (int j = 0; j < kJointCount; ++j) {
    const Eigen::Index power = col(std::string("power_") + joint_name(j) + "_W"), torque = col(std::string("torque_") + joint_name(j) + "_Nm");
    for (Eigen::Index i = 1; i + 1 < r.time_s.size(); i += 7) {
      const double phi_dot = (r.motion.x(i + 1, 3 + j) - r.motion.x(i - 1, 3 + j)) / (2 * dt);
      EXPECT_NEAR(t.values(i, power), t.values(i, torque) * phi_dot, 1e-9 * std::max(1.0, std::abs(t.values(i, power)))) << joint_name(j) << " frame " << i;
    }
  }
  const Eigen::Index ankle = col("power_ankle_r_W");
  int stances = 0;
  for (const IndexRun& run : gait_stances(r.feet[0].contact, r.motion.rate_hz)) {
    const Eigen::Index first = run.first, last = run.last;
    if (first == 0 || last + 1 >= r.time_s.size()) continue;  // whole stances only
    ++stances;
    EXPECT_GT(t.values.col(ankle).segment((first + last) / 2, last - (first + last) / 2 + 1).maxCoeff(), 0.5 * r.mass_kg) << "stance at " << first;
  }
  EXPECT_GE(stances, 1);
}

// Each stance's joint kinetic peaks in the summary (`stance_parameters`' `joint_kinetics`) and in
// the --stances CSV: the largest of each moment in its clinical sense (plantarflexor -tau_ankle,
// knee extensor +tau_knee and hip extensor -tau_hip in the first half, hip flexor +tau_hip in the
// second) and of the ankle's power in the second half, read back from the CSV's own columns.
TEST(JointMoments2D, EachStancesKineticPeaksAreTheTorquesAndPowersPeaksInTheirSenses) {
  const SyntheticWalk walk = make_synthetic_walk({});
  const EstimateResult r = estimate(walk.trial, nullptr, *recognise_marker_set(walk.trial.markers), {});
  const ResultsTable t = results_table(r);
  const auto col = [&](const std::string& name) {
    return static_cast<Eigen::Index>(std::find(t.columns.begin(), t.columns.end(), name) - t.columns.begin());
  };
  const nlohmann::json summary = results_summary(r, nlohmann::json::object());
  const auto& stances = summary["stance_parameters"]["right"];
  ASSERT_GE(stances.size(), 2u);
  int checked = 0;
  for (const auto& s : stances) {
    if (!s["complete"].get<bool>()) continue;
    Eigen::Index a = 0, b = 0;
    while (r.time_s[a] < s["start_s"].get<double>()) ++a;
    while (r.time_s[b] < s["end_s"].get<double>()) ++b;
    const Eigen::Index mid = a + (b - a + 1) / 2;
    const auto largest = [&](Eigen::Index c, double sign, Eigen::Index from, Eigen::Index to) {
      return (sign * t.values.col(c).segment(from, to - from + 1)).maxCoeff();
    };
    const auto& k = s["joint_kinetics"];
    EXPECT_DOUBLE_EQ(k["ankle_plantarflexor_moment_Nm"].get<double>(), largest(col("torque_ankle_r_Nm"), -1, a, b));
    EXPECT_DOUBLE_EQ(k["ankle_push_off_power_W"].get<double>(), largest(col("power_ankle_r_W"), 1, mid, b));
    EXPECT_DOUBLE_EQ(k["knee_extensor_moment_Nm"].get<double>(), largest(col("torque_knee_r_Nm"), 1, a, mid - 1));
    EXPECT_DOUBLE_EQ(k["hip_extensor_moment_Nm"].get<double>(), largest(col("torque_hip_r_Nm"), -1, a, mid - 1));
    EXPECT_DOUBLE_EQ(k["hip_flexor_moment_Nm"].get<double>(), largest(col("torque_hip_r_Nm"), 1, mid, b));
    EXPECT_DOUBLE_EQ(k["ankle_push_off_power_W_per_kg"].get<double>(), k["ankle_push_off_power_W"].get<double>() / r.mass_kg);
    ++checked;
  }
  EXPECT_GE(checked, 1);
  // The --stances CSV carries them per kg, in its last five columns.
  const std::string csv = stance_parameters_csv(r);
  const std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_NE(header.find(",ankle_plantarflexor_moment_Nm_per_kg,ankle_push_off_power_W_per_kg,knee_extensor_moment_Nm_per_kg,"
                        "hip_extensor_moment_Nm_per_kg,hip_flexor_moment_Nm_per_kg"),
            std::string::npos)
      << header;
  // A moment that never acts in a sense has no peak in it (NaN, not the least negative value).
  Eigen::MatrixXd positive = Eigen::MatrixXd::Constant(r.time_s.size(), kJointCount, 10.0);
  const JointKineticPeaks none = joint_kinetic_peaks(positive, r.motion, 0, 10, 60);
  EXPECT_TRUE(std::isnan(none.ankle_plantarflexor_moment_Nm));
  EXPECT_TRUE(std::isnan(none.hip_extensor_moment_Nm));
  EXPECT_DOUBLE_EQ(none.knee_extensor_moment_Nm, 10.0);
}
