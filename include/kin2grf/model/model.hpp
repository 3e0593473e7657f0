// kin2grf model: the 9-body sagittal model of the paper (Sect. 2.2, Fig. 1) in absolute
// coordinates.
//
// Frame: x forward along progression, y up, angles counter-clockwise from +x (SI units).
// Bodies: torso (HAT, hip -> shoulder), thigh, shank, foot (ankle, heel, MT head triangle) and
// toes (MT head -> hallux), right and left. Landmarks I..XII: shoulder, hip (one point for both
// thighs), and per side knee, ankle, heel, MT head, hallux.
//
// Generalised coordinates q (63; the paper's Sect. 2.2 with D* of Sect. 2.3, docs/METHOD-NOTES.md):
//   [0, 24)  x, y of the 12 landmarks        [24, 42) x, y of the 9 centres of mass
//   [42, 51) absolute angle theta_s of each body
//   [51, 59) relative joint angles phi_j = theta_child - theta_parent (hip, knee, ankle, MTP x2)
//   [59, 63) x, y of D*_R, D*_L (material points of the feet under the COP, Sect. 2.3)
// Bilateral constraints (60): per body, each attached point X and the COM G satisfy
//   X - P - R(theta_s) rho_X = 0 (P the body's proximal landmark, rho_X fixed in the body
//   frame): 40 rows; 8 angle definitions phi_j - theta_child + theta_parent = 0; 8 rheonomic
//   phi_j - phi_j(t) = 0; 4 rows D* - A - R(theta_foot) rho_D = 0.
// Mass matrix: diagonal and constant, m_s on (x_G, y_G), I_G,s on theta_s, zero elsewhere.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "kin2grf/model/anthropometry.hpp"

namespace kin2grf {

enum LandmarkId : int {
  kShoulder = 0, kHip = 1,
  kKneeR = 2, kAnkleR = 3, kHeelR = 4, kMtR = 5, kHalluxR = 6,
  kKneeL = 7, kAnkleL = 8, kHeelL = 9, kMtL = 10, kHalluxL = 11,
  kLandmarkCount = 12
};
enum SegmentId : int {
  kTorso = 0, kThighR = 1, kShankR = 2, kFootR = 3, kToesR = 4,
  kThighL = 5, kShankL = 6, kFootL = 7, kToesL = 8, kSegmentCount = 9
};
/// A foot: its index in every per-foot array (right 0, left 1).
enum FootSide : int { kRight = 0, kLeft = 1 };
/// A foot's name, "right" or "left", in every message and output; side_letter: "r" or "l" (landmark
/// names, OpenSim's bodies).
constexpr const char* side_name(int side) { return side == kLeft ? "left" : "right"; }
constexpr const char* side_letter(int side) { return side == kLeft ? "l" : "r"; }

/// A leg's landmarks and bodies, proximal to distal (the same order on both sides).
enum LegLandmark : int { kKnee = 0, kAnkle = 1, kHeel = 2, kMt = 3, kHallux = 4 };
enum LegSegment : int { kThigh = 0, kShank = 1, kFoot = 2, kToes = 3 };

constexpr int landmark(int side, LegLandmark which) { return 2 + 5 * side + which; }
constexpr int segment(int side, LegSegment which) { return 1 + 4 * side + which; }

namespace coord {
constexpr int kPoints = 0, kComs = 24, kTheta = 42, kPhi = 51, kDStar = 59, kCount = 63;
constexpr int point_x(int p) { return 2 * p; }
constexpr int com_x(int s) { return kComs + 2 * s; }
constexpr int theta(int s) { return kTheta + s; }
constexpr int phi(int j) { return kPhi + j; }
constexpr int dstar_x(int side) { return kDStar + 2 * side; }
}  // namespace coord
constexpr int kJointCount = 8;  ///< hip R, knee R, ankle R, MTP R, hip L, knee L, ankle L, MTP L

/// The rows of the bilateral constraints Phi (60), in the order of the header above.
namespace row {
constexpr int kRigid = 0;       ///< 40: per body, each attached point and the COM, (x, y)
constexpr int kRigidCount = 40;
constexpr int kAngle = 40;      ///< 8: phi_j - theta_child + theta_parent = 0 (joint j)
constexpr int kDriving = 48;    ///< 8: phi_j - phi_j(t) = 0, rheonomic (joint j)
constexpr int kDStar = 56;      ///< 4: D* - A - R(theta_foot) rho_D = 0, (x, y) per side
constexpr int kCount = 60;
static_assert(kAngle == kRigid + kRigidCount && kDriving == kAngle + kJointCount && kDStar == kDriving + kJointCount &&
              kCount == kDStar + 4);
}  // namespace row
constexpr int kBilateralCount = row::kCount;

/// Parent and child body of joint j.
constexpr int joint_parent(int j) { return (j % 4 == 0) ? kTorso : segment(j / 4, static_cast<LegSegment>(j % 4 - 1)); }
constexpr int joint_child(int j) { return segment(j / 4, static_cast<LegSegment>(j % 4)); }
const char* joint_name(int j);
/// A leg's joints by kind, in joint j's order within its side (j % 4): hip, knee, ankle, MTP. The
/// first three are a gait report's, and joint_torque_Nm's columns 4 side + 0..2.
inline constexpr const char* kLegJointNames[] = {"hip", "knee", "ankle", "mtp"};
const char* segment_name(int s);

/// One rigid body: its proximal landmark, the other landmarks it carries and its COM, all in
/// the body frame (origin at the proximal landmark, x toward the distal landmark).
struct Body {
  int proximal = 0;
  std::array<int, 2> points{-1, -1};            ///< attached landmarks (-1 unused)
  std::array<Eigen::Vector2d, 2> points_local{};
  Eigen::Vector2d com_local = Eigen::Vector2d::Zero();
  double mass_kg = 0.0;
  double inertia_kgm2 = 0.0;  ///< about the COM
  double length_m = 0.0;
  /// The COM's share of the way from the proximal landmark to the first attached one (body x).
  [[nodiscard]] double com_fraction() const { return length_m > 0 ? com_local.x() / length_m : 0.0; }
};

/// The 9 bodies: what the dynamics needs of the subject (Model/Data split, as in Pinocchio and
/// RBDL: per-frame values live in ModelMotion and the solver's workspace, never here).
struct Model {
  double body_mass_kg = 0.0;
  double gravity_mps2 = 9.81;
  std::array<Body, kSegmentCount> bodies{};
  std::string anthropometry = "winter";

  /// Diagonal of the constant mass matrix (63).
  [[nodiscard]] Eigen::VectorXd mass_diagonal() const;
  /// Generalised gravity force f (63): -m_s g on y_G.
  [[nodiscard]] Eigen::VectorXd gravity_force() const;
};

/// Body lengths and the heel's place in the foot frame, in metres (as measured or given).
struct BodyGeometry {
  double torso = 0.5;
  std::array<double, 2> thigh{0.42, 0.42}, shank{0.42, 0.42}, foot{0.15, 0.15}, toes{0.05, 0.05};
  std::array<Eigen::Vector2d, 2> heel_local{Eigen::Vector2d(-0.06, -0.04), Eigen::Vector2d(-0.06, -0.04)};
};

/// The subject's leg length (m): thigh plus shank, the mean of the two sides (hip centre to
/// ankle centre along the segments).
double leg_length_m(const Model& model);

/// A shank is 0.9-1.1 times its thigh, joint centre to joint centre (Winter's 0.246 and 0.245 of
/// the height; de Leva's 0.434 and 0.422 m, men), and a side's segment is within a few per cent of
/// the other side's. Outside these bounds a knee or ankle landmark is misplaced (a functional
/// joint centre from a walk's small range of motion, a marker off its landmark, a label swapped).
inline constexpr double kMinShankPerThigh = 0.75, kMaxShankPerThigh = 1.33, kMaxSidesApart = 0.15;
/// What the geometry's proportions say against the bounds above, a line each; none when they are
/// a leg's.
std::vector<std::string> segment_proportion_notes(const BodyGeometry& geometry);

/// Masses and inertias from the table; geometry as given. Built once per trial and const
/// afterwards: what else the trial fixes (the floor, the soles, the belt) is its TrialCalibration
/// (dynamics/contact.hpp).
Model build_model(const BodyGeometry& geometry, double body_mass_kg, const AnthropometricTable& table);

}  // namespace kin2grf
