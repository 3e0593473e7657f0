// kin2grf validation: the joint moments driven by the estimate against driven by the plates, on
// the same kinematics: in 3D (validate_joint_moments_3d) and the sagittal model's joint torques
// (validate_joint_torques; validate.hpp).
#include <cmath>
#include <limits>
#include <string>

#include "kin2grf/dynamics/joint_moments_2d.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/validation/validate.hpp"

namespace kin2grf {

namespace {

/// Each foot's kept stances' plate wrenches (lab), zero elsewhere.
std::array<FootWrench3D, 2> plate_wrenches(const ValidationResult& v, Eigen::Index n) {
  std::array<FootWrench3D, 2> out;
  for (auto& w : out) w = {Eigen::MatrixX3d::Zero(n, 3), Eigen::MatrixX3d::Zero(n, 3)};
  for (const StanceValidation& s : v.stances) {
    if (s.plate_index < 0) continue;
    const MeasuredPlate& mp = v.plates[static_cast<std::size_t>(s.plate_index)];
    FootWrench3D& w = out[static_cast<std::size_t>(s.foot)];
    for (Eigen::Index i = s.first; i <= s.last; ++i)
      if (mp.force_lab_N.row(i).allFinite() && mp.moment_origin_lab_Nm.row(i).allFinite()) {
        w.force_N.row(i) += mp.force_lab_N.row(i);
        w.moment_origin_Nm.row(i) += mp.moment_origin_lab_Nm.row(i);
      }
  }
  return out;
}

}  // namespace

void validate_joint_moments_3d(const EstimateResult& e, ValidationResult& v) {
  if (!e.legs_3d) return;
  const Eigen::Index n = e.time_s.size();
  if (e.legs_3d->motion.frames() != n) {
    static const std::string why = "3D joint moments not compared: the estimate was made without its per-frame series (keep_all_series)";
    v.notes.push_back(why);
    return;
  }
  const JointMoments3D measured = joint_moments_3d(e.legs_3d->motion, plate_wrenches(v, n));
  const JointMoments3D& estimated = e.legs_3d->moments;
  for (StanceValidation& s : v.stances) {
    const auto k = static_cast<std::size_t>(s.foot);
    const Eigen::Index a = s.first, len = s.last - s.first + 1;
    JointMomentValidation j;
    for (int c = 0; c < 3; ++c) {
      j.ankle[static_cast<std::size_t>(c)] = compare_series(estimated.ankle_Nm[k].col(c).segment(a, len), measured.ankle_Nm[k].col(c).segment(a, len));
      j.knee[static_cast<std::size_t>(c)] = compare_series(estimated.knee_Nm[k].col(c).segment(a, len), measured.knee_Nm[k].col(c).segment(a, len));
      j.hip[static_cast<std::size_t>(c)] = compare_series(estimated.hip_Nm[k].col(c).segment(a, len), measured.hip_Nm[k].col(c).segment(a, len));
    }
    const Eigen::VectorXd kam_e = knee_adduction_moment(estimated, s.foot), kam_m = knee_adduction_moment(measured, s.foot);
    j.knee_adduction = compare_series(kam_e.segment(a, len), kam_m.segment(a, len));
    j.kam_peak_estimated_Nm = stance_peaks(kam_e, a, s.last);
    j.kam_peak_measured_Nm = stance_peaks(kam_m, a, s.last);
    j.kam_impulse_estimated_Nm_s = stance_impulse(kam_e, e.time_s, a, s.last);
    j.kam_impulse_measured_Nm_s = stance_impulse(kam_m, e.time_s, a, s.last);
    s.moments_3d = j;
  }
  v.measured_moments_3d = measured;
}

void validate_joint_torques(const EstimateResult& e, ValidationResult& v) {
  const Eigen::Index n = e.time_s.size();
  if (e.joint_torque_Nm.rows() != n || e.motion.frames() != n) return;
  // One wrench series per foot and source, zero outside; each stance reads its own foot's frames.
  std::array<FootWrench2D, 2> estimated, measured;
  for (int side = 0; side < 2; ++side) {
    const FootResult& f = e.feet[static_cast<std::size_t>(side)];
    FootWrench2D& w = estimated[static_cast<std::size_t>(side)];
    w = {Eigen::MatrixX2d::Zero(n, 2), Eigen::VectorXd::Zero(n)};
    measured[static_cast<std::size_t>(side)] = w;
    for (Eigen::Index i = 0; i < n; ++i)
      if (f.contact[static_cast<std::size_t>(i)] && std::isfinite(f.cop_x_m[i])) {
        w.force_N.row(i) = f.force_N.row(i);
        w.moment_origin_Nm[i] = sagittal_moment(f.cop_x_m[i], e.ground_level_m(), f.force_N(i, 0), f.force_N(i, 1));
      }
  }
  // Where the plate reads (not past the end of a recording that stops inside the stance).
  const auto reads = [](const MeasuredPlate& mp, Eigen::Index i) { return mp.force_N.row(i).allFinite() && std::isfinite(mp.moment_origin_Nm[i]); };
  bool any = false;
  for (const StanceValidation& s : v.stances) {
    if (s.plate_index < 0 || s.cop_reference_suspect) continue;
    const MeasuredPlate& mp = v.plates[static_cast<std::size_t>(s.plate_index)];
    FootWrench2D& w = measured[static_cast<std::size_t>(s.foot)];
    for (Eigen::Index i = s.first; i <= s.last; ++i)
      if (reads(mp, i)) {
        w.force_N.row(i) += mp.force_N.row(i);
        w.moment_origin_Nm[i] += mp.moment_origin_Nm[i];
      }
    any = true;
  }
  if (!any) return;
  const Eigen::MatrixXd tau_estimated = bottom_up_joint_torques(e.motion, estimated);
  const Eigen::MatrixXd tau_measured = bottom_up_joint_torques(e.motion, measured);
  const Eigen::MatrixXd omega = joint_angular_velocity_series(e.motion);  // for the powers
  v.measured_joint_torque_Nm = Eigen::MatrixXd::Constant(n, kJointCount, std::numeric_limits<double>::quiet_NaN());
  for (StanceValidation& s : v.stances) {
    if (s.plate_index < 0 || s.cop_reference_suspect) continue;
    const MeasuredPlate& mp = v.plates[static_cast<std::size_t>(s.plate_index)];
    const Eigen::Index a = s.first, len = s.last - s.first + 1;
    // NaN where the plate does not read: not compared.
    Eigen::VectorXd plate_reads = Eigen::VectorXd::Zero(len);
    for (Eigen::Index k = 0; k < len; ++k)
      if (!reads(mp, a + k)) plate_reads[k] = std::numeric_limits<double>::quiet_NaN();
    JointTorqueValidation t;
    t.mass_kg = e.mass_kg;
    for (int c = 0; c < 3; ++c) {  // hip, knee, ankle: joints 4 side + c
      const int j = 4 * s.foot + c;
      const Eigen::VectorXd plate = tau_measured.col(j).segment(a, len) + plate_reads;
      t.least_squares[static_cast<std::size_t>(c)] = compare_series(e.joint_torque_Nm.col(j).segment(a, len), plate);
      t.bottom_up[static_cast<std::size_t>(c)] = compare_series(tau_estimated.col(j).segment(a, len), plate);
      const Eigen::VectorXd w = omega.col(j).segment(a, len);
      const Eigen::VectorXd power_estimated = e.joint_torque_Nm.col(j).segment(a, len).cwiseProduct(w);
      const Eigen::VectorXd power_measured = plate.cwiseProduct(w);
      t.power[static_cast<std::size_t>(c)] = compare_series(power_estimated, power_measured);
    }
    for (int c = 0; c < 4; ++c)  // the leg's four joints, over the stance (the MTP's is the toes' inertia alone)
      v.measured_joint_torque_Nm.col(4 * s.foot + c).segment(a, len) = tau_measured.col(4 * s.foot + c).segment(a, len) + plate_reads;
    t.peaks_measured = joint_kinetic_peaks(v.measured_joint_torque_Nm, e.motion, s.foot, s.first, s.last);
    t.peaks_estimated = joint_kinetic_peaks(e.joint_torque_Nm, e.motion, s.foot, s.first, s.last);
    s.torques = t;
  }
}

void validate_total_3d(const EstimateResult& e, ValidationResult& v) {
  const Eigen::Index n = e.time_s.size();
  if (!v.total || e.feet[0].force_lateral_N.size() != n) return;
  TotalValidation& t = *v.total;
  double lateral = 0;
  for (Eigen::Index k : t.frames) lateral += 0.5 * (e.foot_lateral_m[0][k] + e.foot_lateral_m[1][k]);
  t.lateral_reference_m = lateral / static_cast<double>(t.frames.size());
  const std::array<FootWrench3D, 2> feet = estimated_wrenches(e);
  const auto m = static_cast<Eigen::Index>(t.frames.size());
  Eigen::VectorXd ef(m), mf(m), et(m), mt(m);
  for (Eigen::Index q = 0; q < m; ++q) {
    const Eigen::Index k = t.frames[static_cast<std::size_t>(q)], trial_k = e.first_index + k;
    const Eigen::Vector3d P = e.frame.to_lab(t.grm_reference_m.x(), t.grm_reference_m.y(), t.lateral_reference_m, trial_k);
    Eigen::Vector3d Fe = Eigen::Vector3d::Zero(), Me = Eigen::Vector3d::Zero(), Fm = Eigen::Vector3d::Zero(), Mm = Eigen::Vector3d::Zero();
    for (const FootWrench3D& w : feet) Fe += w.force_N.row(k).transpose(), Me += w.moment_origin_Nm.row(k).transpose();
    for (const MeasuredPlate& p : v.plates)
      if (p.force_lab_N.rows() == n && p.force_lab_N.row(k).allFinite() && p.moment_origin_lab_Nm.row(k).allFinite())
        Fm += p.force_lab_N.row(k).transpose(), Mm += p.moment_origin_lab_Nm.row(k).transpose();
    const Eigen::Vector3d MPe = Me - P.cross(Fe), MPm = Mm - P.cross(Fm);
    const Eigen::Vector3d fw = e.frame.forward_at(trial_k);
    ef[q] = MPe.dot(fw), mf[q] = MPm.dot(fw);
    et[q] = MPe.dot(e.frame.up), mt[q] = MPm.dot(e.frame.up);
  }
  t.frontal_moment = compare_series(ef, mf);
  t.transverse_moment = compare_series(et, mt);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::VectorXd* x : {&t.frontal_estimated_Nm, &t.frontal_measured_Nm, &t.transverse_estimated_Nm, &t.transverse_measured_Nm})
    x->setConstant(n, nan);
  for (Eigen::Index q = 0; q < m; ++q) {
    const Eigen::Index k = t.frames[static_cast<std::size_t>(q)];
    t.frontal_estimated_Nm[k] = ef[q], t.frontal_measured_Nm[k] = mf[q];
    t.transverse_estimated_Nm[k] = et[q], t.transverse_measured_Nm[k] = mt[q];
  }
}

}  // namespace kin2grf
