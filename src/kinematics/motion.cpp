#include "kin2grf/kinematics/motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {
namespace {

double angle_of(const Eigen::Vector2d& d) { return std::atan2(d.y(), d.x()); }

}  // namespace

BodyGeometry measure_geometry(const SagittalLandmarks& lm) {
  const Eigen::Index n = lm.frames();
  auto dist = [&](int a, int b) {
    std::vector<double> v;
    v.reserve(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) v.push_back((lm.p[b].row(i) - lm.p[a].row(i)).norm());
    return median(v);
  };
  BodyGeometry g;
  g.torso = dist(kHip, kShoulder);
  for (int s = 0; s < 2; ++s) {
    g.thigh[s] = dist(kHip, landmark(s, kKnee));
    g.shank[s] = dist(landmark(s, kKnee), landmark(s, kAnkle));
    g.foot[s] = dist(landmark(s, kAnkle), landmark(s, kMt));
    g.toes[s] = dist(landmark(s, kMt), landmark(s, kHallux));
    std::vector<double> hx, hy;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector2d A = lm.p[landmark(s, kAnkle)].row(i).transpose();
      const Eigen::Vector2d M = lm.p[landmark(s, kMt)].row(i).transpose();
      const Eigen::Vector2d E = lm.p[landmark(s, kHeel)].row(i).transpose();
      const Eigen::Vector2d local = rotation(-angle_of(M - A)) * (E - A);
      hx.push_back(local.x());
      hy.push_back(local.y());
    }
    g.heel_local[s] = Eigen::Vector2d(median(hx), median(hy));
  }
  return g;
}

Eigen::MatrixXd independent_coordinates(const SagittalLandmarks& lm) {
  const Eigen::Index n = lm.frames();
  Eigen::MatrixXd x(n, 12);
  Eigen::MatrixXd theta(n, kSegmentCount);
  for (Eigen::Index i = 0; i < n; ++i) {
    auto P = [&](int k) { return Eigen::Vector2d(lm.p[k].row(i).transpose()); };
    theta(i, kTorso) = angle_of(P(kShoulder) - P(kHip));
    for (int s = 0; s < 2; ++s) {
      theta(i, segment(s, kThigh)) = angle_of(P(landmark(s, kKnee)) - P(kHip));
      theta(i, segment(s, kShank)) = angle_of(P(landmark(s, kAnkle)) - P(landmark(s, kKnee)));
      theta(i, segment(s, kFoot)) = angle_of(P(landmark(s, kMt)) - P(landmark(s, kAnkle)));
      theta(i, segment(s, kToes)) = angle_of(P(landmark(s, kHallux)) - P(landmark(s, kMt)));
    }
    x(i, 0) = lm.p[kHip](i, 0);
    x(i, 1) = lm.p[kHip](i, 1);
    x(i, 11) = (P(kShoulder) - P(kHip)).norm();
  }
  // Unwrap each absolute angle over time, then form the joint angles.
  for (int s = 0; s < kSegmentCount; ++s)
    for (Eigen::Index i = 1; i < n; ++i) {
      double d = theta(i, s) - theta(i - 1, s);
      while (d > M_PI) { theta(i, s) -= 2 * M_PI; d -= 2 * M_PI; }
      while (d < -M_PI) { theta(i, s) += 2 * M_PI; d += 2 * M_PI; }
    }
  x.col(2) = theta.col(kTorso);
  for (int j = 0; j < kJointCount; ++j) x.col(3 + j) = theta.col(joint_child(j)) - theta.col(joint_parent(j));
  return x;
}

ModelMotion reconstruct_motion(const Model& model, const Eigen::MatrixXd& x, const Eigen::MatrixXd& xd,
                               const Eigen::MatrixXd& xdd, double rate_hz, const Eigen::VectorXd& time_s) {
  const Eigen::Index n = x.rows();
  ModelMotion mm;
  mm.rate_hz = rate_hz;
  mm.time_s = time_s;
  mm.q = Eigen::MatrixXd::Zero(n, coord::kCount);
  mm.qd = Eigen::MatrixXd::Zero(n, coord::kCount);
  mm.qdd = Eigen::MatrixXd::Zero(n, coord::kCount);
  // Bodies in an order where the parent comes first (the torso, then each leg down).
  static constexpr int order[] = {kTorso, kThighR, kShankR, kFootR, kToesR, kThighL, kShankL, kFootL, kToesL};
  for (Eigen::Index i = 0; i < n; ++i) {
    std::array<double, kSegmentCount> th{}, w{}, al{};
    th[kTorso] = x(i, 2); w[kTorso] = xd(i, 2); al[kTorso] = xdd(i, 2);
    for (int j = 0; j < kJointCount; ++j) {
      const int c = joint_child(j), p = joint_parent(j);
      th[c] = th[p] + x(i, 3 + j);
      w[c] = w[p] + xd(i, 3 + j);
      al[c] = al[p] + xdd(i, 3 + j);
    }
    std::array<Eigen::Vector2d, kLandmarkCount> r, v, a;
    r[kHip] = Eigen::Vector2d(x(i, 0), x(i, 1));
    v[kHip] = Eigen::Vector2d(xd(i, 0), xd(i, 1));
    a[kHip] = Eigen::Vector2d(xdd(i, 0), xdd(i, 1));
    // The torso's points scale with its measured length (column 11, when given): d = k e with
    // e = R(theta) rho, so d' = k' e + k e' and d'' = k'' e + 2 k' e' + k e''.
    double ks = 1, ksd = 0, ksdd = 0;  // k, k', k''
    if (x.cols() > 11) {
      const double L0 = model.bodies[kTorso].length_m;
      ks = x(i, 11) / L0, ksd = xd(i, 11) / L0, ksdd = xdd(i, 11) / L0;
    }
    auto place = [&](const Body& b, int s, const Eigen::Vector2d& local, Eigen::Vector2d& rr, Eigen::Vector2d& vv,
                     Eigen::Vector2d& aa) {
      const Eigen::Vector2d e = rotation(th[s]) * local;
      const Eigen::Vector2d ed = w[s] * perp(e), edd = al[s] * perp(e) - w[s] * w[s] * e;
      // Other bodies: k = 1, k' = k'' = 0 (exactly the fixed-length forward kinematics).
      const bool scaled = s == kTorso;
      const double k0 = scaled ? ks : 1.0, k1 = scaled ? ksd : 0.0, k2 = scaled ? ksdd : 0.0;
      rr = r[b.proximal] + k0 * e;
      vv = v[b.proximal] + k1 * e + k0 * ed;
      aa = a[b.proximal] + k2 * e + 2 * k1 * ed + k0 * edd;
    };
    for (int s : order) {
      const Body& b = model.bodies[s];
      for (int k = 0; k < 2; ++k)
        if (b.points[k] >= 0) place(b, s, b.points_local[k], r[b.points[k]], v[b.points[k]], a[b.points[k]]);
      Eigen::Vector2d rg, vg, ag;
      place(b, s, b.com_local, rg, vg, ag);
      mm.q.block<1, 2>(i, coord::com_x(s)) = rg.transpose();
      mm.qd.block<1, 2>(i, coord::com_x(s)) = vg.transpose();
      mm.qdd.block<1, 2>(i, coord::com_x(s)) = ag.transpose();
      mm.q(i, coord::theta(s)) = th[s];
      mm.qd(i, coord::theta(s)) = w[s];
      mm.qdd(i, coord::theta(s)) = al[s];
    }
    for (int k = 0; k < kLandmarkCount; ++k) {
      mm.q.block<1, 2>(i, coord::point_x(k)) = r[k].transpose();
      mm.qd.block<1, 2>(i, coord::point_x(k)) = v[k].transpose();
      mm.qdd.block<1, 2>(i, coord::point_x(k)) = a[k].transpose();
    }
    for (int j = 0; j < kJointCount; ++j) {
      mm.q(i, coord::phi(j)) = x(i, 3 + j);
      mm.qd(i, coord::phi(j)) = xd(i, 3 + j);
      mm.qdd(i, coord::phi(j)) = xdd(i, 3 + j);
    }
  }
  return mm;
}

ModelMotion compute_motion(const Model& model, const SagittalLandmarks& lm, double cutoff_hz, TorsoLength torso) {
  if (lm.frames() < 8) throw InputError("too few frames (" + std::to_string(lm.frames()) + ") for the kinematics");
  const double dt = 1.0 / lm.rate_hz;
  Eigen::MatrixXd raw = independent_coordinates(lm);
  if (torso == TorsoLength::Fixed) raw.conservativeResize(Eigen::NoChange, 11);
  const Eigen::MatrixXd x = cutoff_hz > 0 ? butterworth_filtfilt(raw, lm.rate_hz, cutoff_hz) : raw;
  const Eigen::MatrixXd xd = central_difference(x, dt);
  const Eigen::MatrixXd xdd = second_difference(x, dt);
  return reconstruct_motion(model, x, xd, xdd, lm.rate_hz, lm.time_s);
}

void lag_torso_fore_aft(ModelMotion& m, double tau_s) {
  if (!(tau_s > 0) || m.frames() == 0) return;
  const int c = coord::com_x(kTorso);
  const Eigen::Index n = m.frames();
  // Frame i takes the acceleration of (fractional) frame i - d, linearly interpolated; frames
  // before the trial's first take its first. Backwards, so that each frame reads only the
  // earlier ones, not yet overwritten.
  const double d = tau_s * m.rate_hz;
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    const double t = static_cast<double>(i) - d;
    if (t <= 0) {
      m.qdd(i, c) = m.qdd(0, c);
      continue;
    }
    const auto i0 = static_cast<Eigen::Index>(t);  // t < i: i0 + 1 <= i
    const double f = t - static_cast<double>(i0);
    m.qdd(i, c) = (1 - f) * m.qdd(i0, c) + f * m.qdd(i0 + 1, c);
  }
}

double measured_torso_lag_s(const ModelMotion& m) {
  if (m.frames() < 20 || !(m.rate_hz > 0)) return 0.0;
  // The middle 80 %, at most a minute of it: the trunk's timing does not change along a trial,
  // and a 10-minute trial at 2 kHz would otherwise take 0.5 s here.
  const Eigen::Index n = m.frames(), m0 = n / 10;
  const Eigen::Index m1 = std::min(n - n / 10, m0 + static_cast<Eigen::Index>(std::min(60.0 * m.rate_hz, static_cast<double>(n))));
  const int c = coord::com_x(kTorso), h = coord::point_x(kHip);
  const int reach = std::max(1, static_cast<int>(0.08 * m.rate_hz));
  // The peak lag of y behind x, in frames (parabola through the peak); NaN without a positive peak.
  auto peak_lag = [&](int x, int y) {
    std::vector<double> r(static_cast<std::size_t>(2 * reach + 1));
    for (int lag = -reach; lag <= reach; ++lag) {
      double sum = 0;
      for (Eigen::Index i = m0; i < m1; ++i)
        if (const Eigen::Index j = i + lag; j >= 0 && j < n) sum += m.qdd(i, x) * m.qdd(j, y);
      r[static_cast<std::size_t>(lag + reach)] = sum;
    }
    const auto k = static_cast<int>(std::max_element(r.begin(), r.end()) - r.begin());
    if (!(r[static_cast<std::size_t>(k)] > 0)) return std::numeric_limits<double>::quiet_NaN();
    const auto at = [&](int i) { return r[static_cast<std::size_t>(i)]; };
    const double offset = k > 0 && k < 2 * reach ? parabola_vertex_offset(at(k - 1), at(k), at(k + 1), true) : 0.0;
    return k - reach + offset;
  };
  // Both ways round and halved: a finite window biases each estimate by the same amount (a
  // quarter of a frame for a stride's harmonics), and the difference cancels it.
  const double lag = 0.5 * (peak_lag(h, c) - peak_lag(c, h));
  return std::isfinite(lag) ? lag / m.rate_hz : 0.0;
}

double noise_limited_cutoff(const SagittalLandmarks& lm, double upper_hz) {
  Eigen::MatrixXd xy(lm.frames(), 2 * kLandmarkCount);
  for (int k = 0; k < kLandmarkCount; ++k) xy.middleCols(2 * k, 2) = lm.p[static_cast<std::size_t>(k)];
  return residual_analysis_cutoff(xy, lm.rate_hz, upper_hz);
}

}  // namespace kin2grf
