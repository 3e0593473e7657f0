#include "kin2grf/kinematics/motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {

Eigen::Vector2d whole_body_com(const Model& model, const MotionFrame& f) {
  Eigen::Vector2d mr = Eigen::Vector2d::Zero();
  double m = 0.0;
  for (int b = 0; b < kSegmentCount; ++b) {
    const double mb = model.bodies[static_cast<std::size_t>(b)].mass_kg;
    mr += mb * Eigen::Vector2d(f.q(coord::com_x(b)), f.q(coord::com_x(b) + 1));
    m += mb;
  }
  return m > 0 ? Eigen::Vector2d(mr / m) : Eigen::Vector2d::Zero();
}

namespace {

double angle_of(const Eigen::Vector2d& d) { return std::atan2(d.y(), d.x()); }

/// Position, velocity and acceleration of a point fixed in a body (Sect. 2.2's forward
/// kinematics, with the torso's length scale k, k', k''; k = 1, k' = k'' = 0 for the others).
struct PointKinematics {
  Eigen::Vector2d r, v, a;
};
PointKinematics place(const PointKinematics& proximal, double th, double w, double al, const Eigen::Vector2d& local, double k0,
                      double k1, double k2) {
  const Eigen::Vector2d e = rotation(th) * local;
  const Eigen::Vector2d ed = w * perp(e), edd = al * perp(e) - w * w * e;
  return {proximal.r + k0 * e, proximal.v + k1 * e + k0 * ed, proximal.a + k2 * e + 2 * k1 * ed + k0 * edd};
}

/// The torso's length scale k = L(t) / L0 and its derivatives at frame i (1, 0, 0 without column 11).
std::array<double, 3> torso_scale(const ModelMotion& m, Eigen::Index i, const double* xd_i, const double* xdd_i) {
  if (m.x.cols() <= 11) return {1.0, 0.0, 0.0};
  const double L0 = m.model->bodies[kTorso].length_m;
  return {m.x(i, 11) / L0, xd_i[11] / L0, xdd_i[11] / L0};
}

/// The acceleration along `axis` (0 fore-aft, 1 vertical) of a segment's COM hanging from the hip
/// (the torso or a thigh) as frame() places it, every frame: the hip's, with the segment's
/// absolute angle (a thigh's the torso's plus its hip joint's) and its COM offset (the torso's
/// scaled with its length). The series the torso and thigh lags delay and the torso's vertical
/// smoothing filters.
Eigen::VectorXd chain_com_acceleration_mps2(const ModelMotion& m, int segment_index, int axis) {
  const Eigen::Index n = m.frames();
  const bool torso = segment_index == kTorso;
  const int hip_column = torso ? -1 : 3 + 4 * (segment_index == segment(0, kThigh) ? 0 : 1);  // the hip joint's angle
  const Eigen::Vector2d& rho = m.model->bodies[static_cast<std::size_t>(segment_index)].com_local;
  Eigen::VectorXd ax(n);
  std::array<double, kMaxIndependent> d1{}, d2{};
  for (Eigen::Index i = 0; i < n; ++i) {
    m.derivatives_at(i, d1.data(), d2.data());
    const PointKinematics hip{Eigen::Vector2d(m.x(i, 0), m.x(i, 1)), Eigen::Vector2d(d1[0], d1[1]), Eigen::Vector2d(d2[0], d2[1])};
    double th = m.x(i, 2), w = d1[2], al = d2[2];
    if (!torso) {
      const auto c = static_cast<std::size_t>(hip_column);
      th += m.x(i, hip_column), w += d1[c], al += d2[c];
    }
    const auto [k0, k1, k2] = torso ? torso_scale(m, i, d1.data(), d2.data()) : std::array<double, 3>{1.0, 0.0, 0.0};
    ax[i] = place(hip, th, w, al, rho, k0, k1, k2).a[axis];
  }
  return ax;
}

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
  // The absolute angles first, in x itself (a long trial's memory): the torso's in
  // column 2, each joint's child segment's in column 3 + j.
  for (Eigen::Index i = 0; i < n; ++i) {
    auto P = [&](int k) { return Eigen::Vector2d(lm.p[k].row(i).transpose()); };
    x(i, 2) = angle_of(P(kShoulder) - P(kHip));
    for (int s = 0; s < 2; ++s) {
      x(i, 3 + 4 * s + kThigh) = angle_of(P(landmark(s, kKnee)) - P(kHip));
      x(i, 3 + 4 * s + kShank) = angle_of(P(landmark(s, kAnkle)) - P(landmark(s, kKnee)));
      x(i, 3 + 4 * s + kFoot) = angle_of(P(landmark(s, kMt)) - P(landmark(s, kAnkle)));
      x(i, 3 + 4 * s + kToes) = angle_of(P(landmark(s, kHallux)) - P(landmark(s, kMt)));
    }
    x(i, 0) = lm.p[kHip](i, 0);
    x(i, 1) = lm.p[kHip](i, 1);
    x(i, 11) = (P(kShoulder) - P(kHip)).norm();
  }
  // Unwrap each absolute angle over time, then form the joint angles, child less parent: the
  // distal joints first, so that a parent's absolute angle is still there for its child.
  for (int c = 2; c < 3 + kJointCount; ++c)
    for (Eigen::Index i = 1; i < n; ++i) {
      double d = x(i, c) - x(i - 1, c);
      while (d > M_PI) { x(i, c) -= 2 * M_PI; d -= 2 * M_PI; }
      while (d < -M_PI) { x(i, c) += 2 * M_PI; d += 2 * M_PI; }
    }
  for (int depth = 3; depth >= 0; --depth)
    for (int s = 0; s < 2; ++s) {
      const int j = 4 * s + depth;
      static_assert(kThigh == 0 && kShank == 1 && kFoot == 2 && kToes == 3, "joint j's child is segment(j / 4, j % 4)");
      x.col(3 + j) -= x.col(depth == 0 ? 2 : 3 + j - 1);  // joint_parent(j)'s absolute angle
    }
  return x;
}

void ModelMotion::derivatives_at(Eigen::Index i, double* d1, double* d2) const {
  const Eigen::Index n = x.rows(), cols = x.cols();
  if (xd.rows() == n && xdd.rows() == n && xd.cols() == cols && xdd.cols() == cols) {
    for (Eigen::Index k = 0; k < cols; ++k) d1[k] = xd(i, k), d2[k] = xdd(i, k);
    return;
  }
  // x's central differences, row i (the doubles of the whole-trial matrices).
  const double dt = 1.0 / rate_hz;
  for (Eigen::Index k = 0; k < cols; ++k) d1[k] = central_difference_at(x, i, k, dt), d2[k] = second_difference_at(x, i, k, dt);
}

Eigen::VectorXd ModelMotion::xdd_column(int c) const {
  const Eigen::Index n = x.rows();
  if (xdd.rows() == n && xdd.cols() == x.cols()) return xdd.col(c);
  Eigen::VectorXd out(n);
  for (Eigen::Index i = 0; i < n; ++i) out[i] = second_difference_at(x, i, c, 1.0 / rate_hz);
  return out;
}

void ModelMotion::frame(Eigen::Index i, MotionFrame& f) const {
  // Every coordinate is written below (each landmark is a body's proximal or attached point);
  // D* is zero where the motion keeps none.
  // Bodies in an order where the parent comes first (the torso, then each leg down).
  static constexpr int order[] = {kTorso, kThighR, kShankR, kFootR, kToesR, kThighL, kShankL, kFootL, kToesL};
  std::array<double, kMaxIndependent> d1{}, d2{};
  derivatives_at(i, d1.data(), d2.data());
  std::array<double, kSegmentCount> th{}, w{}, al{};
  th[kTorso] = x(i, 2); w[kTorso] = d1[2]; al[kTorso] = d2[2];
  for (int j = 0; j < kJointCount; ++j) {
    const int c = joint_child(j), p = joint_parent(j);
    th[c] = th[p] + x(i, 3 + j);
    w[c] = w[p] + d1[static_cast<std::size_t>(3 + j)];
    al[c] = al[p] + d2[static_cast<std::size_t>(3 + j)];
  }
  std::array<PointKinematics, kLandmarkCount> pk;
  pk[kHip] = {Eigen::Vector2d(x(i, 0), x(i, 1)), Eigen::Vector2d(d1[0], d1[1]), Eigen::Vector2d(d2[0], d2[1])};
  // The torso's points scale with its measured length (column 11, when given): d = k e with
  // e = R(theta) rho, so d' = k' e + k e' and d'' = k'' e + 2 k' e' + k e''.
  const auto [ks, ksd, ksdd] = torso_scale(*this, i, d1.data(), d2.data());
  for (int s : order) {
    const Body& b = model->bodies[s];
    const bool scaled = s == kTorso;
    const double k0 = scaled ? ks : 1.0, k1 = scaled ? ksd : 0.0, k2 = scaled ? ksdd : 0.0;
    for (int k = 0; k < 2; ++k)
      if (b.points[k] >= 0) pk[b.points[k]] = place(pk[b.proximal], th[s], w[s], al[s], b.points_local[k], k0, k1, k2);
    const PointKinematics g = place(pk[b.proximal], th[s], w[s], al[s], b.com_local, k0, k1, k2);
    f.q.segment<2>(coord::com_x(s)) = g.r;
    f.qd.segment<2>(coord::com_x(s)) = g.v;
    f.qdd.segment<2>(coord::com_x(s)) = g.a;
    f.q(coord::theta(s)) = th[s];
    f.qd(coord::theta(s)) = w[s];
    f.qdd(coord::theta(s)) = al[s];
  }
  for (int k = 0; k < kLandmarkCount; ++k) {
    f.q.segment<2>(coord::point_x(k)) = pk[k].r;
    f.qd.segment<2>(coord::point_x(k)) = pk[k].v;
    f.qdd.segment<2>(coord::point_x(k)) = pk[k].a;
  }
  for (int j = 0; j < kJointCount; ++j) {
    f.q(coord::phi(j)) = x(i, 3 + j);
    f.qd(coord::phi(j)) = d1[static_cast<std::size_t>(3 + j)];
    f.qdd(coord::phi(j)) = d2[static_cast<std::size_t>(3 + j)];
  }
  if (torso_ax_mps2.size() > i) f.qdd(coord::com_x(kTorso)) = torso_ax_mps2[i];
  if (torso_ay_mps2.size() > i) f.qdd(coord::com_x(kTorso) + 1) = torso_ay_mps2[i];
  for (int s = 0; s < 2; ++s)
    if (const Eigen::VectorXd& a = thigh_ax_mps2[static_cast<std::size_t>(s)]; a.size() > i) f.qdd(coord::com_x(segment(s, kThigh))) = a[i];
  for (int s = 0; s < 2; ++s)
    f.cop_foot_angle_rad[static_cast<std::size_t>(s)] =
        cop_foot_angle_rad.rows() > i ? cop_foot_angle_rad(i, s) : std::numeric_limits<double>::quiet_NaN();
  // D* (Sect. 2.3) is the contact stage's: contact_frame fills it in as the frame is solved.
  f.q.segment<4>(coord::dstar_x(0)).setZero();
  f.qd.segment<4>(coord::dstar_x(0)).setZero();
  f.qdd.segment<4>(coord::dstar_x(0)).setZero();
}

ModelMotion reconstruct_motion(std::shared_ptr<const Model> model, Eigen::MatrixXd x, Eigen::MatrixXd xd, Eigen::MatrixXd xdd,
                               double rate_hz, Eigen::VectorXd time_s) {
  ModelMotion mm;
  mm.rate_hz = rate_hz;
  mm.time_s = std::move(time_s);
  mm.model = std::move(model);
  mm.x = std::move(x);
  mm.xd = std::move(xd);
  mm.xdd = std::move(xdd);
  // The HAT COM's fore-aft acceleration as the chain gives it, the series the torso lag delays.
  mm.torso_ax_mps2 = chain_com_acceleration_mps2(mm, kTorso, 0);
  return mm;
}

Eigen::MatrixXd model_coordinates(const SagittalLandmarks& lm, TorsoLength torso) {
  if (lm.frames() < 8) throw InputError("too few frames (" + std::to_string(lm.frames()) + ") for the kinematics");
  Eigen::MatrixXd x = independent_coordinates(lm);
  if (torso == TorsoLength::Fixed) x.conservativeResize(Eigen::NoChange, 11);
  return x;
}

ModelMotion motion_from_coordinates(std::shared_ptr<const Model> model, Eigen::MatrixXd x, double rate_hz, Eigen::VectorXd time_s,
                                    double cutoff_hz, double cop_angle_cutoff_hz, FilterEdge edges, double edge_span_periods) {
  // The feet's absolute angles at the COP's own cut-off: the sum of the chain's columns (torso,
  // hip, knee, ankle), the foot's theta as frame() builds it, filtered (a linear filter, so the
  // sum of the filtered columns).
  Eigen::MatrixX2d cop_angle;
  if (cop_angle_cutoff_hz > 0 && cop_angle_cutoff_hz != cutoff_hz) {
    cop_angle.resize(x.rows(), 2);
    for (int s = 0; s < 2; ++s) cop_angle.col(s) = x.col(2) + x.middleCols(3 + 4 * s, 3).rowwise().sum();
    cop_angle = butterworth_filtfilt(Eigen::MatrixXd(cop_angle), rate_hz, cop_angle_cutoff_hz);
  }
  if (cutoff_hz > 0) x = butterworth_filtfilt(std::move(x), rate_hz, cutoff_hz, edges, edge_span_periods);
  // Empty derivatives: each frame takes x's central differences (ModelMotion::derivatives_at).
  ModelMotion m = reconstruct_motion(std::move(model), std::move(x), Eigen::MatrixXd(), Eigen::MatrixXd(), rate_hz, std::move(time_s));
  m.cop_foot_angle_rad = std::move(cop_angle);
  return m;
}

ModelMotion compute_motion(std::shared_ptr<const Model> model, const SagittalLandmarks& lm, double cutoff_hz, TorsoLength torso,
                           double cop_angle_cutoff_hz, FilterEdge edges) {
  return motion_from_coordinates(std::move(model), model_coordinates(lm, torso), lm.rate_hz, lm.time_s, cutoff_hz, cop_angle_cutoff_hz,
                                 edges);
}

namespace {
/// `a` delayed in place by `d` frames: frame i takes (fractional) frame i - d, linearly
/// interpolated; frames before the trial's first take its first. Backwards, so that each frame
/// reads only the earlier ones, not yet overwritten.
void delay_in_place(Eigen::VectorXd& a, double d) {
  const Eigen::Index n = a.size();
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    const double t = static_cast<double>(i) - d;
    if (t <= 0) {
      a[i] = a[0];
      continue;
    }
    const auto i0 = static_cast<Eigen::Index>(t);  // t < i: i0 + 1 <= i
    const double f = t - static_cast<double>(i0);
    a[i] = (1 - f) * a[i0] + f * a[i0 + 1];
  }
}
}  // namespace

void lag_torso_fore_aft(ModelMotion& m, double tau_s) {
  if (!(tau_s > 0) || m.frames() == 0) return;
  delay_in_place(m.torso_ax_mps2, tau_s * m.rate_hz);
}

void lag_thigh_fore_aft(ModelMotion& m, int side, double tau_s) {
  if (!(tau_s > 0) || m.frames() == 0 || (side != 0 && side != 1)) return;
  Eigen::VectorXd ax = chain_com_acceleration_mps2(m, segment(side, kThigh), 0);
  delay_in_place(ax, tau_s * m.rate_hz);
  m.thigh_ax_mps2[static_cast<std::size_t>(side)] = std::move(ax);
}

void smooth_torso_vertical(ModelMotion& m, double cutoff_hz) {
  if (!(cutoff_hz > 0) || m.frames() == 0) return;
  m.torso_ay_mps2 = butterworth_filtfilt(chain_com_acceleration_mps2(m, kTorso, 1), m.rate_hz, cutoff_hz);
}

double measured_torso_lag_s(const ModelMotion& m) {
  if (m.frames() < 20 || !(m.rate_hz > 0)) return 0.0;
  // The middle 80 %, at most a minute of it: the trunk's timing does not change along a trial,
  // and a 10-minute trial at 2 kHz would otherwise take 0.5 s here.
  const Eigen::Index n = m.frames(), m0 = n / 10;
  const Eigen::Index m1 = std::min(n - n / 10, m0 + static_cast<Eigen::Index>(std::min(60.0 * m.rate_hz, static_cast<double>(n))));
  // The hip's fore-aft acceleration is its independent coordinate's (column 0).
  using Series = Eigen::Ref<const Eigen::VectorXd>;  // views, no copies
  const Eigen::VectorXd hip_ax = m.xdd_column(0);
  const Series hip = hip_ax, hat = m.torso_ax_mps2;
  const int reach = std::max(1, static_cast<int>(0.08 * m.rate_hz));
  // The peak lag of y behind x, in frames (parabola through the peak); NaN without a positive peak.
  auto peak_lag = [&](const Series& x, const Series& y) {
    std::vector<double> r(static_cast<std::size_t>(2 * reach + 1));
    for (int lag = -reach; lag <= reach; ++lag) {
      double sum = 0;
      for (Eigen::Index i = m0; i < m1; ++i)
        if (const Eigen::Index j = i + lag; j >= 0 && j < n) sum += x[i] * y[j];
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
  const double lag = 0.5 * (peak_lag(hip, hat) - peak_lag(hat, hip));
  return std::isfinite(lag) ? lag / m.rate_hz : 0.0;
}

double noise_limited_cutoff(const SagittalLandmarks& lm, double upper_hz) {
  // residual_analysis_cutoff reads at most a minute of frames: only those are gathered (a long
  // trial's memory).
  const Eigen::Index n = std::min<Eigen::Index>(lm.frames(), static_cast<Eigen::Index>(60 * lm.rate_hz));
  Eigen::MatrixXd xy(n, 2 * kLandmarkCount);
  for (int k = 0; k < kLandmarkCount; ++k) xy.middleCols(2 * k, 2) = lm.p[static_cast<std::size_t>(k)].topRows(n);
  return residual_analysis_cutoff(xy, lm.rate_hz, upper_hz);
}

}  // namespace kin2grf
