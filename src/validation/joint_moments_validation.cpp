// kin2grf validation: the 3D joint moments driven by the estimate against driven by the plates,
// on the same leg kinematics (validate.hpp, validate_joint_moments_3d).
#include <cmath>
#include <string>

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
    s.moments_3d = j;
  }
  v.measured_moments_3d = measured;
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
}

}  // namespace kin2grf
