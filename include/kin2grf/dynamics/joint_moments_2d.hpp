// kin2grf dynamics: the sagittal model's joint torques by bottom-up Newton-Euler inverse dynamics
// with a given ground reaction (kin2grf, not the paper: what a gait lab computes from its plates).
//
// The paper's joint torques are Lagrange multipliers (Eq. 7): the least squares spreads whatever
// the contact forces leave of the whole body's motion (the residual) over every joint. A lab's
// inverse dynamics instead works up each leg from its own plate, so its torques answer to that
// foot's ground reaction and that leg's motion alone. `validate` runs this function with each
// foot's plate on the estimate's own motion: the difference from the estimate's torques is then
// the estimate's alone (as validate_joint_moments_3d does in 3D).
//
// For joint j (hip, knee, ankle, MTP of a side) at point P (the child body's proximal point), the
// child's subtree S (the thigh, shank, foot and toes for the hip; the toes alone for the MTP),
// each body s with mass m_s, COM r_s, inertia I_s about it, angle theta_s, g = (0, -g):
//   tau_j = sum_{s in S} [ (r_s - P) x m_s (r_s'' - g) + I_s theta_s'' ]  -  (M_O - P x F)
// with F the ground force on the foot and M_O its moment about the lab origin (a COP c: M_O = c x F),
// 2D cross product a x b = a_x b_y - a_y b_x. tau_j is the moment the parent exerts on the child,
// counter-clockwise positive in the sagittal frame: the sign of EstimateResult::joint_torque_Nm.
// The ground force acts on the foot (as model 2's point D, which the foot carries), so it enters
// the hip, knee and ankle and not the MTP, whose torque is the toes' own inertia. Where the
// contact forces explain the whole body's motion exactly (both feet down: four multipliers for
// three equations, Eq. 7's residual zero), the least squares' torques are these, to round-off
// (test JointMoments2D.TheLeastSquaresTorquesAreTheBottomUpOnesWhereTheContactsExplainTheMotion).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <limits>

#include "kin2grf/kinematics/motion.hpp"

namespace kin2grf {

/// One foot's ground reaction over a trial, sagittal frame: force (anterior, vertical), N, and
/// its moment about the lab origin, N m (counter-clockwise +); zero where the foot is unloaded.
struct FootWrench2D {
  Eigen::MatrixX2d force_N;
  Eigen::VectorXd moment_origin_Nm;
};

/// Joint j's torque (N m, on the child, counter-clockwise +) at one frame, by the formula above.
double bottom_up_joint_torque(const Model& model, const MotionFrame& m, int j, const Eigen::Vector2d& force_N,
                              double moment_origin_Nm);

/// Every joint's torque over the trial (N x kJointCount, the columns of EstimateResult::
/// joint_torque_Nm), each leg from its own foot's wrench (`feet`: right, left; N rows each).
Eigen::MatrixXd bottom_up_joint_torques(const ModelMotion& motion, const std::array<FootWrench2D, 2>& feet);

/// The joints' angular velocities at frame i, rad/s: phi_j' = theta_child' - theta_parent' (the
/// motion's independent coordinates, differentiated as the dynamics' accelerations are). A joint's
/// power is tau_j phi_j' (W): the torque on the child turns with theta_child', the parent's
/// reaction -tau_j with theta_parent'. + the joint generates energy (its muscles shorten), - it
/// absorbs it.
std::array<double, kJointCount> joint_angular_velocities(const ModelMotion& motion, Eigen::Index i);
/// The same over every frame, N x kJointCount (the columns of EstimateResult::joint_torque_Nm):
/// a whole trial's powers are joint_torque_Nm.cwiseProduct(this).
Eigen::MatrixXd joint_angular_velocity_series(const ModelMotion& motion);

/// One stance's sagittal joint kinetics as a gait report reads them: the peaks of the internal
/// moments in their clinical senses, N m, and of the ankle's power, W (NaN: no such value, e.g. a
/// moment that never acts in that sense). The sagittal frame's x points forward and torques are
/// counter-clockwise + on the distal segment, so a plantarflexor moment (toes pushed down) is
/// -tau_ankle, a knee extensor moment +tau_knee, a hip extensor moment -tau_hip and a hip flexor
/// moment +tau_hip. Halves of the stance as the stance parameters' (dynamics/stance_parameters.hpp):
/// the loading response's peaks in the first half, push-off's in the second.
struct JointKineticPeaks {
  double ankle_plantarflexor_moment_Nm = std::numeric_limits<double>::quiet_NaN();  ///< over the stance
  double ankle_push_off_power_W = std::numeric_limits<double>::quiet_NaN();         ///< second half (the A2 burst)
  double knee_extensor_moment_Nm = std::numeric_limits<double>::quiet_NaN();        ///< first half
  double hip_extensor_moment_Nm = std::numeric_limits<double>::quiet_NaN();         ///< first half
  double hip_flexor_moment_Nm = std::numeric_limits<double>::quiet_NaN();           ///< second half
};
/// The peaks of side `side`'s stance over frames first..last (inclusive) of `torque_Nm` (N x
/// kJointCount, EstimateResult::joint_torque_Nm's columns) on `motion`. A peak in a sense the
/// moment never takes is NaN (the largest of -tau where tau stays positive is not a peak).
JointKineticPeaks joint_kinetic_peaks(const Eigen::MatrixXd& torque_Nm, const ModelMotion& motion, int side, Eigen::Index first,
                                      Eigen::Index last);

}  // namespace kin2grf
