// kin2grf dynamics: 3D ankle, knee and hip moments by bottom-up Newton-Euler inverse dynamics
// (kin2grf, not the paper: issue 28's third step, the knee adduction moment clinicians read).
//
// Run on the same leg kinematics (LegMotion3D, made once) with any ground reaction: the estimate's
// and, in `validate`, the plates', so that the difference between the two is the estimate's alone.
//
// Segments, per side, from the model's landmarks in the lab (markers/landmarks.hpp), the knee and
// the ankle moved to the joint centres first where their markers are on the lateral skin
// (JointCentreOffsets: medially along the lateral axis made orthogonal to the shank; the sagittal
// model needs no such move, the 3D frontal moments do: 5 cm of knee lever at 700 N is 35 N m of
// knee adduction moment):
//   thigh: hip centre -> knee. The hip centre of each side: the model's hip landmark (the two
//     centres' midpoint) moved along the lateral axis by half their distance (JointCentreOffsets::
//     hip_half_width_m: the hip rule's own, else kHipHalfWidthPerThigh of the thigh): the pelvis's
//     obliquity and rotation (a few degrees) are left out. Frame as the shank's, thigh axis up.
//   shank: knee -> ankle. Frame: e_y = (knee - ankle) / |.| (up the segment), e_z = the sagittal
//     frame's lateral axis (to the walker's right) made orthogonal to e_y, e_x = e_y x e_z
//     (anterior). The landmarks give no axial rotation of the shank, so its frame takes the
//     walker's heading (a documented fallback; its long-axis inertia is a tenth of the others').
//   foot: ankle, heel, MT head, with the toes lumped in (foot + toes mass, mass-weighted COM).
//     Frame: e_x = (MT - heel) / |.|, e_z = e_x x (ankle - heel) / |.| (to the right), e_y =
//     e_z x e_x. Three landmarks: a full 3D frame.
// Landmarks are filtered at the dynamics' kinematic cut-off (zero-lag Butterworth), COMs on the
// proximal-distal line at the model's fraction, accelerations by second differences; angular
// velocity omega = vee(dR/dt R^T), angular acceleration its central difference (lab frame).
// Inertia: principal, about the COM in the segment frame: the model's sagittal inertia about the
// two transverse axes and (rho_long / rho_sag)^2 of it about the long axis, de Leva 1996 (male,
// Table 4): shank 0.103 / 0.255, foot 0.124 / 0.257 (Winter's table gives no longitudinal radius).
//
// Newton-Euler, lab frame, g = -gravity up; F, M_O: the foot's ground force (N) and its moment
// about the lab origin (N m; c x F + T up for a COP c and a free moment T about up);
// H = R I R^T alpha + omega x (R I R^T omega):
//   foot:  F_a = m_f (a_f - g) - F
//          M_a = H_f - (M_O - G_f x F) - (A - G_f) x F_a
//   shank: F_k = m_s (a_s - g) + F_a
//          M_k = H_s + (A - G_s) x F_a + M_a - (K - G_s) x F_k
//   thigh: F_h = m_t (a_t - g) + F_k
//          M_h = H_t + (K - G_t) x F_k + M_k - (P - G_t) x F_h
// F_a, M_a: the force and moment the shank exerts on the foot at the ankle A (internal, on the
// distal segment); F_k, M_k the thigh's on the shank at the knee K; F_h, M_h the pelvis's on the
// thigh at the hip centre P.
//
// Components, in the distal segment's frame (the ankle's in the foot's, the knee's in the shank's),
// anatomical so that both sides read alike:
//   (the hip's in the thigh's)
//   sagittal   M . e_z, counter-clockwise + in the sagittal frame (the 2D joint torques' sign);
//   frontal    + adducts the distal segment (right M . e_x, left -M . e_x): at the knee, an
//              internal adductor moment; the external knee adduction moment (KAM) is its negative;
//   transverse + rotates the distal segment internally (right M . e_y, left -M . e_y).
#pragma once

#include <Eigen/Dense>
#include <array>

#include "kin2grf/model/model.hpp"

namespace kin2grf {

/// De Leva's (1996) longitudinal over sagittal radius of gyration (see above).
inline constexpr double kShankLongitudinalGyrationRatio = 0.103 / 0.255, kFootLongitudinalGyrationRatio = 0.124 / 0.257,
                        kThighLongitudinalGyrationRatio = 0.149 / 0.329;
/// Without hip centres of the hip rule's own: half the distance between the hip joint centres as
/// a fraction of the thigh's length (adults: about 0.085 m for a 0.42 m thigh; the inter-HJC
/// distance is about 0.17-0.18 m).
inline constexpr double kHipHalfWidthPerThigh = 0.2;

/// One segment's motion in the lab, per frame.
struct SegmentMotion3D {
  double mass_kg = 0.0;
  Eigen::Vector3d inertia_kgm2 = Eigen::Vector3d::Zero();  ///< principal, about the COM, segment frame (x, y, z)
  Eigen::MatrixX3d com_m, com_acc_mps2;  ///< N x 3
  Eigen::MatrixXd rotation;              ///< N x 9: the frame's axes e_x, e_y, e_z (lab), three columns each
  Eigen::MatrixX3d omega_rps, alpha_rps2;
  [[nodiscard]] Eigen::Matrix3d R(Eigen::Index i) const {
    Eigen::Matrix3d r;
    for (int a = 0; a < 3; ++a) r.col(a) = rotation.block<1, 3>(i, 3 * a).transpose();
    return r;
  }
};

/// Per side (right, left), how far medially of its landmark a joint's centre lies, m (0: the
/// landmark is the centre): half the joint's width plus the marker's radius for a marker on the
/// joint's lateral skin (markers/landmarks.hpp, "surface": "lateral").
struct JointCentreOffsets {
  std::array<double, 2> knee_m{0.0, 0.0}, ankle_m{0.0, 0.0};
  /// Half the distance between the two hip centres, m: each lies this far to its side of the hip
  /// landmark (their midpoint). 0: the thigh starts at the midpoint (the sagittal model's).
  double hip_half_width_m = 0.0;
};

/// Without the subject's measured widths: the knee's (femoral bicondylar) and the ankle's
/// (bimalleolar) width as fractions of the knee-ankle length. Adults' knees are about 95-105 mm
/// wide and their ankles 65-75 mm for a knee-ankle length of about 0.43 m (de Leva 1996's male
/// shank, 0.434 m), hence 0.23 and 0.165; scaled by the subject's own shank, a child's or a tall
/// runner's joint keeps its proportion. Plug-in Gait files carry the measured widths (Trial).
inline constexpr double kKneeWidthPerShank = 0.23, kAnkleWidthPerShank = 0.165;
/// The markers' diameter when the file does not give it (m): the 14 mm markers of most gait labs.
inline constexpr double kDefaultMarkerDiameterM = 0.014;

/// The legs' kinematics for the 3D joint moments (made once per trial).
struct LegMotion3D {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double gravity_mps2 = 9.81;
  std::array<SegmentMotion3D, 2> thigh, shank, foot;  ///< per side (right, left)
  std::array<Eigen::MatrixX3d, 2> hip_m, knee_m, ankle_m;  ///< the joint centres, filtered
  [[nodiscard]] Eigen::Index frames() const { return knee_m[0].rows(); }
};

/// `landmark_lab_m`: each landmark's lab position, N x 3 (finite); `lateral_axis`: each frame's
/// lateral axis (N x 3); `cutoff_hz` <= 0: unfiltered.
LegMotion3D leg_motion_3d(const Model& model, const std::array<Eigen::MatrixX3d, kLandmarkCount>& landmark_lab_m,
                          const Eigen::MatrixX3d& lateral_axis, const Eigen::Vector3d& up, double rate_hz, double cutoff_hz,
                          const JointCentreOffsets& offsets = {});

/// One foot's ground reaction in the lab, per frame, as a wrench at the lab origin: the force on
/// the body (N) and its moment about the origin (N m), zero without contact. A COP c and a free
/// moment T about up give M_O = c x F + T up (foot_wrench); a plate's measured force and moment
/// are one already, and a foot's stances on several plates add.
struct FootWrench3D {
  Eigen::MatrixX3d force_N, moment_origin_Nm;
};
/// The wrench of forces at COPs (NaN COP: no contact, a zero wrench) with free moments about `up`.
FootWrench3D foot_wrench(const Eigen::MatrixX3d& force_N, const Eigen::MatrixX3d& cop_m, const Eigen::VectorXd& free_moment_Nm,
                         const Eigen::Vector3d& up);

/// Per side: the ankle's, the knee's and the hip's internal moment on the distal segment, N x 3
/// (sagittal, frontal, transverse; the header's signs), and the lab-frame vectors they come from.
struct JointMoments3D {
  std::array<Eigen::MatrixX3d, 2> ankle_Nm, knee_Nm, hip_Nm;
  std::array<Eigen::MatrixX3d, 2> ankle_lab_Nm, knee_lab_Nm, hip_lab_Nm;
};

JointMoments3D joint_moments_3d(const LegMotion3D& legs, const std::array<FootWrench3D, 2>& feet);

/// joint_moments_3d(leg_motion_3d(...), feet) made `block_frames` frames at a time: the landmarks
/// filtered once over the whole trial, then each block's leg kinematics (with kBlockHaloFrames of
/// its neighbours on each side, so that its differences are those of the whole) made, used and let
/// go. The same moments frame for frame, with one block's kinematics (about 1.2 kB a frame) held
/// instead of the trial's: a long trial's memory when nothing else needs the legs' kinematics.
inline constexpr Eigen::Index kBlockHaloFrames = 4;
/// `landmark_lab_m` is taken (filtered in place): moved in, it is not copied.
JointMoments3D joint_moments_3d_in_blocks(const Model& model, std::array<Eigen::MatrixX3d, kLandmarkCount> landmark_lab_m,
                                          const Eigen::MatrixX3d& lateral_axis, const Eigen::Vector3d& up, double rate_hz, double cutoff_hz,
                                          const JointCentreOffsets& offsets, const std::array<FootWrench3D, 2>& feet,
                                          Eigen::Index block_frames = 2000);

/// JointMoments3D's joints in the per-frame CSV's order, and its columns' planes (its matrices'
/// columns 0, 1, 2).
inline constexpr const char* kJoint3DNames[] = {"ankle", "knee", "hip"};
inline constexpr const char* kPlaneNames[] = {"sagittal", "frontal", "transverse"};
/// The moments (N m, frames x planes) of joint 0 ankle, 1 knee, 2 hip (kJoint3DNames) on `side`.
inline const Eigen::MatrixX3d& joint_moments_of(const JointMoments3D& m, int joint, int side) {
  const std::array<Eigen::MatrixX3d, 2>& j = joint == 0 ? m.ankle_Nm : joint == 1 ? m.knee_Nm : m.hip_Nm;
  return j[static_cast<std::size_t>(side)];
}

/// The external knee adduction moment (N m) from joint_moments_3d's knee: -frontal; at frame i.
inline Eigen::VectorXd knee_adduction_moment(const JointMoments3D& m, int side) { return -m.knee_Nm[static_cast<std::size_t>(side)].col(1); }
inline double knee_adduction_moment(const JointMoments3D& m, int side, Eigen::Index i) { return -m.knee_Nm[static_cast<std::size_t>(side)](i, 1); }

/// A stance's first and second KAM peaks (N m): the largest finite value of `kam` over the first
/// and the second half of frames [first, last] (the second half takes the odd frame); NaN where a
/// half has none (a stance of one frame has no first half).
std::array<double, 2> stance_peaks(const Eigen::VectorXd& kam, Eigen::Index first, Eigen::Index last);

/// A stance's KAM angular impulse (N m s): the time integral of the KAM's positive (adduction)
/// part over frames [first, last] of `time_s`, by the trapezoidal rule, the KAM taken as 0 where
/// it is negative:
///   J = sum_i (t_{i+1} - t_i) (max(KAM_i, 0) + max(KAM_{i+1}, 0)) / 2.
/// The knee-osteoarthritis literature's "KAM impulse" (Thorp et al. 2006, Kean et al. 2012): it
/// weighs how long the medial compartment is loaded as well as how much, which the peaks do not.
/// A pair of frames with a non-finite value adds nothing; NaN when no pair is finite.
double stance_impulse(const Eigen::VectorXd& kam, const Eigen::VectorXd& time_s, Eigen::Index first, Eigen::Index last);

}  // namespace kin2grf
