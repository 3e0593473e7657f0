#include "kin2grf/dynamics/joint_moments_3d.hpp"

#include <cmath>
#include <limits>

#include "kin2grf/dynamics/stance_parameters.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/kinematics/filter.hpp"

namespace kin2grf {

namespace {

/// The COM on a body's proximal-distal line at the model's fraction, N x 3.
Eigen::MatrixX3d body_com(const Body& b, const std::array<Eigen::MatrixX3d, kLandmarkCount>& p) {
  const double f = b.com_fraction();
  return (1 - f) * p[static_cast<std::size_t>(b.proximal)] + f * p[static_cast<std::size_t>(b.points[0])];
}

/// omega = vee(dR/dt R^T) by central differences of the frames' axes, and its derivative.
void angular_motion(SegmentMotion3D& s, double dt) {
  const Eigen::MatrixXd Rd = central_difference(s.rotation, dt);
  const Eigen::Index n = s.rotation.rows();
  s.omega_rps.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Matrix3d dR;
    for (int a = 0; a < 3; ++a) dR.col(a) = Rd.block<1, 3>(i, 3 * a).transpose();
    const Eigen::Matrix3d W = dR * s.R(i).transpose();
    s.omega_rps.row(i) = 0.5 * Eigen::RowVector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
  }
  s.alpha_rps2 = central_difference(s.omega_rps, dt);
}

void set_axes(SegmentMotion3D& s, Eigen::Index i, const Eigen::Vector3d& ex, const Eigen::Vector3d& ey, const Eigen::Vector3d& ez) {
  s.rotation.block<1, 3>(i, 0) = ex.transpose();
  s.rotation.block<1, 3>(i, 3) = ey.transpose();
  s.rotation.block<1, 3>(i, 6) = ez.transpose();
}

/// A unit vector, or InputError naming what degenerated (two landmarks at one place).
Eigen::Vector3d unit(const Eigen::Vector3d& v, const char* what, Eigen::Index i) {
  const double norm = v.norm();
  if (!(norm > 1e-9)) throw InputError(std::string("3D joint moments: the ") + what + " is undefined at frame " + std::to_string(i));
  return v / norm;
}

/// A long segment (thigh, shank) from its proximal to its distal joint centre: COM on that line at
/// the model's fraction, e_y up the segment, e_z the lateral axis made orthogonal to it.
SegmentMotion3D long_segment_motion(const Body& b, double longitudinal_ratio, const Eigen::MatrixX3d& proximal,
                                    const Eigen::MatrixX3d& distal, const Eigen::MatrixX3d& lateral_axis, double dt, const char* name,
                                    const char* joints) {
  SegmentMotion3D s;
  s.mass_kg = b.mass_kg;
  s.inertia_kgm2 = {b.inertia_kgm2, b.inertia_kgm2 * longitudinal_ratio * longitudinal_ratio, b.inertia_kgm2};
  const double f = b.com_fraction();
  s.com_m = (1 - f) * proximal + f * distal;
  s.com_acc_mps2 = second_difference(s.com_m, dt);
  const Eigen::Index n = proximal.rows();
  s.rotation.resize(n, 9);
  const std::string axis = std::string(name) + "'s long axis (" + joints + " at one place)";
  const std::string across = std::string(name) + "'s lateral axis (the segment lies along the lateral axis)";
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d ey = unit((proximal.row(i) - distal.row(i)).transpose(), axis.c_str(), i);
    const Eigen::Vector3d lat = lateral_axis.row(i).transpose();
    const Eigen::Vector3d ez = unit(lat - lat.dot(ey) * ey, across.c_str(), i);
    set_axes(s, i, ey.cross(ez), ey, ez);
  }
  angular_motion(s, dt);
  return s;
}

/// The distance between the foot's and the toes' COMs at frame i (m).
double foot_toes_com_distance(const Model& model, int side, const std::array<Eigen::MatrixX3d, kLandmarkCount>& p, Eigen::Index i) {
  const Body& f = model.bodies[static_cast<std::size_t>(segment(side, kFoot))];
  const Body& t = model.bodies[static_cast<std::size_t>(segment(side, kToes))];
  return (body_com(f, p).row(i) - body_com(t, p).row(i)).norm();
}

/// `d`: the foot's and toes' COMs' distance for their common inertia (foot_toes_com_distance).
SegmentMotion3D foot_motion(const Model& model, int side, const std::array<Eigen::MatrixX3d, kLandmarkCount>& p, double dt, double d) {
  const Body& f = model.bodies[static_cast<std::size_t>(segment(side, kFoot))];
  const Body& t = model.bodies[static_cast<std::size_t>(segment(side, kToes))];
  const Eigen::MatrixX3d& ankle = p[static_cast<std::size_t>(landmark(side, kAnkle))];
  const Eigen::MatrixX3d& heel = p[static_cast<std::size_t>(landmark(side, kHeel))];
  const Eigen::MatrixX3d& mt = p[static_cast<std::size_t>(landmark(side, kMt))];
  SegmentMotion3D s;
  s.mass_kg = f.mass_kg + t.mass_kg;
  const Eigen::MatrixX3d cf = body_com(f, p), ct = body_com(t, p);
  s.com_m = (f.mass_kg * cf + t.mass_kg * ct) / s.mass_kg;
  s.com_acc_mps2 = second_difference(s.com_m, dt);
  // Transverse inertia of the two about their common COM (parallel axes, at the trial's first
  // frame's distance: the toes bend little against the foot's size), the long axis's by de
  // Leva's ratio.
  const double transverse = f.inertia_kgm2 + t.inertia_kgm2 + f.mass_kg * t.mass_kg / s.mass_kg * d * d;
  s.inertia_kgm2 = {transverse * kFootLongitudinalGyrationRatio * kFootLongitudinalGyrationRatio, transverse, transverse};
  const Eigen::Index n = ankle.rows();
  s.rotation.resize(n, 9);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d ex = unit((mt.row(i) - heel.row(i)).transpose(), "foot's long axis (heel and MT head at one place)", i);
    const Eigen::Vector3d ez = unit(ex.cross((ankle.row(i) - heel.row(i)).transpose()), "foot's plane (ankle, heel and MT head in a line)", i);
    set_axes(s, i, ex, ez.cross(ex), ez);
  }
  angular_motion(s, dt);
  return s;
}

/// I alpha + omega x I omega about the COM, lab frame.
Eigen::Vector3d angular_momentum_rate(const SegmentMotion3D& s, Eigen::Index i) {
  const Eigen::Matrix3d R = s.R(i);
  const Eigen::Matrix3d I = R * s.inertia_kgm2.asDiagonal() * R.transpose();
  const Eigen::Vector3d w = s.omega_rps.row(i).transpose();
  return I * s.alpha_rps2.row(i).transpose() + w.cross(I * w);
}

/// (sagittal, frontal, transverse) of a lab moment in a segment's frame (the header's signs).
Eigen::RowVector3d anatomical(const Eigen::Vector3d& M, const Eigen::Matrix3d& R, int side) {
  const Eigen::Vector3d c = R.transpose() * M;
  const double mirror = side == kLeft ? -1.0 : 1.0;
  return {c.z(), mirror * c.x(), mirror * c.y()};
}

/// The knee and ankle moved medially by their offsets, along the lateral axis made orthogonal to
/// the shank (knee - ankle as marked): the lateral axis points to the walker's right, so medial is
/// its opposite on the right leg and itself on the left.
void move_to_joint_centres(std::array<Eigen::MatrixX3d, kLandmarkCount>& p, const Eigen::MatrixX3d& lateral_axis, int side,
                           const JointCentreOffsets& o) {
  const auto k = static_cast<std::size_t>(side);
  if (o.knee_m[k] == 0 && o.ankle_m[k] == 0) return;
  Eigen::MatrixX3d& knee = p[static_cast<std::size_t>(landmark(side, kKnee))];
  Eigen::MatrixX3d& ankle = p[static_cast<std::size_t>(landmark(side, kAnkle))];
  const double to_medial = side == kRight ? -1.0 : 1.0;
  for (Eigen::Index i = 0; i < knee.rows(); ++i) {
    const Eigen::Vector3d ey = unit((knee.row(i) - ankle.row(i)).transpose(), "shank's long axis (knee and ankle at one place)", i);
    const Eigen::Vector3d lat = lateral_axis.row(i).transpose();
    const Eigen::Vector3d medial = to_medial * unit(lat - lat.dot(ey) * ey, "shank's lateral axis (the shank lies along the lateral axis)", i);
    knee.row(i) += o.knee_m[k] * medial.transpose();
    ankle.row(i) += o.ankle_m[k] * medial.transpose();
  }
}

}  // namespace

namespace {

/// leg_motion_3d, with each foot's foot-toes COM distance given (a block of a trial takes the
/// trial's first frame's) or, when null, taken at the first frame.
LegMotion3D leg_motion(const Model& model, const std::array<Eigen::MatrixX3d, kLandmarkCount>& landmark_lab_m,
                       const Eigen::MatrixX3d& lateral_axis, const Eigen::Vector3d& up, double rate_hz, double cutoff_hz,
                       const JointCentreOffsets& offsets, const std::array<double, 2>* foot_toes_distance) {
  const Eigen::Index n = lateral_axis.rows();
  for (const auto& p : landmark_lab_m)
    if (p.rows() != n) throw InputError("3D joint moments: the landmarks' lab positions do not match the lateral axes' frames");
  if (!(rate_hz > 0)) throw InputError("3D joint moments: the rate must be positive");
  std::array<Eigen::MatrixX3d, kLandmarkCount> p;
  for (int k = 0; k < kLandmarkCount; ++k) {
    const auto& q = landmark_lab_m[static_cast<std::size_t>(k)];
    if (!q.allFinite()) throw InputError(std::string("3D joint moments: landmark ") + std::to_string(k) + " has undefined samples");
    p[static_cast<std::size_t>(k)] = cutoff_hz > 0 && n > 3 ? Eigen::MatrixX3d(butterworth_filtfilt(Eigen::MatrixXd(q), rate_hz, cutoff_hz)) : q;
  }
  for (int side = 0; side < 2; ++side) move_to_joint_centres(p, lateral_axis, side, offsets);
  LegMotion3D out;
  out.up = up.normalized();
  out.gravity_mps2 = model.gravity_mps2;
  const double dt = 1.0 / rate_hz;
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    out.knee_m[k] = p[static_cast<std::size_t>(landmark(side, kKnee))];
    out.ankle_m[k] = p[static_cast<std::size_t>(landmark(side, kAnkle))];
    // The hip centre of this side: the lateral axis points to the walker's right.
    out.hip_m[k] = p[kHip] + (side == kRight ? 1.0 : -1.0) * offsets.hip_half_width_m * lateral_axis;
    out.thigh[k] = long_segment_motion(model.bodies[static_cast<std::size_t>(segment(side, kThigh))], kThighLongitudinalGyrationRatio,
                                       out.hip_m[k], out.knee_m[k], lateral_axis, dt, "thigh", "hip and knee");
    out.shank[k] = long_segment_motion(model.bodies[static_cast<std::size_t>(segment(side, kShank))], kShankLongitudinalGyrationRatio,
                                       out.knee_m[k], out.ankle_m[k], lateral_axis, dt, "shank", "knee and ankle");
    out.foot[k] = foot_motion(model, side, p, dt, foot_toes_distance ? (*foot_toes_distance)[k] : foot_toes_com_distance(model, side, p, 0));
  }
  return out;
}

}  // namespace

LegMotion3D leg_motion_3d(const Model& model, const std::array<Eigen::MatrixX3d, kLandmarkCount>& landmark_lab_m,
                          const Eigen::MatrixX3d& lateral_axis, const Eigen::Vector3d& up, double rate_hz, double cutoff_hz,
                          const JointCentreOffsets& offsets) {
  return leg_motion(model, landmark_lab_m, lateral_axis, up, rate_hz, cutoff_hz, offsets, nullptr);
}

std::array<double, 2> stance_peaks(const Eigen::VectorXd& kam, Eigen::Index first, Eigen::Index last) {
  const Eigen::Index mid = stance_second_half(first, last);
  const auto peak = [&](Eigen::Index from, Eigen::Index to) {
    double best = std::numeric_limits<double>::quiet_NaN();
    for (Eigen::Index i = from; i <= to; ++i)
      if (std::isfinite(kam[i]) && !(kam[i] <= best)) best = kam[i];
    return best;
  };
  return {peak(first, mid - 1), peak(mid, last)};
}

double stance_impulse(const Eigen::VectorXd& kam, const Eigen::VectorXd& time_s, Eigen::Index first, Eigen::Index last) {
  double impulse = 0;
  bool any = false;
  for (Eigen::Index i = first; i < last; ++i) {
    if (!std::isfinite(kam[i]) || !std::isfinite(kam[i + 1]) || !std::isfinite(time_s[i]) || !std::isfinite(time_s[i + 1])) continue;
    impulse += 0.5 * (time_s[i + 1] - time_s[i]) * (std::max(kam[i], 0.0) + std::max(kam[i + 1], 0.0));
    any = true;
  }
  return any ? impulse : std::numeric_limits<double>::quiet_NaN();
}

FootWrench3D foot_wrench(const Eigen::MatrixX3d& force_N, const Eigen::MatrixX3d& cop_m, const Eigen::VectorXd& free_moment_Nm,
                         const Eigen::Vector3d& up) {
  const Eigen::Index n = force_N.rows();
  if (cop_m.rows() != n || free_moment_Nm.size() != n) throw InputError("3D joint moments: force, COP and free moment differ in frames");
  FootWrench3D w;
  w.force_N = Eigen::MatrixX3d::Zero(n, 3);
  w.moment_origin_Nm = Eigen::MatrixX3d::Zero(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d F = force_N.row(i).transpose(), c = cop_m.row(i).transpose();
    if (!F.allFinite() || !c.allFinite()) continue;
    const double T = std::isfinite(free_moment_Nm[i]) ? free_moment_Nm[i] : 0.0;
    w.force_N.row(i) = F.transpose();
    w.moment_origin_Nm.row(i) = (c.cross(F) + T * up).transpose();
  }
  return w;
}

JointMoments3D joint_moments_3d(const LegMotion3D& legs, const std::array<FootWrench3D, 2>& feet) {
  const Eigen::Index n = legs.frames();
  const Eigen::Vector3d g = -legs.gravity_mps2 * legs.up;
  JointMoments3D out;
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    const FootWrench3D& w = feet[k];
    if (w.force_N.rows() != n || w.moment_origin_Nm.rows() != n)
      throw InputError(std::string("3D joint moments: the ") + side_name(side) + " foot's ground reaction does not match the frames");
    const SegmentMotion3D &foot = legs.foot[k], &shank = legs.shank[k], &thigh = legs.thigh[k];
    for (auto* m : {&out.ankle_Nm[k], &out.knee_Nm[k], &out.hip_Nm[k], &out.ankle_lab_Nm[k], &out.knee_lab_Nm[k], &out.hip_lab_Nm[k]})
      m->resize(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d A = legs.ankle_m[k].row(i).transpose(), K = legs.knee_m[k].row(i).transpose();
      const Eigen::Vector3d Gf = foot.com_m.row(i).transpose(), Gs = shank.com_m.row(i).transpose();
      Eigen::Vector3d F = w.force_N.row(i).transpose(), MO = w.moment_origin_Nm.row(i).transpose();
      if (!F.allFinite() || !MO.allFinite()) F.setZero(), MO.setZero();  // no reaction measured: none
      // The foot (the header's equations), then the shank above it.
      const Eigen::Vector3d Fa = foot.mass_kg * (foot.com_acc_mps2.row(i).transpose() - g) - F;
      const Eigen::Vector3d Ma = angular_momentum_rate(foot, i) - (MO - Gf.cross(F)) - (A - Gf).cross(Fa);
      const Eigen::Vector3d Fk = shank.mass_kg * (shank.com_acc_mps2.row(i).transpose() - g) + Fa;
      const Eigen::Vector3d Mk = angular_momentum_rate(shank, i) + (A - Gs).cross(Fa) + Ma - (K - Gs).cross(Fk);
      const Eigen::Vector3d P = legs.hip_m[k].row(i).transpose(), Gt = thigh.com_m.row(i).transpose();
      const Eigen::Vector3d Fh = thigh.mass_kg * (thigh.com_acc_mps2.row(i).transpose() - g) + Fk;
      const Eigen::Vector3d Mh = angular_momentum_rate(thigh, i) + (K - Gt).cross(Fk) + Mk - (P - Gt).cross(Fh);
      out.ankle_lab_Nm[k].row(i) = Ma.transpose();
      out.knee_lab_Nm[k].row(i) = Mk.transpose();
      out.hip_lab_Nm[k].row(i) = Mh.transpose();
      out.ankle_Nm[k].row(i) = anatomical(Ma, foot.R(i), side);
      out.knee_Nm[k].row(i) = anatomical(Mk, shank.R(i), side);
      out.hip_Nm[k].row(i) = anatomical(Mh, thigh.R(i), side);
    }
  }
  return out;
}

JointMoments3D joint_moments_3d_in_blocks(const Model& model, std::array<Eigen::MatrixX3d, kLandmarkCount> filtered,
                                          const Eigen::MatrixX3d& lateral_axis, const Eigen::Vector3d& up, double rate_hz, double cutoff_hz,
                                          const JointCentreOffsets& offsets, const std::array<FootWrench3D, 2>& feet, Eigen::Index block_frames) {
  const Eigen::Index n = lateral_axis.rows();
  if (block_frames < 1) throw InputError("3D joint moments: a block needs at least one frame");
  // The filter is the one step over the whole trial (zero-lag: every frame sees both ends).
  for (auto& q : filtered) {
    if (q.rows() != n) throw InputError("3D joint moments: the landmarks' lab positions do not match the lateral axes' frames");
    if (cutoff_hz > 0 && n > 3 && q.allFinite()) q = butterworth_filtfilt(Eigen::MatrixXd(std::move(q)), rate_hz, cutoff_hz);
  }
  // The trial's first frame's foot-toes distances (as the whole trial's leg_motion_3d takes them).
  std::array<double, 2> distance{0.0, 0.0};
  if (n > 0) {
    std::array<Eigen::MatrixX3d, kLandmarkCount> first;
    for (int k = 0; k < kLandmarkCount; ++k) first[static_cast<std::size_t>(k)] = filtered[static_cast<std::size_t>(k)].topRows(1);
    for (int side = 0; side < 2; ++side) move_to_joint_centres(first, lateral_axis.topRows(1), side, offsets);
    for (int side = 0; side < 2; ++side) distance[static_cast<std::size_t>(side)] = foot_toes_com_distance(model, side, first, 0);
  }
  JointMoments3D out;
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    if (feet[k].force_N.rows() != n || feet[k].moment_origin_Nm.rows() != n)
      throw InputError(std::string("3D joint moments: the ") + side_name(side) + " foot's ground reaction does not match the frames");
    for (auto* m : {&out.ankle_Nm[k], &out.knee_Nm[k], &out.hip_Nm[k], &out.ankle_lab_Nm[k], &out.knee_lab_Nm[k], &out.hip_lab_Nm[k]})
      m->resize(n, 3);
  }
  for (Eigen::Index a = 0; a < n; a += block_frames) {
    const Eigen::Index len = std::min(block_frames, n - a);
    const Eigen::Index lo = std::max<Eigen::Index>(0, a - kBlockHaloFrames), hi = std::min(n, a + len + kBlockHaloFrames);
    std::array<Eigen::MatrixX3d, kLandmarkCount> p;
    for (int k = 0; k < kLandmarkCount; ++k) p[static_cast<std::size_t>(k)] = filtered[static_cast<std::size_t>(k)].middleRows(lo, hi - lo);
    std::array<FootWrench3D, 2> w;
    for (std::size_t k = 0; k < 2; ++k)
      w[k] = {feet[k].force_N.middleRows(lo, hi - lo), feet[k].moment_origin_Nm.middleRows(lo, hi - lo)};
    const JointMoments3D m =
        joint_moments_3d(leg_motion(model, p, lateral_axis.middleRows(lo, hi - lo), up, rate_hz, 0.0, offsets, &distance), w);
    for (std::size_t k = 0; k < 2; ++k) {
      out.ankle_Nm[k].middleRows(a, len) = m.ankle_Nm[k].middleRows(a - lo, len);
      out.knee_Nm[k].middleRows(a, len) = m.knee_Nm[k].middleRows(a - lo, len);
      out.hip_Nm[k].middleRows(a, len) = m.hip_Nm[k].middleRows(a - lo, len);
      out.ankle_lab_Nm[k].middleRows(a, len) = m.ankle_lab_Nm[k].middleRows(a - lo, len);
      out.knee_lab_Nm[k].middleRows(a, len) = m.knee_lab_Nm[k].middleRows(a - lo, len);
      out.hip_lab_Nm[k].middleRows(a, len) = m.hip_lab_Nm[k].middleRows(a - lo, len);
    }
  }
  return out;
}

}  // namespace kin2grf
