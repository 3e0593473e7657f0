// kin2grf dynamics: the mediolateral ground reaction force (kin2grf, not the paper: its authors'
// "GRF along the lateral axis" future work; issue 28's first step). The sagittal model's
// multipliers are unchanged; this adds a force along the sagittal frame's lateral axis
// (SagittalFrame::lateral = forward x up) to each foot.
//
// Total (Newton's second law across the plane; gravity has no lateral part):
//   F_z(t) = M a_Gz(t),  z_G = sum_s m_s z_s / M,
// with each segment's COM on the line between its proximal and distal landmarks at its
// anthropometric fraction (the model's com_local), the arms and the head where their markers
// hold data at their own COMs, their mass taken off the HAT's (UpperBodySegments: an arm swings
// sideways on its own, 7 N of lateral force on a 70 kg walker at 1 m/s^2); the COM's lab
// position is low-pass filtered (`cutoff_hz`, EstimateOptions::lateral_cutoff_hz: the body's
// sway is slow, the skin markers' noise is not), differentiated twice (central differences) and
// projected on each frame's lateral axis.
//
// Split between the feet in contact (k = right, left). Each foot in contact carries its own
// lower leg's lateral inertia (shank, foot and toes: L_k = sum m_s a_s,z over them), the rest
// shared by the feet's vertical forces F_y,k (the sagittal solve's, post-filtered):
//   F_z,k = L_k + (F_z - sum_{j in contact} L_j) F_y,k / sum_j F_y,j,
// so that a foot alone carries F_z and a double support shares the body above the shanks as it
// shares the weight; zero where a foot is not in contact, and in flight. Why: a landing foot
// brakes its own shank's and foot's sideways swing (its plate's brief lateral force at heel
// strike, 10-20 N on the development walks) while it takes almost no weight yet; the load share
// alone gave that force to the trailing foot. The lower legs' motion is the crisp one (bony
// landmarks, not the trunk's skin): it is filtered at the dynamics' kinematic cut-off, the whole
// body's at `cutoff_hz`. The thigh stays in the shared part: its proximal end is the pelvis's.
// An inverted-pendulum split (each foot's reaction pointing from its COP to the COM,
// F_y,k (z_G - z_k) / (y_G - y_ground), which gives the feet opposite signs in double support)
// was measured and lost on every development lab's walks (per-foot rRMSE 24-53 % against
// 14-33 %; docs/METHOD-NOTES.md), and so did a share of it added in double support only
// (session 22: 16.1 -> 16.2-19.2 % walking at weights 0.15-0.5).
#pragma once
#include "kin2grf/dynamics/joint_moments_3d.hpp"

#include <Eigen/Dense>
#include <array>
#include <vector>

#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/markers/landmarks.hpp"
#include "kin2grf/model/anthropometry.hpp"
#include "kin2grf/model/model.hpp"

namespace kin2grf {

/// The arms and the head as segments of their own (kin2grf's 3D model; issue 28): each part's mass
/// (a fraction of body mass from the anthropometric table) at its own COM's lab position, N x 3,
/// its mass taken off the HAT's COM. An upper arm's COM lies between shoulder and elbow at its
/// table fraction, a forearm's between elbow and wrist, the hand's at the wrist, the head's at its
/// markers' mean. An arm needs its shoulder, elbow and wrist landmarks.
struct UpperBodySegments {
  struct Part {
    double mass_fraction = 0.0;
    Eigen::MatrixX3d com_m;
  };
  std::vector<Part> parts;
  std::string description;  ///< "the right arm, the left arm and the head"; empty: none
};
UpperBodySegments upper_body_segments(const std::array<Eigen::MatrixX3d, kUpperBodyCount>& lab_m, const AnthropometricTable& table);

/// What the split needs of one foot: its vertical force (N) and contact state, per frame.
struct FootLoad {
  const Eigen::VectorXd* vertical_N = nullptr;
  const std::vector<bool>* contact = nullptr;
};

struct MediolateralForces {
  Eigen::VectorXd total_N;                  ///< M a_Gz, per frame
  std::array<Eigen::VectorXd, 2> lower_leg_N;  ///< L_k, each lower leg's lateral inertia (N)
  Eigen::VectorXd com_lateral_m;            ///< z_G, filtered
  std::array<Eigen::VectorXd, 2> foot_N;    ///< per foot (right, left), zero without contact
};

/// The whole body's centre of mass as two weighted sums of the landmarks (sagittal_landmarks'
/// lab_sums): [0] every segment but the HAT, each at its COM fraction between its proximal and
/// distal landmarks with m_s / M, [1] the HAT's own COM (weights summing to 1). The COM is [0] +
/// s [1] + the upper body's parts (whole_body_lateral), s the HAT's share of the mass less theirs:
/// mediolateral_forces' COM, made without holding every landmark's lab position. The weights
/// depend on the table's fractions only (the model's lengths do not enter).
std::vector<std::array<double, kLandmarkCount>> com_landmark_weights(const Model& model);

/// The whole body's lateral place and lateral inertial force (the frontal balance's,
/// EstimateOptions::frontal_split_weight): the COM of com_landmark_weights' two sums, the HAT's
/// at its share, and `upper`'s parts, low-pass filtered at `cutoff_hz`, its lateral coordinate
/// (z_G, m) and M a_Gz (N), each frame's lateral axis taken as mediolateral_forces takes it (the
/// acceleration in the lab, then projected). No lag.
struct WholeBodyLateral {
  Eigen::VectorXd com_lateral_m, total_N;
};
WholeBodyLateral whole_body_lateral(const Model& model, const std::vector<Eigen::MatrixX3d>& lab_sums, const UpperBodySegments* upper,
                                    const Eigen::MatrixX3d& lateral_axis, double rate_hz, double cutoff_hz);

/// `landmark_lab_m`: each landmark's lab position (unfiltered), N x 3; `lateral_axis`: each
/// frame's lateral axis, N x 3 (a turning walk's rotates: the acceleration is taken in the lab and
/// projected, so the frame's rotation adds nothing); `motion`: the sagittal motion (its model's
/// masses, its rate and frames); `cutoff_hz`: the whole body's lateral acceleration's cut-off
/// (EstimateOptions::lateral_cutoff_hz); `leg_cutoff_hz`: the lower legs' (the dynamics'
/// kinematic cut-off; 0: `cutoff_hz`); `own_leg_inertia` false: the load share alone (the
/// split before issue 28's third step, for comparison); `upper_body_lag_s`: the torso's share
/// of the COM (the HAT less the arms and head of their own) enters the total delayed by this
/// (a(t - tau), as lag_torso_fore_aft delays its fore-aft acceleration: the upper body's mass,
/// mostly viscera, arms and head on a compliant spine, follows the pelvis late sideways too),
/// except on the frames `near_flight` flags (flight_frames), which take the total as measured.
MediolateralForces mediolateral_forces(const ModelMotion& motion, const std::array<Eigen::MatrixX3d, kLandmarkCount>& landmark_lab_m,
                                       const Eigen::MatrixX3d& lateral_axis, double cutoff_hz, const std::array<FootLoad, 2>& feet,
                                       double leg_cutoff_hz = 0.0, bool own_leg_inertia = true, const UpperBodySegments* upper = nullptr,
                                       double upper_body_lag_s = 0.0, const std::vector<bool>* near_flight = nullptr);

/// The paper's least squares (Eq. 5: the multipliers of least norm, joint torques in it) for the
/// lateral split of a bilateral stance (the pipeline's: a landing's, both feet on the ground near
/// a flight phase): at each flagged frame the two feet's lateral forces F_0 + F_1 =
/// T (the whole body's, as mediolateral_forces gave it) minimise the sum of the squared 3D joint
/// moments of both legs (ankle, knee, hip; lab-frame vectors), which are linear in them:
///   M_jk = a_jk + h_jk F_k,   a: the moments with those frames' lateral forces zero (`zero`),
///   h = `unit` - `zero` (`unit`: with 1 N on each foot; h_jk = (J - c_k) x e, J the joint,
///   c_k the COP, e the lateral axis), so
///   F_0 = (A_1 T + B_1 - B_0) / (A_0 + A_1),  A_k = sum_j |h_jk|^2,  B_k = sum_j a_jk . h_jk.
/// A walking handover keeps the split of mediolateral_forces (measured better there on every
/// walk), and so does quiet standing (Camargo's gait initiation, slightly); a landing is where
/// the feet push apart or together, which a share of one total cannot give (the drop jump:
/// per-foot lateral rRMSE 70 / 62 -> 43 / 41 %; docs/METHOD-NOTES.md). `foot_N` (per foot) is changed at the flagged
/// frames; the returned moments are `zero`'s, with those frames' made the new forces' (linear).
JointMoments3D least_squares_lateral_split(const JointMoments3D& zero, const JointMoments3D& unit, const std::vector<bool>& frames,
                                           std::array<Eigen::VectorXd, 2>& foot_N);

}  // namespace kin2grf
