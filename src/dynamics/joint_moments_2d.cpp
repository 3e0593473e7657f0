// kin2grf dynamics: the sagittal joint torques, bottom-up (dynamics/joint_moments_2d.hpp).
#include "kin2grf/dynamics/joint_moments_2d.hpp"

#include <cmath>

#include "kin2grf/dynamics/stance_parameters.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {

double bottom_up_joint_torque(const Model& model, const MotionFrame& m, int j, const Eigen::Vector2d& force_N,
                              double moment_origin_Nm) {
  const int side = j / 4, depth = j % 4;
  const int p = model.bodies[static_cast<std::size_t>(joint_child(j))].proximal;
  const double px = m.q(coord::point_x(p)), py = m.q(coord::point_x(p) + 1);
  const double g = model.gravity_mps2;
  double tau = 0.0;
  for (int k = depth; k < 4; ++k) {
    const int s = segment(side, static_cast<LegSegment>(k));
    const Body& b = model.bodies[static_cast<std::size_t>(s)];
    const double fx = b.mass_kg * m.qdd(coord::com_x(s)), fy = b.mass_kg * (m.qdd(coord::com_x(s) + 1) + g);
    tau += sagittal_moment(m.q(coord::com_x(s)) - px, m.q(coord::com_x(s) + 1) - py, fx, fy) +
           b.inertia_kgm2 * m.qdd(coord::theta(s));
  }
  // The ground acts on the foot: on every joint's subtree but the MTP's (the toes alone).
  if (depth <= kFoot)
    tau -= moment_origin_Nm - sagittal_moment(px, py, force_N.x(), force_N.y());
  return tau;
}

Eigen::MatrixXd bottom_up_joint_torques(const ModelMotion& motion, const std::array<FootWrench2D, 2>& feet) {
  const Eigen::Index n = motion.frames();
  Eigen::MatrixXd tau(n, kJointCount);
  MotionFrame m;
  for (Eigen::Index i = 0; i < n; ++i) {
    motion.frame(i, m);
    for (int j = 0; j < kJointCount; ++j) {
      const FootWrench2D& w = feet[static_cast<std::size_t>(j / 4)];
      tau(i, j) = bottom_up_joint_torque(*motion.model, m, j, w.force_N.row(i).transpose(), w.moment_origin_Nm[i]);
    }
  }
  return tau;
}

std::array<double, kJointCount> joint_angular_velocities(const ModelMotion& motion, Eigen::Index i) {
  // Columns 3..10 of the independent coordinates are the joint angles (independent_coordinates).
  std::array<double, kMaxIndependent> d1{}, d2{};
  motion.derivatives_at(i, d1.data(), d2.data());
  std::array<double, kJointCount> w{};
  for (std::size_t j = 0; j < w.size(); ++j) w[j] = d1[3 + j];
  return w;
}

Eigen::MatrixXd joint_angular_velocity_series(const ModelMotion& motion) {
  Eigen::MatrixXd omega(motion.frames(), kJointCount);
  for (Eigen::Index i = 0; i < omega.rows(); ++i) {
    const std::array<double, kJointCount> w = joint_angular_velocities(motion, i);
    for (int j = 0; j < kJointCount; ++j) omega(i, j) = w[static_cast<std::size_t>(j)];
  }
  return omega;
}

JointKineticPeaks joint_kinetic_peaks(const Eigen::MatrixXd& torque_Nm, const ModelMotion& motion, int side, Eigen::Index first,
                                      Eigen::Index last) {
  JointKineticPeaks p;
  if (first < 0 || last < first || last >= torque_Nm.rows() || last >= motion.frames()) return p;
  const int hip = 4 * side, knee = hip + 1, ankle = hip + 2;
  const Eigen::Index mid = stance_second_half(first, last);
  // The largest positive value of x over the frames, NaN without one (fmax skips the NaN start).
  const auto peak = [](double& best, double x) {
    if (x > 0) best = std::fmax(best, x);
  };
  for (Eigen::Index i = first; i <= last; ++i) {
    const bool second = i >= mid;
    peak(p.ankle_plantarflexor_moment_Nm, -torque_Nm(i, ankle));
    if (second) {
      peak(p.ankle_push_off_power_W, torque_Nm(i, ankle) * joint_angular_velocities(motion, i)[static_cast<std::size_t>(ankle)]);
      peak(p.hip_flexor_moment_Nm, torque_Nm(i, hip));
    } else {
      peak(p.knee_extensor_moment_Nm, torque_Nm(i, knee));
      peak(p.hip_extensor_moment_Nm, -torque_Nm(i, hip));
    }
  }
  return p;
}

}  // namespace kin2grf
