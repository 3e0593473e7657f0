// Tests of dynamics/contact: foot models, COP function, contact calibration, ground level, flight frames.
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
#include "kin2grf/markers/landmarks.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

using kin2grf::test::run;
using kin2grf::test::synthetic_landmarks;

// Running frames are told from the kinematics: near a flight the whole body's vertical force
// sum m (a_y + g) falls to about zero (free fall); standing, squatting and walking never do.
TEST(Contact, FlightFramesAreFoundFromTheKinematicsAlone) {
  SyntheticOptions so;
  so.squat_depth = 0.0;
  so.flight_height_m = 0.3;  // flight 1.253-1.747 s
  const Trial t = make_synthetic_trial(so);
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  ModelMotion mm = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
  const auto run = flight_frames(r.model(), mm, r.calibration.contact);
  ASSERT_EQ(run.size(), static_cast<std::size_t>(mm.frames()));
  for (Eigen::Index i = 0; i < mm.frames(); ++i) {
    const double time = mm.time_s[i];
    if (time > 1.3 && time < 1.7) {
      EXPECT_TRUE(run[static_cast<std::size_t>(i)]) << time;  // in the flight
    } else if (time < 0.7 || time > 2.3) {
      EXPECT_FALSE(run[static_cast<std::size_t>(i)]) << time;  // far from it
    }
  }
  // The speed gate's floor holds near the flight alone (SpeedGateRule::floor_mps), whatever COP
  // function the frames take: the estimate says on how many frames.
  for (const bool running_cop : {true, false}) {
    EstimateOptions o;
    if (!running_cop) o.contact.running_cop.reset();
    const auto e = estimate(t, nullptr, *find_marker_set("kin2grf-example"), o);
    EXPECT_NEAR(e.calibration.flight_speed_gate_mps, 0.75, 1e-12);
    EXPECT_LT(e.calibration.speed_gate_mps, 0.75);
    const std::string near = std::to_string(std::count(run.begin(), run.end(), true)) + " frames near a flight phase";
    bool said = false;
    for (const auto& m : e.messages) said = said || (m.find("contact speed gate") != std::string::npos && m.find(near) != std::string::npos);
    EXPECT_TRUE(said) << running_cop;
  }
  for (const double depth : {0.0, 1.0}) {  // quiet standing and squats: never
    SyntheticOptions sq;
    sq.squat_depth = depth;
    const Trial ts = make_synthetic_trial(sq);
    const auto rs = estimate(ts, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
    ModelMotion ms = compute_motion(rs.model(), synthetic_landmarks(ts), 6.0);
    const auto none = flight_frames(rs.model(), ms, rs.calibration.contact);
    EXPECT_EQ(std::count(none.begin(), none.end(), true), 0) << depth;
  }
}

// A fast walk's mid-stance dip (UWA's 2 m/s walk: the kinematic force sum falls to 0.10 body
// weight, its plate to 0.26) is not a flight: the stance foot stays on the ground. Here squats at
// 2.5 Hz with both feet flat (deep and fast enough that m (a_y + g) falls below 0.2 body weight,
// as the force sum alone shows) must give no running frame.
TEST(Contact, ADeepDipWithAFootOnTheGroundIsNotAFlight) {
  SyntheticOptions so;
  so.squat_depth = 1.0;
  so.squat_period_s = 0.4;
  const Trial t = make_synthetic_trial(so);
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  ModelMotion mm = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
  const auto by_force_alone = flight_frames(r.model(), mm, r.calibration.contact, 0.2, 0.4, -1e9);
  ASSERT_GT(std::count(by_force_alone.begin(), by_force_alone.end(), true), 0) << "the bounce must dip below 0.2 body weight";
  const auto run = flight_frames(r.model(), mm, r.calibration.contact);
  EXPECT_EQ(std::count(run.begin(), run.end(), true), 0);
}

// Model 2's COP function (Eq. 2): constant outside the event angles, through each event's
// position, continuous, and (for the defaults and the paper's) never moving back toward the heel.
TEST(Contact, CopFractionPassesThroughTheEventsAndStaysMonotone) {
  for (const CopFunction& F : {CopFunction{}, CopFunction::paper(), CopFunction::running()}) {
    EXPECT_DOUBLE_EQ(F.fraction(F.delta_hs - 1.0), F.s_hs);
    EXPECT_DOUBLE_EQ(F.fraction(F.delta_to + 1.0), F.s_to);
    EXPECT_NEAR(F.fraction(F.delta_hs), F.s_hs, 1e-12);
    EXPECT_NEAR(F.fraction(F.delta_ho), F.s_ho, 1e-12);
    EXPECT_NEAR(F.fraction(F.delta_mo), F.s_mo, 1e-12);
    EXPECT_NEAR(F.fraction(F.delta_to), F.s_to, 1e-12);
    double last = F.fraction(-2.0);
    for (double th = -2.0; th <= 2.0; th += 1e-3) {
      const double s = F.fraction(th);
      EXPECT_GE(s, last - 1e-12) << th;
      EXPECT_LT(std::abs(s - last), 0.01) << "a jump at " << th;  // continuous at 1 mrad steps
      last = s;
    }
  }
}

// The contact calibration (Sect. 2.3) puts A and B on the floor under the heel and MT landmarks in
// the foot-flat frames; a foot that never stands on the floor takes the other foot's soles.
TEST(Contact, CalibrationPutsTheSolesOnTheFloorInFlatFrames) {
  SyntheticOptions so;
  const Trial t = make_synthetic_trial(so);
  const SagittalLandmarks lm = synthetic_landmarks(t);
  const ContactCalibration cal = calibrate_contact(lm, 0.0);
  EXPECT_TRUE(cal.message.empty()) << cal.message;
  for (int side = 0; side < 2; ++side) {
    ASSERT_GE(cal.flat_frames[static_cast<std::size_t>(side)], 10) << side;
    const auto& fg = cal.feet[static_cast<std::size_t>(side)];
    for (Eigen::Index i = 0; i < lm.frames(); i += 25) {
      const Eigen::Vector2d a = lm.p[landmark(side, kAnkle)].row(i).transpose(), m = lm.p[landmark(side, kMt)].row(i).transpose();
      const Eigen::Matrix2d R = rotation(std::atan2(m.y() - a.y(), m.x() - a.x()));
      const Eigen::Vector2d A = a + R * fg.heel_local, B = a + R * fg.mt_local;
      EXPECT_NEAR(A.y(), 0.0, 2e-3) << "side " << side << " frame " << i;  // the squat keeps its feet flat
      EXPECT_NEAR(B.y(), 0.0, 2e-3) << "side " << side << " frame " << i;
      EXPECT_NEAR(A.x(), lm.p[landmark(side, kHeel)](i, 0), 2e-3);
      EXPECT_NEAR(B.x(), m.x(), 2e-3);
    }
  }
  SyntheticOptions hop;
  hop.left_leg_raised_rad = 0.6;
  const ContactCalibration one = calibrate_contact(synthetic_landmarks(make_synthetic_trial(hop)), 0.0);
  EXPECT_NE(one.message.find("left foot never stands on the floor"), std::string::npos) << one.message;
  EXPECT_EQ(one.feet[1].heel_local, one.feet[0].heel_local);
  EXPECT_EQ(one.feet[1].flat_angle_rad, one.feet[0].flat_angle_rad);
}

// The foot-flat reference is the angle the foot rests at, whatever share of the flat frames it is
// still turning in (EstimateOptions' contact.still_foot_rad_per_s). A walk whose foot rests briefly
// and rises slowly onto its toes within the 15 mm band (a trial cut to its stances has fewer
// frames at rest): the flat frames' median is pulled into the heel rise, the still frames' is not.
TEST(Contact, TheFootFlatReferenceIsTheAngleTheFootRestsAt) {
  constexpr double rate = 1000.0, theta0 = -0.30, L = 0.16, marker = 0.02;
  const Eigen::Vector2d heel_from_mt(-(L * std::cos(theta0) + 0.07), 0.0);  // heel and MT markers level at rest
  auto walk = [&](double rest_s) {
    // One cycle: rest; a heel rise about the MT at 1 rad/s (the heel 13 mm up after 60 ms); the
    // lift, still turning; the swing (the angle back to theta0, out of the band); a flat descent.
    const double rise = 0.08, lift = 0.1, swing = 0.2, descent = 0.1, cycle = rest_s + rise + lift + swing + descent;
    const auto n = static_cast<Eigen::Index>(4 * cycle * rate);
    SagittalLandmarks lm;
    lm.rate_hz = rate;
    lm.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1) / rate);
    for (auto& p : lm.p) p = Eigen::MatrixX2d::Zero(n, 2);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double t = std::fmod(lm.time_s[i], cycle);
      double theta = theta0, h = 0.0;  // h: the MT marker's rise
      if (t >= rest_s && t < rest_s + rise + lift) theta = theta0 - (t - rest_s);
      if (t >= rest_s + rise && t < rest_s + rise + lift) h = 0.1 * (t - rest_s - rise) / lift;
      if (t >= rest_s + rise + lift && t < rest_s + rise + lift + swing) {
        const double u = (t - rest_s - rise - lift) / swing;
        theta = theta0 - (rise + lift) * (1 - u), h = 0.1;
      }
      if (t >= cycle - descent) h = 0.1 * (cycle - t) / descent;
      const Eigen::Vector2d M(1.0 * lm.time_s[i], marker + h);
      const Eigen::Vector2d A = M - L * Eigen::Vector2d(std::cos(theta), std::sin(theta));
      const Eigen::Vector2d E = M + rotation(theta - theta0) * heel_from_mt;
      const Eigen::Vector2d T = M + rotation(theta - theta0) * Eigen::Vector2d(0.05, 0.0);
      for (int side = 0; side < 2; ++side) {
        lm.p[landmark(side, kMt)].row(i) = M.transpose();
        lm.p[landmark(side, kAnkle)].row(i) = A.transpose();
        lm.p[landmark(side, kHeel)].row(i) = E.transpose();
        lm.p[landmark(side, kHallux)].row(i) = T.transpose();
      }
    }
    return lm;
  };
  for (double rest_s : {0.04, 0.4}) {
    const SagittalLandmarks lm = walk(rest_s);
    const ContactCalibration still = calibrate_contact(lm, 0.0, 0.5), flat = calibrate_contact(lm, 0.0, 0.0);
    for (int side = 0; side < 2; ++side) {
      EXPECT_NEAR(still.feet[static_cast<std::size_t>(side)].flat_angle_rad, theta0, 3e-3) << "rest " << rest_s << " s";
      EXPECT_GE(flat.flat_frames[static_cast<std::size_t>(side)], still.flat_frames[static_cast<std::size_t>(side)]);
    }
    if (rest_s < 0.1) EXPECT_LT(flat.feet[0].flat_angle_rad, theta0 - 8e-3) << "the flat frames alone: pulled into the heel rise";
    else EXPECT_NEAR(flat.feet[0].flat_angle_rad, theta0, 3e-3) << "a long rest: both rules agree";
  }
}

// The ground level: the lab floor (0) when the flat-stance landmarks stand 0-150 mm above it,
// otherwise the lowest of them (a raised walkway, a floor below the origin), with a message.
TEST(Contact, GroundLevelIsTheLabFloorUnlessTheFeetSayOtherwise) {
  const SagittalLandmarks lm = synthetic_landmarks(make_synthetic_trial({}));
  auto lifted = [&](double dy) {
    SagittalLandmarks l = lm;
    for (auto& p : l.p) p.col(1).array() += dy;
    return l;
  };
  double lowest = 1e9;
  for (int side = 0; side < 2; ++side) lowest = std::min(lowest, lm.p[landmark(side, kMt)].col(1).minCoeff());
  const GroundLevel floor = estimate_ground_level(lm);
  EXPECT_EQ(floor.level_m, 0.0);
  EXPECT_NE(floor.message.find("lab floor"), std::string::npos) << floor.message;
  EXPECT_EQ(estimate_ground_level(lifted(0.10)).level_m, 0.0) << "still within 150 mm";
  const GroundLevel raised = estimate_ground_level(lifted(0.50));
  EXPECT_NEAR(raised.level_m, 0.50 + lowest, 0.01) << "a raised walkway";
  EXPECT_NE(raised.message.find("lowest of them"), std::string::npos) << raised.message;
  EXPECT_NEAR(estimate_ground_level(lifted(-0.30)).level_m, -0.30 + lowest, 0.01) << "the origin above the floor";
}

// Model 2's COP follows the body over the foot (kin2grf's centre-of-mass term, session 46): in one
// frame, the same foot at the same angle with the body's centre of mass moved forward puts the COP
// further along the sole by the gain times the move in sole lengths; with a gain of 0 (the
// paper's function) it stays where the angle puts it. The failure it guards: a foot-flat in
// which the body rolls over the foot while the angle, and with it the COP, stands still.
TEST(Contact, TheCopFollowsTheBodysCentreOfMassOverTheFoot) {
  const Trial t = make_synthetic_trial({});
  const auto r = run({});
  const Model& model = r.model();
  const ModelMotion motion = compute_motion(model, synthetic_landmarks(t), 6.0);
  double mass = 0.0;
  for (const Body& b : model.bodies) mass += b.mass_kg;
  const double shift = 0.05, com_shift = model.bodies[kTorso].mass_kg / mass * shift;  // the torso moved 5 cm forward
  for (const CopFunction& F : {CopFunction{}, CopFunction::paper()}) {
    ContactModelOptions co;
    co.cop = F;
    co.running_cop.reset();
    int compared = 0;
    for (Eigen::Index i = 0; i < motion.frames(); i += 11) {
      MotionFrame f0 = motion.frame(i), f1 = f0;
      f1.q(coord::com_x(kTorso)) += shift;
      EXPECT_NEAR(whole_body_com(model, f1).x() - whole_body_com(model, f0).x(), com_shift, 1e-12);
      FrameContacts c0, c1;
      contact_frame(model, r.calibration.contact, co, false, f0, c0);
      contact_frame(model, r.calibration.contact, co, false, f1, c1);
      for (int side = 0; side < 2; ++side) {
        const auto& sp = c0.sole[static_cast<std::size_t>(side)];
        const double L = cop_length_m(F.length, r.calibration.contact.feet[static_cast<std::size_t>(side)], (sp[1] - sp[0]).norm(),
                                      (sp[2] - sp[1]).norm());
        const double s0 = c0.cop_fraction[side], s1 = c1.cop_fraction[side];
        if (s0 <= 0.0 || s1 >= 1.25 || s0 >= 1.25) continue;  // at the sole's ends the fraction is held
        ++compared;
        EXPECT_NEAR(s1 - s0, F.com_gain * com_shift / L, 1e-12) << "frame " << i << " side " << side;
        const double dx = c1.points[static_cast<std::size_t>(side)].position.x() - c0.points[static_cast<std::size_t>(side)].position.x();
        if (F.com_gain > 0) EXPECT_GT(dx, 0.0) << "frame " << i << " side " << side;
        else EXPECT_EQ(dx, 0.0) << "frame " << i << " side " << side;
      }
    }
    EXPECT_GE(compared, 20);
  }
  EXPECT_GT(CopFunction{}.com_gain, 0.0);  // the default has the term
}

// The built-in walking function counts the COP's place in heel-to-MT-heads lengths (CopLength::
// HeelMt, session 47): a toe marker placed further along the toes does not move the COP behind the
// MT head, where the paper's sole lengths move it with the toe; and a 5th-metatarsal MT marker
// (which lies behind the 2nd head) lengthens the unit by mt_head_ahead_share of the ankle-MT
// length, as the 2nd head lies that far ahead of it. The failure it guards: one foot's COP placed
// 2-3 cm apart by two labs' toe markers, in the stance phases the toes do not carry.
TEST(Contact, TheCopIsCountedInHeelToMetatarsalHeadLengthsNotTheToeMarkers) {
  const Trial t = make_synthetic_trial({});
  const auto r = run({});
  const Model& model = r.model();
  SagittalLandmarks lm = synthetic_landmarks(t);
  const ModelMotion motion = compute_motion(model, lm, 6.0);
  // The calibration's unit: |AB|, plus the share of the ankle-MT length for a 5th-MT marker.
  const ContactCalibration plain = calibrate_contact(lm, r.ground_level_m());
  lm.mt_head_ahead_share = {0.2, 0.0};
  const ContactCalibration lateral = calibrate_contact(lm, r.ground_level_m());
  const auto& fp = plain.feet[0];
  EXPECT_NEAR(fp.heel_mt_length_m, (fp.mt_local - fp.heel_local).norm(), 1e-12);
  const double ankle_mt = model.bodies[kFootR].length_m;  // the foot segment: ankle to MT head
  EXPECT_NEAR(lateral.feet[0].heel_mt_length_m - fp.heel_mt_length_m, 0.2 * ankle_mt, 0.01 * ankle_mt);
  EXPECT_EQ(lateral.feet[1].heel_mt_length_m, plain.feet[1].heel_mt_length_m);
  // Toes twice as long: the heel-MT function's COP stays put behind B; the sole function's moves.
  ContactCalibration long_toes = r.calibration.contact;
  for (auto& f : long_toes.feet) f.hallux_local *= 2.0;
  // B 30 mm further ahead (a lateral marker's allowance): the COP moves forward by s x 30 mm.
  ContactCalibration longer_unit = r.calibration.contact;
  for (auto& f : longer_unit.feet) f.heel_mt_length_m += 0.03;
  int behind_b = 0;
  for (CopLength length : {CopLength::HeelMt, CopLength::Sole}) {
    ContactModelOptions co;
    co.cop = CopFunction{};
    co.cop.length = length;
    co.cop.com_gain = 0.0;  // the angle's place alone (the centre-of-mass term, in metres, does not change with the unit)
    co.running_cop.reset();
    for (Eigen::Index i = 0; i < motion.frames(); i += 7) {
      MotionFrame f = motion.frame(i);
      FrameContacts c0, c1, c2;
      contact_frame(model, r.calibration.contact, co, false, f, c0);
      contact_frame(model, long_toes, co, false, f, c1);
      contact_frame(model, longer_unit, co, false, f, c2);
      for (int side = 0; side < 2; ++side) {
        const auto k = static_cast<std::size_t>(side);
        const auto& sp = c0.sole[k];
        const double s = c0.cop_fraction[side], l1 = (sp[1] - sp[0]).norm();
        const double x0 = c0.points[k].position.x(), x1 = c1.points[k].position.x(), x2 = c2.points[k].position.x();
        if (length == CopLength::HeelMt) {
          if (s * r.calibration.contact.feet[k].heel_mt_length_m >= l1 || s <= 0.0 || s >= 1.25) continue;  // on the rear foot only
          ++behind_b;
          EXPECT_EQ(x1, x0) << "frame " << i << " side " << side;
          EXPECT_NEAR(x2 - x0, s * 0.03 * (sp[1].x() - sp[0].x()) / l1, 1e-12) << "frame " << i << " side " << side;
        } else if (s > 0.05) {
          EXPECT_GT(x1 - x0, 1e-3) << "the sole's length follows the toe marker; frame " << i << " side " << side;
          EXPECT_EQ(x2, x0) << "the sole function does not read the heel-MT length";
        }
      }
    }
  }
  EXPECT_GE(behind_b, 20);
}

// The landmark stage marks a set's 5th-metatarsal MT marker ("surface": "lateral") for the
// calibration, and only that side's unit lengthens.
TEST(Contact, AFifthMetatarsalMarkerLengthensTheHeelToMetatarsalHeadsUnit) {
  const Trial walk = make_example_walk();
  MarkerSet set = *find_marker_set("kin2grf-example");
  const auto plain = estimate(walk, nullptr, set, EstimateOptions{});
  set.rules[static_cast<std::size_t>(landmark(kLeft, kMt))].lateral_surface = true;
  const auto lateral = estimate(walk, nullptr, set, EstimateOptions{});
  const auto& p = plain.calibration.contact.feet, &l = lateral.calibration.contact.feet;
  EXPECT_EQ(l[kRight].heel_mt_length_m, p[kRight].heel_mt_length_m);
  EXPECT_NEAR(l[kLeft].heel_mt_length_m - p[kLeft].heel_mt_length_m, kLateralMtToeExtraShare * plain.model().bodies[kFootL].length_m,
              0.02 * plain.model().bodies[kFootL].length_m);
  EXPECT_NEAR(p[kLeft].heel_mt_length_m, (p[kLeft].mt_local - p[kLeft].heel_local).norm(), 1e-12);
}

// The pipeline makes each frame's contacts as it solves the frame, reusing one FrameContacts and
// one MotionFrame: they are a fresh frame's to the bit (the reused FrameContacts keeps no point
// of the frame before), and D* goes into the reused frame as into a fresh one.
TEST(Contact, EachFramesContactsAreAFreshFramesBitForBit) {
  const Trial t = make_synthetic_trial({});
  const auto r = run({});
  for (FootModel model : {FootModel::Cop, FootModel::ThreePoint}) {
    ContactModelOptions co;
    co.foot_model = model;
    const ModelMotion motion = compute_motion(r.model(), synthetic_landmarks(t), 6.0);
    const auto all = test::contact_frames(r.model(), r.calibration.contact, co, motion);  // fresh per frame
    FrameContacts fc;
    MotionFrame f;
    for (Eigen::Index i = 0; i < motion.frames(); i += 7) {
      motion.frame(i, f);
      contact_frame(r.model(), r.calibration.contact, co, false, f, fc);
      const FrameContacts& ref = all.contacts[static_cast<std::size_t>(i)];
      ASSERT_EQ(fc.points.size(), ref.points.size()) << i;
      ASSERT_EQ(fc.points.size(), model == FootModel::Cop ? 2u : 6u);
      for (std::size_t j = 0; j < fc.points.size(); ++j) {
        EXPECT_EQ(fc.points[j].side, ref.points[j].side);
        EXPECT_EQ(fc.points[j].position, ref.points[j].position);
        EXPECT_EQ(fc.points[j].velocity, ref.points[j].velocity);
        EXPECT_EQ(fc.points[j].gap_m, ref.points[j].gap_m);
      }
      EXPECT_EQ(fc.foot_inclination_rad, ref.foot_inclination_rad);
      const MotionFrame& kept = all.frames[static_cast<std::size_t>(i)];
      EXPECT_EQ(f.q, kept.q) << i;
      EXPECT_EQ(f.qdd, kept.qdd) << i;
    }
  }
}

namespace {

/// A foot's lowest sole point at 200 Hz as the pipeline sees it: the true height (m) filtered
/// without lag at 6 Hz, its rate by central differences; the speed along the ground is the true
/// one (fast in swing, 0 once landed).
struct SoleSeries {
  Eigen::VectorXd gap, rate, speed;
  std::vector<int> point;
  double rate_hz = 200.0;
};

SoleSeries filtered_sole(const Eigen::VectorXd& height, const Eigen::VectorXd& speed) {
  SoleSeries s;
  s.gap = butterworth_filtfilt(height, s.rate_hz, 6.0);
  const Eigen::Index n = height.size();
  s.rate = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 1; i + 1 < n; ++i) s.rate[i] = (s.gap[i + 1] - s.gap[i - 1]) * s.rate_hz / 2;
  s.speed = speed;
  s.point.assign(static_cast<std::size_t>(n), 0);
  return s;
}

/// The first frame after the last landing frame (-1: none).
Eigen::Index landed_frame(const std::vector<bool>& landing) {
  for (Eigen::Index i = static_cast<Eigen::Index>(landing.size()) - 1; i >= 0; --i)
    if (landing[static_cast<std::size_t>(i)]) return i + 1;
  return -1;
}

LandingRule rule_at(double fraction) {
  LandingRule r;
  r.fraction = fraction;
  r.swing_speed_mps = 1.0;
  return r;
}

}  // namespace

// A heel landing at 0.3 m/s of descent: the zero-lag filtered descent speed passes half its
// pre-impact value at the impact, so the rule at 0.5 lands the foot within 10 ms of it; at 1.0
// (from the peak) before it; the frames before stay free of load.
TEST(Contact, ALandingFootTakesNoLoadBeforeItsDescentHasStopped) {
  const Eigen::Index n = 400, impact = 200;  // 2 s at 200 Hz, impact at 1 s
  Eigen::VectorXd h(n), v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i - impact) / 200.0;
    h[i] = t < 0 ? std::min(0.3 * -t, 0.06) : 0.0;  // 6 cm up, then down at 0.3 m/s to the floor
    v[i] = t < 0 ? 1.5 : 0.0;
  }
  const SoleSeries s = filtered_sole(h, v);
  const Eigen::Index half = landed_frame(landing_frames(s.gap, s.rate, s.speed, s.point, rule_at(0.5)));
  EXPECT_NEAR(static_cast<double>(half), static_cast<double>(impact), 2.0);
  const Eigen::Index peak = landed_frame(landing_frames(s.gap, s.rate, s.speed, s.point, rule_at(1.0)));
  EXPECT_LT(peak, impact);
  EXPECT_GT(peak, impact - 20);  // within 100 ms: the filter's reach
  // Without the rule (fraction 0) nothing is held back.
  const auto none = landing_frames(s.gap, s.rate, s.speed, s.point, rule_at(0.0));
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);
}

// A swing foot whose descent slows to a hover 10-12 mm up for 260 ms (still sinking, as
// PiG_Motion3's left foot does) before its final approach lands at the final approach, not when
// the hover slows its descent.
TEST(Contact, AFootHoveringBeforeItsFinalApproachLandsAtTheApproach) {
  const Eigen::Index n = 300, impact = 150;  // impact at 0.75 s
  Eigen::VectorXd h(n), v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / 200.0, ti = static_cast<double>(impact) / 200.0;
    if (t < 0.3) h[i] = 0.06;
    else if (t < 0.46) h[i] = 0.06 - 0.3 * (t - 0.3);                  // down at 0.3 m/s to 12 mm
    else if (t < ti - 0.03) h[i] = 0.012 - 0.002 * (t - 0.46) / 0.26;  // the hover, sinking 2 mm
    else h[i] = t < ti ? 0.010 * (ti - t) / 0.03 : 0.0;                // the final approach, 0.33 m/s
    v[i] = t < ti ? 1.5 : 0.0;
  }
  const SoleSeries s = filtered_sole(h, v);
  const Eigen::Index landed = landed_frame(landing_frames(s.gap, s.rate, s.speed, s.point, rule_at(0.5)));
  EXPECT_GT(landed, impact - 8);  // not at the hover (from frame 92 on)
  EXPECT_LE(landed, impact + 4);
}

// A planted foot (never in swing) whose lowest point sinks 15 mm as it rolls is not landing;
// nor is a landed foot whose lowest point then switches to the forefoot slapping down, nor one
// that settles slowly after a fast drop.
TEST(Contact, APlantedFootsDescentsAreNotLandings) {
  const Eigen::Index n = 300;
  Eigen::VectorXd h(n), still = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) h[i] = -0.015 * std::clamp((static_cast<double>(i) - 100) / 60.0, 0.0, 1.0);
  const SoleSeries planted = filtered_sole(h, still);
  const auto none = landing_frames(planted.gap, planted.rate, planted.speed, planted.point, rule_at(0.5));
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);

  // A 2 m/s drop landing at frame 100, then 60 mm/s of settling for 100 ms in the same descent,
  // then (frame 220 on) the forefoot (point B) slapping down at 0.5 m/s.
  Eigen::VectorXd d(n), v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i - 100) / 200.0;
    d[i] = t < 0 ? std::min(2.0 * -t, 0.3) : -0.06 * std::min(t, 0.1);
    if (i >= 220) d[i] -= 0.5 * std::min((static_cast<double>(i) - 220) / 200.0, 0.02);
    v[i] = t < 0 ? 1.5 : 0.0;
  }
  SoleSeries s = filtered_sole(d, v);
  for (Eigen::Index i = 220; i < n; ++i) s.point[static_cast<std::size_t>(i)] = 1;
  const auto landing = landing_frames(s.gap, s.rate, s.speed, s.point, rule_at(0.5));
  const Eigen::Index landed = landed_frame(landing);
  EXPECT_NEAR(static_cast<double>(landed), 100.0, 3.0);  // the drop, not the settling or the slap
}

namespace {
// A heel that comes down at 0.6 m/s from 6 cm and stops on the floor (5 cm up, the marker's
// height) at `impact`, the MT head 2 cm up and still; 200 Hz. Raw: the rule filters them itself.
struct Heights {
  Eigen::VectorXd heel, mt;
};
Heights landing_heights(Eigen::Index n, Eigen::Index impact) {
  Heights h{Eigen::VectorXd(n), Eigen::VectorXd::Constant(n, 0.02)};
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i - impact) / 200.0;
    h.heel[i] = 0.05 + (t < 0 ? std::min(0.6 * -t, 0.06) : 0.0);
  }
  return h;
}
std::vector<bool> contact_from(Eigen::Index n, Eigen::Index first, Eigen::Index last) {
  std::vector<bool> c(static_cast<std::size_t>(n), false);
  for (Eigen::Index i = first; i <= last; ++i) c[static_cast<std::size_t>(i)] = true;
  return c;
}
}  // namespace

// Issue 29: a contact the solve begins 40 ms before the heel arrives carries nothing until the
// heel, seen at 15 Hz, has stopped; frames after the stop, and a contact that begins after it,
// keep what the solve gave them.
TEST(Contact, AFootInContactBeforeItsHeelHasStoppedHasNotLandedYet) {
  const Eigen::Index n = 400, impact = 200;
  const Heights h = landing_heights(n, impact);
  TouchdownStopRule rule;
  rule.fraction = 0.1;
  const auto before = frames_before_touchdown(contact_from(n, impact - 8, impact + 120), h.heel, h.mt, 200.0, rule);
  const auto flagged = std::count(before.begin(), before.end(), true);
  EXPECT_TRUE(before[static_cast<std::size_t>(impact - 8)]);
  EXPECT_GE(flagged, 6);   // the filtered stop lies within a few frames of the impact
  EXPECT_LE(flagged, 12);
  for (Eigen::Index i = impact + 5; i < n; ++i) EXPECT_FALSE(before[static_cast<std::size_t>(i)]) << i;
  // A landing from a flight phase is left as solved.
  const std::vector<bool> flight(static_cast<std::size_t>(n), true);
  const auto ran = frames_before_touchdown(contact_from(n, impact - 8, impact + 120), h.heel, h.mt, 200.0, rule, flight);
  EXPECT_EQ(std::count(ran.begin(), ran.end(), true), 0);
  // Contact beginning once the heel is down: nothing to hold back.
  const auto late = frames_before_touchdown(contact_from(n, impact + 6, impact + 120), h.heel, h.mt, 200.0, rule);
  EXPECT_EQ(std::count(late.begin(), late.end(), true), 0);
  // Off: nothing.
  rule.fraction = 0.0;
  const auto off = frames_before_touchdown(contact_from(n, impact - 8, impact + 120), h.heel, h.mt, 200.0, rule);
  EXPECT_EQ(std::count(off.begin(), off.end(), true), 0);
}

// A heel that brakes before it lands (Plug-in Gait's flat-foot walker, session 34): it comes down at
// 1.4 m/s, brakes within 40 ms to 0.15 m/s 10 mm above the floor and sinks on at that speed for
// 70 ms before it stops. Slowed to under a tenth of its approach, it is still descending faster
// than the slowest landing approach (0.1 m/s): it has not landed until it stops, and the contact
// the solve begins 100 ms before that carries nothing until then.
TEST(Contact, AHeelThatBrakesAndSinksOnHasNotLandedUntilItStops) {
  const Eigen::Index n = 400, impact = 200;
  Heights h{Eigen::VectorXd(n), Eigen::VectorXd::Constant(n, 0.02)};
  const auto descent = [](double t) {  // m/s at time t (s) from the stop
    if (t >= 0) return 0.0;
    if (t >= -0.07) return 0.15;
    if (t >= -0.11) return 0.15 + (1.4 - 0.15) * (-0.07 - t) / 0.04;
    return 1.4;
  };
  h.heel[n - 1] = 0.05;
  for (Eigen::Index i = n - 2; i >= 0; --i) {
    const double t = static_cast<double>(i - impact) / 200.0;
    h.heel[i] = std::min(h.heel[i + 1] + descent(t) / 200.0, 0.2);
  }
  TouchdownStopRule rule;
  rule.fraction = 0.1;
  const auto before = frames_before_touchdown(contact_from(n, impact - 20, impact + 120), h.heel, h.mt, 200.0, rule);
  const auto flagged = std::count(before.begin(), before.end(), true);
  // The whole sinking (14 frames) is held back, not only the approach before the brake.
  for (Eigen::Index i = impact - 20; i < impact - 3; ++i) EXPECT_TRUE(before[static_cast<std::size_t>(i)]) << i;
  EXPECT_GE(flagged, 17);
  EXPECT_LE(flagged, 24);
  for (Eigen::Index i = impact + 4; i < n; ++i) EXPECT_FALSE(before[static_cast<std::size_t>(i)]) << i;
}

// A slow walker (issue 29's held-out 0.36 m/s walk): the heel comes down at 0.08 m/s and the solve's
// contact begins 250 ms before it stops. The rule's fixed window (150 ms) and least descent
// (0.1 m/s) miss it; scaled to the walker's 1.8 s stance (touchdown_stop_rule: x 2.4) it holds the
// load back to within a few frames of the stop. A normal walk's stance keeps the fixed values.
TEST(Contact, ASlowWalkersLandingIsFoundOnItsOwnTimeScale) {
  const Eigen::Index n = 600, impact = 300;
  Heights h{Eigen::VectorXd(n), Eigen::VectorXd::Constant(n, 0.02)};
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i - impact) / 200.0;
    h.heel[i] = 0.05 + (t < 0 ? std::min(0.08 * -t, 0.06) : 0.0);
  }
  const auto contact = contact_from(n, impact - 50, impact + 300);
  const auto fixed = frames_before_touchdown(contact, h.heel, h.mt, 200.0, touchdown_stop_rule(0.1, std::nullopt));
  EXPECT_EQ(std::count(fixed.begin(), fixed.end(), true), 0);
  const auto slow = frames_before_touchdown(contact, h.heel, h.mt, 200.0, touchdown_stop_rule(0.1, 1.8));
  const auto flagged = std::count(slow.begin(), slow.end(), true);
  EXPECT_GE(flagged, 44);  // the 50 frames before the stop, give or take the 15 Hz filter's spread
  EXPECT_LE(flagged, 56);
  for (Eigen::Index i = impact + 8; i < n; ++i) EXPECT_FALSE(slow[static_cast<std::size_t>(i)]) << i;
  // A normal walk's stance, or none: the rule's own values.
  const TouchdownStopRule base, normal = touchdown_stop_rule(0.1, 0.7), none = touchdown_stop_rule(0.1, std::nullopt),
                                scaled = touchdown_stop_rule(0.1, 1.5);
  EXPECT_EQ(normal.window_s, base.window_s);
  EXPECT_EQ(normal.min_descent_mps, base.min_descent_mps);
  EXPECT_EQ(none.window_s, base.window_s);
  EXPECT_DOUBLE_EQ(scaled.window_s, 2 * base.window_s);
  EXPECT_DOUBLE_EQ(scaled.min_descent_mps, 0.5 * base.min_descent_mps);
  EXPECT_EQ(scaled.fraction, 0.1);
}

// A foot that did not come down (a standing foot, a stance at the window's first frame, a foot
// set down slower than a landing) is never held back, however high its landmarks: with no
// descent seen there is no evidence that it has not landed.
TEST(Contact, AFootThatDidNotComeDownIsNeverHeldBack) {
  const Eigen::Index n = 300;
  TouchdownStopRule rule;
  rule.fraction = 0.1;
  const Eigen::VectorXd still = Eigen::VectorXd::Constant(n, 0.05), mt = Eigen::VectorXd::Constant(n, 0.02);
  const auto a = frames_before_touchdown(contact_from(n, 0, 150), still, mt, 200.0, rule);
  const auto b = frames_before_touchdown(contact_from(n, 100, 250), still, mt, 200.0, rule);
  EXPECT_EQ(std::count(a.begin(), a.end(), true) + std::count(b.begin(), b.end(), true), 0);
  // Set down at 5 cm/s: below the least descent of a landing.
  Eigen::VectorXd slow(n);
  for (Eigen::Index i = 0; i < n; ++i) slow[i] = 0.05 + std::max(0.0, 0.05 * static_cast<double>(150 - i) / 200.0);
  const auto c = frames_before_touchdown(contact_from(n, 140, 250), slow, mt, 200.0, rule);
  EXPECT_EQ(std::count(c.begin(), c.end(), true), 0);
  // Heights with a gap (NaN) give no flags rather than a guess.
  Eigen::VectorXd gap = landing_heights(n, 150).heel;
  gap[20] = std::numeric_limits<double>::quiet_NaN();
  const auto d = frames_before_touchdown(contact_from(n, 142, 250), gap, mt, 200.0, rule);
  EXPECT_EQ(std::count(d.begin(), d.end(), true), 0);
}

// kin2grf's contact is with one level floor: a foot that carries weight far above it (a box, a
// step, a stair) or a body held up while neither foot is in contact (a chair, a handrail) is
// named, with the frames; a foot's impact a few centimetres up for a few frames and a flight
// (the kinematics asking nothing of the ground) are not.
TEST(Contact, SupportTheFloorDoesNotExplainIsNamed) {
  const double rate_hz = 100.0, weight_N = 700.0;
  const Eigen::Index n = 100;
  std::array<FootResult, 2> feet;
  for (FootResult& f : feet) {
    f.force_N = Eigen::MatrixX2d::Zero(n, 2);
    f.gap_m = Eigen::VectorXd::Constant(n, 0.002);
    f.contact.assign(static_cast<std::size_t>(n), true);
  }
  Eigen::VectorXd ask = Eigen::VectorXd::Constant(n, weight_N);
  // The right foot on a 17 cm step for rows 10-29 (the file's frames 11-30, 0.2 s), carrying half the
  // body weight.
  for (Eigen::Index i = 10; i < 30; ++i) {
    feet[0].force_N(i, 1) = 0.5 * weight_N;
    feet[0].gap_m[i] = 0.17;
  }
  // The left foot's impact 7 cm up for 5 rows (a run's landing reads so): not a step.
  for (Eigen::Index i = 40; i < 45; ++i) {
    feet[1].force_N(i, 1) = 1.5 * weight_N;
    feet[1].gap_m[i] = 0.07;
  }
  // Rows 50-61: neither foot in contact while the kinematics ask 0.7 body weights (held up).
  // Rows 62-89: neither in contact and the kinematics ask 0.1 (a flight): nothing to say.
  for (Eigen::Index i = 50; i < 90; ++i)
    for (FootResult& f : feet) {
      f.contact[static_cast<std::size_t>(i)] = false;
      f.gap_m[i] = 0.3;
    }
  ask.segment(50, 12).setConstant(0.7 * weight_N);
  ask.segment(62, 28).setConstant(0.1 * weight_N);
  const auto notes = support_notes(feet, ask, weight_N, rate_hz, 0.0, 1);
  ASSERT_EQ(notes.size(), 2u) << ::testing::PrintToString(notes);
  EXPECT_NE(notes[0].find("right foot: carries up to 0.50 body weights while its sole stands 170-170 mm above the floor"),
            std::string::npos)
      << notes[0];
  EXPECT_NE(notes[0].find("frames 11-30 (0.20 s)"), std::string::npos) << notes[0];
  EXPECT_NE(notes[1].find("frames 51-62 (0.12 s): the body's kinematics ask 0.70-0.70 body weights of the ground, yet neither foot"),
            std::string::npos)
      << notes[1];
  // Shorter than a tenth of a second, or under the height: nothing.
  for (Eigen::Index i = 19; i < 30; ++i) feet[0].gap_m[i] = 0.04;  // 9 frames left at 17 cm
  ask.segment(50, 12).setConstant(0.1 * weight_N);
  ask.segment(50, 9).setConstant(0.7 * weight_N);
  EXPECT_TRUE(support_notes(feet, ask, weight_N, rate_hz, 0.0, 1).empty());
}

// End to end: a squat on a 17 cm step with the floor held at the lab's 0 (--ground-level 0), as a
// stair trial's upper step stands; the same squat on the floor says nothing.
TEST(Contact, ASquatOnAStepAboveTheFloorIsNamed) {
  for (const double step_m : {0.0, 0.17}) {
    SyntheticOptions so;
    so.squat_depth = 1.0;
    Trial t = make_synthetic_trial(so);
    for (auto& p : t.markers.positions_m) p.col(2).array() += step_m;
    EstimateOptions o;
    o.ground_level_m = 0.0;
    const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), o);
    int said = 0;
    for (const auto& m : r.messages) said += m.find("mm above the floor (0.000 m), frames 1-") != std::string::npos;
    EXPECT_EQ(said, step_m > 0 ? 2 : 0) << step_m << ::testing::PrintToString(r.messages);
  }
}
