#include "kin2grf/dynamics/contact.hpp"

#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/numeric.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace kin2grf {

double speed_gate_for(const SpeedGateRule& rule, double v, bool near_flight) {
  if (rule.ratio <= 0) return std::max(0.0, rule.fixed_mps);
  return std::max(near_flight ? rule.floor_mps : rule.standstill_mps, rule.ratio * std::abs(v));
}

namespace {

/// Material point of body s at lab position X this frame: its velocity, acceleration and the
/// Jacobian rows of its x and y with respect to q (through the proximal landmark and theta_s).
struct MaterialPoint {
  Eigen::Vector2d v, a;
  ContactJacobian jx, jy;
};

MaterialPoint material_point(const Model& model, const MotionFrame& m, int s, const Eigen::Vector2d& X) {
  const int P = model.bodies[s].proximal;
  const Eigen::Vector2d rP = m.q.segment<2>(coord::point_x(P));
  const Eigen::Vector2d vP = m.qd.segment<2>(coord::point_x(P));
  const Eigen::Vector2d aP = m.qdd.segment<2>(coord::point_x(P));
  const double w = m.qd(coord::theta(s)), al = m.qdd(coord::theta(s));
  const Eigen::Vector2d d = X - rP;
  MaterialPoint mp;
  mp.v = vP + w * perp(d);
  mp.a = aP + al * perp(d) - w * w * d;
  mp.jx.add(coord::point_x(P), 1.0);
  mp.jx.add(coord::theta(s), -d.y());
  mp.jy.add(coord::point_x(P) + 1, 1.0);
  mp.jy.add(coord::theta(s), d.x());
  return mp;
}

}  // namespace

std::array<Eigen::Vector2d, 3> sole_points(const ContactCalibration& soles, const MotionFrame& m, int side) {
  const int foot = segment(side, kFoot), toes = segment(side, kToes);
  const int ankle = landmark(side, kAnkle), mt = landmark(side, kMt);
  const Eigen::Vector2d rA = m.q.segment<2>(coord::point_x(ankle));
  const Eigen::Vector2d rM = m.q.segment<2>(coord::point_x(mt));
  const Eigen::Matrix2d Rf = rotation(m.q(coord::theta(foot)));
  const Eigen::Matrix2d Rt = rotation(m.q(coord::theta(toes)));
  const auto& fg = soles.feet[static_cast<std::size_t>(side)];
  return {rA + Rf * fg.heel_local, rA + Rf * fg.mt_local, rM + Rt * fg.hallux_local};
}

Eigen::VectorXd vertical_force_sum_N(const Model& model, const ModelMotion& m) {
  const Eigen::Index n = m.frames();
  Eigen::VectorXd out(n);
  MotionFrame f;
  for (Eigen::Index i = 0; i < n; ++i) {
    m.frame(i, f);
    double fy = 0;
    for (int s = 0; s < kSegmentCount; ++s)
      fy += model.bodies[static_cast<std::size_t>(s)].mass_kg * (f.qdd(coord::com_x(s) + 1) + model.gravity_mps2);
    out[i] = fy;
  }
  return out;
}

std::vector<bool> flight_frames(const Model& model, const ModelMotion& m, const ContactCalibration& soles, double flight_fraction,
                                double window_s, double clearance_m) {
  return flight_frames(model, m, soles, vertical_force_sum_N(model, m), flight_fraction, window_s, clearance_m);
}

std::vector<bool> flight_frames(const Model& model, const ModelMotion& m, const ContactCalibration& soles, const Eigen::VectorXd& fy,
                                double flight_fraction, double window_s, double clearance_m) {
  const Eigen::Index n = m.frames();
  if (fy.size() != n) throw std::invalid_argument("flight_frames: one vertical force sum per frame");
  double mass = 0;
  for (const Body& b : model.bodies) mass += b.mass_kg;
  const double limit = flight_fraction * mass * model.gravity_mps2;
  std::vector<bool> flight(static_cast<std::size_t>(n), false), out(static_cast<std::size_t>(n), false);
  MotionFrame f;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(fy[i] < limit)) continue;
    m.frame(i, f);
    bool airborne = true;
    for (int side = 0; side < 2 && airborne; ++side)
      for (const Eigen::Vector2d& p : sole_points(soles, f, side)) airborne = airborne && p.y() - soles.ground_level_m > clearance_m;
    flight[static_cast<std::size_t>(i)] = airborne;
  }
  const Eigen::Index w = static_cast<Eigen::Index>(std::lround(window_s * m.rate_hz));
  Eigen::Index last = -1 - w;  // the latest flight frame at or before i
  for (Eigen::Index i = 0; i < n; ++i) {
    if (flight[static_cast<std::size_t>(i)]) last = i;
    if (i - last <= w) out[static_cast<std::size_t>(i)] = true;
  }
  Eigen::Index next = n + w;  // the earliest flight frame at or after i
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    if (flight[static_cast<std::size_t>(i)]) next = i;
    if (next - i <= w) out[static_cast<std::size_t>(i)] = true;
  }
  return out;
}

void contact_frame(const Model& model, const ContactCalibration& soles, const ContactModelOptions& o, bool running, MotionFrame& f,
                   FrameContacts& fc) {
  const double ground = soles.ground_level_m + o.ground_shift_m;
  fc.points.clear();
  // Model 2's COP function, and the body's centre of mass its term reads: one per frame.
  const CopFunction& F = running && o.running_cop ? *o.running_cop : o.cop;
  const double com_x = o.foot_model == FootModel::Cop && F.com_gain != 0.0 ? whole_body_com(model, f).x() : 0.0;
  for (int side = 0; side < 2; ++side) {
    const int foot = segment(side, kFoot), toes = segment(side, kToes);
    const auto sp = sole_points(soles, f, side);
    fc.sole[static_cast<std::size_t>(side)] = sp;
    const double theta = f.cop_foot_angle_rad[static_cast<std::size_t>(side)];
    fc.foot_inclination_rad[side] =
        -((std::isnan(theta) ? f.q(coord::theta(foot)) : theta) - soles.feet[static_cast<std::size_t>(side)].flat_angle_rad);
    if (o.touchdown_fraction > 0) {
      // The lowest sole point and its velocity (A, B on the foot, C on the toes): only the
      // touchdown rule reads them, so the per-frame solve does not pay for them otherwise.
      const std::size_t k = sp[0].y() <= sp[1].y() && sp[0].y() <= sp[2].y() ? 0 : sp[1].y() <= sp[2].y() ? 1 : 2;
      fc.lowest_gap_m[static_cast<std::size_t>(side)] = sp[k].y() - ground;
      fc.lowest_point[static_cast<std::size_t>(side)] = static_cast<int>(k);
      const Eigen::Vector2d v = material_point(model, f, k < 2 ? foot : toes, sp[k]).v;
      fc.lowest_gap_rate_mps[static_cast<std::size_t>(side)] = v.y();
      fc.lowest_velocity_x_mps[static_cast<std::size_t>(side)] = v.x();
    }
    if (o.foot_model == FootModel::ThreePoint) {
      for (int k = 0; k < 3; ++k) {
        const MaterialPoint mp = material_point(model, f, k < 2 ? foot : toes, sp[k]);
        ContactPoint cp;
        cp.side = side;
        cp.position = sp[k];
        cp.velocity = mp.v;
        cp.gap_m = sp[k].y() - ground;
        cp.jac_normal = mp.jy;
        cp.jac_tangent = mp.jx;
        fc.points.push_back(std::move(cp));
      }
      continue;
    }
    // Model 2: D at arc fraction s of A -> B -> C, at the lowest sole point's height (Eq. 2); s
    // counted in the function's length (CopLength), at most kMaxCopFraction sole lengths.
    const double l1 = (sp[1] - sp[0]).norm(), l2 = (sp[2] - sp[1]).norm();
    const double unit = cop_length_m(F.length, soles.feet[static_cast<std::size_t>(side)], l1, l2);
    const double com_place = F.com_gain != 0.0 && unit > 0 ? (com_x - sp[0].x()) / unit : 0.0;
    const double s = F.fraction(fc.foot_inclination_rad[side], com_place);
    fc.cop_fraction[side] = s;
    const double along = std::min(s * unit, kMaxCopFraction * (l1 + l2));
    const Eigen::Vector2d on = along <= l1 ? sp[0] + (sp[1] - sp[0]) * (l1 > 0 ? along / l1 : 0.0)
                                           : sp[1] + (sp[2] - sp[1]) * (l2 > 0 ? (along - l1) / l2 : 0.0);
    const double yD = std::min({sp[0].y(), sp[1].y(), sp[2].y()});
    const Eigen::Vector2d D(on.x(), yD);
    // D* is the foot's material point at D.
    const MaterialPoint mp = material_point(model, f, foot, D);
    const int c = coord::dstar_x(side);
    f.q.segment<2>(c) = D;
    f.qd.segment<2>(c) = mp.v;
    f.qdd.segment<2>(c) = mp.a;
    ContactPoint cp;
    cp.side = side;
    cp.position = D;
    cp.velocity = mp.v;
    cp.gap_m = D.y() - ground;
    cp.jac_normal.add(c + 1, 1.0);
    cp.jac_tangent.add(c, 1.0);
    fc.points.push_back(std::move(cp));
  }
}

std::vector<bool> landing_frames(const Eigen::VectorXd& gap, const Eigen::VectorXd& rate, const Eigen::VectorXd& speed,
                                 const std::vector<int>& point, const LandingRule& rule) {
  const Eigen::Index n = gap.size();
  std::vector<bool> out(static_cast<std::size_t>(n), false);
  if (!(rule.fraction > 0)) return out;
  // A foot is away (in swing) once its lowest sole point has moved along the ground faster than
  // the swing speed since it last landed; only an away foot lands.
  bool away = false;
  Eigen::Index seen = 0;  // frames before this have been looked at for the away state
  const auto look_until = [&](Eigen::Index last) {
    for (; seen <= last; ++seen)
      if (!(rule.swing_speed_mps > 0) || speed[seen] > rule.swing_speed_mps) away = true;
  };
  // Descents of one sole point: a switch of the lowest point (the forefoot slapping down after a
  // heel strike) begins a new run; a pause slower than kPause does not end one (a hovering swing
  // foot's filtered rate ripples by a few mm/s about zero before its final approach).
  constexpr double kPause = 0.01;  // m/s
  std::vector<IndexRun> runs;
  for (const IndexRun& r : runs_where(n, [&](Eigen::Index i) { return rate[i] < kPause; })) {
    Eigen::Index first = r.first;
    for (Eigen::Index i = r.first + 1; i <= r.last + 1; ++i)
      if (i > r.last || point[static_cast<std::size_t>(i)] != point[static_cast<std::size_t>(first)]) runs.push_back({first, i - 1}), first = i;
  }
  for (const IndexRun& run : runs) {
    look_until(run.last);
    if (!away) continue;
    const double drop = gap[run.first] - gap.segment(run.first, run.last - run.first + 1).minCoeff();
    if (!(drop >= rule.min_drop_m)) continue;
    // The final approach's peak: the last local peak of the descent speed that is an approach (a
    // swing foot's descent can slow and speed up again before the final approach; a landed
    // foot's slow settling after it is not one).
    const double least =
        std::max(rule.min_speed_mps, rule.min_peak_share * -rate.segment(run.first, run.last - run.first + 1).minCoeff());
    Eigen::Index peak = -1;
    for (Eigen::Index i = run.last; i >= run.first && peak < 0; --i) {
      const double d = -rate[i];
      if (d >= least && (i == run.first || d >= -rate[i - 1]) && (i == run.last || d >= -rate[i + 1])) peak = i;
    }
    if (peak < 0) continue;
    Eigen::Index landed = peak;
    while (landed <= run.last && -rate[landed] > rule.fraction * -rate[peak]) ++landed;
    for (Eigen::Index i = run.first; i < landed; ++i) out[static_cast<std::size_t>(i)] = true;
    away = false;
    seen = landed;
  }
  return out;
}

std::vector<bool> frames_before_touchdown(const std::vector<bool>& contact, const Eigen::VectorXd& heel_height_m, const Eigen::VectorXd& mt_height_m,
                                          double rate_hz, const TouchdownStopRule& rule, const std::vector<bool>& near_flight) {
  const auto n = static_cast<Eigen::Index>(contact.size());
  std::vector<bool> out(contact.size(), false);
  if (!(rule.fraction > 0) || !(rate_hz > 0) || n < 3 || heel_height_m.size() != n || mt_height_m.size() != n) return out;
  const double cutoff = std::min(rule.cutoff_hz, 0.9 * max_zero_lag_cutoff_hz(rate_hz));
  const auto w = std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::lround(rule.window_s * rate_hz)));
  struct Landmark {
    Eigen::VectorXd y, descent;  // height (filtered) and descent speed (m/s, + down)
    double floor = 0.0;
  };
  std::array<Landmark, 2> lm;
  for (int k = 0; k < 2; ++k) {
    const Eigen::VectorXd& raw = k == 0 ? heel_height_m : mt_height_m;
    if (!raw.allFinite()) return out;
    Landmark& l = lm[static_cast<std::size_t>(k)];
    l.y = butterworth_filtfilt(raw, rate_hz, cutoff);
    l.descent.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index a = std::max<Eigen::Index>(0, i - 1), b = std::min<Eigen::Index>(n - 1, i + 1);
      l.descent[i] = -(l.y[b] - l.y[a]) * rate_hz / static_cast<double>(b - a);
    }
    std::vector<double> h(l.y.data(), l.y.data() + n);
    std::nth_element(h.begin(), h.begin() + n / 10, h.end());
    l.floor = h[static_cast<std::size_t>(n / 10)];
  }
  const auto landed = [&](Eigen::Index i) {
    for (const Landmark& l : lm) {
      if (l.y[i] > l.floor + rule.height_band_m) continue;
      const double peak = l.descent.segment(std::max<Eigen::Index>(0, i - w), std::min(w, i) + 1).maxCoeff();
      // Stopped: slowed to a fraction of the approach, and no longer sinking as fast as a landing
      // approaches (a heel that brakes from 1.4 m/s to 0.11 m/s a few mm above its floor and sinks
      // on at that speed for 70 ms has not yet landed).
      if (peak >= rule.min_descent_mps && l.descent[i] <= std::min(rule.fraction * peak, rule.min_descent_mps)) return true;
    }
    return false;
  };
  for (Eigen::Index a = 1; a < n; ++a) {
    if (!contact[static_cast<std::size_t>(a)] || contact[static_cast<std::size_t>(a - 1)] || flag_at(near_flight, a)) continue;
    Eigen::Index end = a;  // the run's end, or the window's
    while (end < n && end - a <= w && contact[static_cast<std::size_t>(end)]) ++end;
    Eigen::Index i = a;
    while (i < end && !landed(i)) ++i;
    if (i == end) continue;  // no landing seen: the solve's contact stands
    for (Eigen::Index k = a; k < i; ++k) out[static_cast<std::size_t>(k)] = true;
  }
  return out;
}

TouchdownStopRule touchdown_stop_rule(double fraction, std::optional<double> stance_s) {
  TouchdownStopRule rule;
  rule.fraction = fraction;
  if (stance_s && *stance_s > kTouchdownNormalStanceS) {
    const double scale = *stance_s / kTouchdownNormalStanceS;
    rule.window_s *= scale;
    rule.min_descent_mps /= scale;
  }
  return rule;
}

void BeltVelocitySamples::add(const FrameContacts& fc) {
  for (const auto& p : fc.points)
    if (p.gap_m < 0.01) v_mps.push_back(p.velocity.x());
}

std::optional<double> BeltVelocitySamples::median_mps() const {
  if (v_mps.empty()) return std::nullopt;
  return median(v_mps);
}

}  // namespace kin2grf

namespace kin2grf {

namespace {
double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}
std::vector<Eigen::Index> flat_frames(const SagittalLandmarks& lm, int side) {
  const auto& E = lm.p[landmark(side, kHeel)];
  const auto& M = lm.p[landmark(side, kMt)];
  std::vector<double> he(E.col(1).data(), E.col(1).data() + E.rows()), hm(M.col(1).data(), M.col(1).data() + M.rows());
  const double te = percentile(he, 0.10) + 0.015, tm = percentile(hm, 0.10) + 0.015;
  std::vector<Eigen::Index> f;
  for (Eigen::Index i = 0; i < lm.frames(); ++i)
    if (E(i, 1) < te && M(i, 1) < tm) f.push_back(i);
  return f;
}
/// Median, 0 for no samples (a foot with no flat frames keeps a neutral calibration).
double median_or_zero(std::vector<double> v) { return v.empty() ? 0.0 : median(std::move(v)); }
/// Of the flat frames, those where the foot is also still: its angle (ankle -> MT) turning slower
/// than still_rad_per_s (0: every flat frame), at the dynamics' 6 Hz. The height band admits the
/// end of the landing's foot slap and the start of the heel rise (15 mm over a 200 mm foot is 4
/// degrees), whose share of the flat frames, and with it their median angle, depends on how much of
/// the trial is stance: a trial cut to its plate stances moved one foot's reference by 2 degrees and
/// its COP rRMSE from 6 to 13 %. The foot at rest is the reference pose; fewer than 3 still frames
/// keep the flat ones.
std::vector<Eigen::Index> still_frames(const SagittalLandmarks& lm, int side, const std::vector<Eigen::Index>& flat,
                                       double still_rad_per_s) {
  if (!(still_rad_per_s > 0)) return flat;
  const auto& A = lm.p[landmark(side, kAnkle)];
  const auto& M = lm.p[landmark(side, kMt)];
  const Eigen::Index n = lm.frames();
  if (n < 3 || !(lm.rate_hz > 0) || !A.allFinite() || !M.allFinite()) return flat;
  Eigen::VectorXd theta(n);
  for (Eigen::Index i = 0; i < n; ++i) theta[i] = std::atan2(M(i, 1) - A(i, 1), M(i, 0) - A(i, 0));
  const double cutoff = std::min(kStillFootCutoffHz, 0.9 * max_zero_lag_cutoff_hz(lm.rate_hz));
  const Eigen::VectorXd smooth = butterworth_filtfilt(theta, lm.rate_hz, cutoff);
  std::vector<Eigen::Index> out;
  for (Eigen::Index i : flat) {
    const Eigen::Index a = std::max<Eigen::Index>(0, i - 1), b = std::min<Eigen::Index>(n - 1, i + 1);
    if (std::abs(smooth[b] - smooth[a]) * lm.rate_hz / static_cast<double>(b - a) < still_rad_per_s) out.push_back(i);
  }
  return out.size() >= 3 ? out : flat;
}
}  // namespace

ContactCalibration calibrate_contact(const SagittalLandmarks& lm, double ground_level, double still_foot_rad_per_s) {
  ContactCalibration cal;
  cal.ground_level_m = ground_level;
  std::array<double, 2> heel_height{};
  // Heel landmarks stand 20-90 mm above the floor in foot-flat stance. When both feet's flat
  // frames stand higher than kMaxHeelHeight, neither foot stands on this floor in the window:
  // the soles are placed kNominalHeelHeight below the heel landmarks instead of being drawn
  // down to the floor (which would invent a stance).
  constexpr double kMaxHeelHeight = 0.15, kNominalHeelHeight = 0.04;
  std::array<double, 2> sole{ground_level, ground_level};
  {
    std::array<double, 2> h{};
    for (int side = 0; side < 2; ++side) {
      std::vector<double> hh;
      for (auto i : flat_frames(lm, side)) hh.push_back(lm.p[landmark(side, kHeel)](i, 1));
      h[static_cast<std::size_t>(side)] = median_or_zero(hh);
    }
    if (std::min(h[0], h[1]) - ground_level > kMaxHeelHeight) {
      for (int side = 0; side < 2; ++side) sole[static_cast<std::size_t>(side)] = h[static_cast<std::size_t>(side)] - kNominalHeelHeight;
      cal.message = "neither foot stands on the floor in the processed window (heel landmarks " +
                    std::to_string(static_cast<int>(1000 * (std::min(h[0], h[1]) - ground_level))) +
                    " mm above it at their lowest): soles placed " + std::to_string(static_cast<int>(1000 * kNominalHeelHeight)) +
                    " mm below the heel landmarks";
    }
  }
  for (int side = 0; side < 2; ++side) {
    const double ground = sole[static_cast<std::size_t>(side)];
    const auto f = still_frames(lm, side, flat_frames(lm, side), still_foot_rad_per_s);
    cal.flat_frames[static_cast<std::size_t>(side)] = static_cast<int>(f.size());
    const auto& A = lm.p[landmark(side, kAnkle)];
    const auto& E = lm.p[landmark(side, kHeel)];
    const auto& M = lm.p[landmark(side, kMt)];
    const auto& T = lm.p[landmark(side, kHallux)];
    std::vector<double> ang, ax, ay, bx, by, cx, cy;
    for (auto i : f) {
      const Eigen::Vector2d a = A.row(i).transpose(), e = E.row(i).transpose(), m = M.row(i).transpose(), t = T.row(i).transpose();
      const double thf = std::atan2(m.y() - a.y(), m.x() - a.x());
      const double tht = std::atan2(t.y() - m.y(), t.x() - m.x());
      ang.push_back(thf);
      const Eigen::Vector2d la = rotation(-thf) * (Eigen::Vector2d(e.x(), ground) - a);
      const Eigen::Vector2d lb = rotation(-thf) * (Eigen::Vector2d(m.x(), ground) - a);
      const Eigen::Vector2d lc = rotation(-tht) * (Eigen::Vector2d(t.x(), ground) - m);
      ax.push_back(la.x()); ay.push_back(la.y());
      bx.push_back(lb.x()); by.push_back(lb.y());
      cx.push_back(lc.x()); cy.push_back(lc.y());
    }
    std::vector<double> hh;
    for (auto i : f) hh.push_back(E(i, 1) - ground_level);
    heel_height[static_cast<std::size_t>(side)] = median_or_zero(hh);
    auto& fg = cal.feet[static_cast<std::size_t>(side)];
    fg.flat_angle_rad = median_or_zero(ang);
    fg.heel_local = Eigen::Vector2d(median_or_zero(ax), median_or_zero(ay));
    fg.mt_local = Eigen::Vector2d(median_or_zero(bx), median_or_zero(by));
    fg.hallux_local = Eigen::Vector2d(median_or_zero(cx), median_or_zero(cy));
    std::vector<double> ankle_mt;
    for (auto i : f) ankle_mt.push_back((M.row(i) - A.row(i)).norm());
    fg.heel_mt_length_m = (fg.mt_local - fg.heel_local).norm() +
                          lm.mt_head_ahead_share[static_cast<std::size_t>(side)] * median_or_zero(ankle_mt);
  }
  // A foot that never stands on the floor in the window (a hop on the other leg) has no flat
  // frames at ground level: it takes the other foot's sole geometry instead of a sole drawn
  // down to the floor beneath it.
  for (int side = 0; side < 2 && sole[0] == ground_level; ++side) {
    const int other = 1 - side;
    if (heel_height[static_cast<std::size_t>(side)] > heel_height[static_cast<std::size_t>(other)] + 0.03) {
      cal.feet[static_cast<std::size_t>(side)] = cal.feet[static_cast<std::size_t>(other)];
      cal.message = std::string(side_name(side)) + " foot never stands on the floor (heel landmark " +
                    std::to_string(static_cast<int>(1000 * heel_height[static_cast<std::size_t>(side)])) +
                    " mm above it at its lowest): its sole geometry is taken from the " + side_name(1 - side) + " foot";
    }
  }
  return cal;
}

GroundLevel estimate_ground_level(const SagittalLandmarks& lm) {
  double lowest = std::numeric_limits<double>::infinity();
  for (int side = 0; side < 2; ++side) {
    const auto f = flat_frames(lm, side);
    std::vector<double> he, hm;
    for (auto i : f) {
      he.push_back(lm.p[landmark(side, kHeel)](i, 1));
      hm.push_back(lm.p[landmark(side, kMt)](i, 1));
    }
    lowest = std::min({lowest, median_or_zero(he), median_or_zero(hm)});
  }
  if (lowest >= 0.0 && lowest <= 0.15) {
    std::string message = "ground level 0 m (lab floor; lowest flat-stance foot landmark " + std::to_string(lowest * 1000).substr(0, 5) +
                          " mm above it)";
    // A skin marker's centre stands at least its radius (7-12 mm) above the floor, and a heel or
    // MT-head marker at flat foot at most about 60 mm (24-55 mm on the development trials): outside
    // that, the markers and the floor are likely offset (a ground calibration error), which moves
    // every contact and COP.
    if (lowest < kMinFootMarkerHeightM || lowest > kMaxFootMarkerHeightM)
      message += "; that is " + std::string(lowest < kMinFootMarkerHeightM ? "nearer the floor than a marker's radius" :
                                                                          "higher than a foot marker stands at flat foot") +
                 ": the markers and the floor may be offset (check the ground calibration; --ground-level sets the floor)";
    return {0.0, message};
  }
  return {lowest, "ground level " + std::to_string(lowest).substr(0, 6) +
                     " m: the flat-stance foot landmarks are not 0-150 mm above the lab floor, so the lowest of them is taken"};
}

}  // namespace kin2grf
