// kin2grf dynamics: least-squares Lagrange multipliers with unilateral contact activation
// (paper Sect. 2.4-2.5, Eqs. 5-10).
//
// Equation of motion (Eq. 5), with the sign of lambda chosen so that a compressive normal
// contact force is lambda_n >= 0 (upward on the body):
//   M qdd = f + Phi_q(q, t)^T lambda.
// Given qdd, with the active set C of contacts (inactive multipliers fixed at zero, Eq. 6):
//   lambda_A = argmin ||lambda||_W  over  argmin || Phi_q,A^T lambda - (M qdd - f) ||      (Eq. 7)
// i.e. the minimum-norm least-squares solution (the pseudo-inverse for W = I, the paper).
// How it is computed: Phi_q,A^T = [B C], B the 60 bilateral columns (full column rank), C the
// contact columns. B^+ X = N^-1 Phi_q X with N = Phi_q Phi_q^T (60 x 60, about 330 non-zeros),
// factorised per frame as L D L^T on a fill pattern and an AMD order found once per solver
// (Phi_q's sparsity does not depend on q), in buffers of fixed size. U, the orthonormal basis of
// the complement of range(B) = null(Phi_q), is known in closed form: the whole body's rigid
// motions (translation along x and y, rotation about the origin: every point (x, y) moves by
// (-y, x), every absolute angle by 1, the relative angles not at all), orthonormalised. The
// least-squares residual only lives in U: lambda_C solves the 3-equation problem
// U^T C lambda_C ~ U^T b, its remaining freedom is fixed by minimising
// ||W_C lambda_C||^2 + ||W_B B^+ (b - C lambda_C)||^2 (an SVD of at most 3 x 12 and a small least
// squares), and lambda_B = B^+ (b - C lambda_C). This is the exact pseudo-inverse solution of the
// full 63-column problem, without refactoring it for each active set. Rank decisions in the
// 3 x k problem use a relative tolerance of 1e-8; a pivot of D below 1e-10 of the largest (a
// degenerate geometry) falls back to a dense rank-revealing factorisation.
// Activation (Alart-Curnier mixed criterion, Eqs. 8-9): contact j is active when
//   lambda_n,j - r g_n,j > 0.
// Semi-smooth Newton / active-set iterations (Fig. 5): start with every contact active, solve,
// reclassify, repeat until the set repeats; a set seen before ends the loop (cycle guard, the
// last solution is kept) and so does the iteration cap.
// Feet side by side (kin2grf, not the paper): see SolverOptions::min_split_distance_m.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <vector>

#include "kin2grf/dynamics/contact.hpp"
#include "kin2grf/model/model.hpp"

namespace kin2grf {

enum class MultiplierNorm {
  Paper,        ///< W = I over every multiplier (the paper's pseudo-inverse)
  TorqueScaled  ///< rigid-body internal forces out of the norm, joint torques / torque_length_m
};

struct SolverOptions {
  double r_N_per_m = 1e3;      ///< activation parameter r (Eq. 8); default from `kin2grf study r`
  int max_iterations = 20;
  MultiplierNorm norm = MultiplierNorm::TorqueScaled;  ///< kin2grf's default; the paper: Paper
  double torque_length_m = 0.9;
  /// Feet side by side: when both feet are in contact and all their active points lie within
  /// this distance along progression (m), the sagittal moment equation cannot tell how the load
  /// is split between them (F_R x_R + F_L x_L = M with x_R ~ x_L), and fitting it anyway hands one
  /// foot the whole load and the other a negative force. The moment direction of the 3-equation
  /// fit (its weakest singular direction) is then faded out (smoothstep from 1 at this distance
  /// to 0 at half of it) and the minimum norm shares the load. 0 disables (the paper).
  /// kin2grf's default 0.15 m: a moment error of 20-30 N m (a few % of the walking GRM range)
  /// moves F_R - F_L by dM / d, 150-200 N at that distance. Walking double support keeps its
  /// feet 0.37-0.57 m apart (the 7 development trials) and is not affected; the drop jump's
  /// side-by-side landing (0-9 cm) goes from 58 to 17 % vertical (`kin2grf study split-distance`).
  double min_split_distance_m = 0.15;
  /// Dense rank-revealing factorisation instead of the structured one (the fallback when a pivot
  /// of the normal equations vanishes; selectable to cross-check them).
  bool dense_factorisation = false;
};

struct FrameSolution {
  Eigen::Matrix<double, kJointCount, 1> joint_torque_Nm = Eigen::Matrix<double, kJointCount, 1>::Zero();
  /// Per contact point (n, t) pairs (fixed capacity: a frame's solve allocates nothing).
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 2 * kMaxContactPoints, 1> contact_lambda;
  std::array<bool, kMaxContactPoints> contact_active{};  ///< per contact point; false beyond them
  /// d(joint torques) / d(normal multiplier) per contact point (column j: point j), so that a
  /// split of the normal forces changed after the solve changes the torques with it.
  Eigen::Matrix<double, kJointCount, Eigen::Dynamic, 0, kJointCount, kMaxContactPoints> torque_per_normal;
  /// The same per unit tangential multiplier (a landing foot's load dropped before its touchdown,
  /// frames_before_touchdown, takes its torques out with it).
  Eigen::Matrix<double, kJointCount, Eigen::Dynamic, 0, kJointCount, kMaxContactPoints> torque_per_tangent;
  int iterations = 0;
  bool cycled = false;
  bool capped = false;
};

/// Feet side by side (SolverOptions::min_split_distance_m): the weight the solve keeps of its
/// sagittal split when the active points of both feet spread `spread_m` along progression, a
/// smoothstep from 0 below half the distance to 1 at it. The frontal split of the pipeline
/// (EstimateOptions::frontal_split_weight) acts by 1 minus it. split_distance_m <= 0: 1.
inline double side_by_side_sagittal_weight(double spread_m, double split_distance_m) {
  if (!(split_distance_m > 0)) return 1.0;
  const double u = std::clamp(2.0 * spread_m / split_distance_m - 1.0, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

/// Per-frame solver over (Model, TrialCalibration); owns its workspace (the Data) so that a
/// trial's frames reuse the same buffers. From the calibration it takes the trial's speed gate
/// and the belt velocity the gate is measured against.
class ContactSolver {
 public:
  ContactSolver(const Model& model, const TrialCalibration& calibration, const SolverOptions& options);
  /// q, qdd: the frame's 63 coordinates (D* filled) and accelerations.
  /// A row of ModelMotion's q and qdd is taken as it is (strided), without a copy.
  using FrameVector = Eigen::Ref<const Eigen::VectorXd, 0, Eigen::InnerStride<>>;
  FrameSolution solve(const FrameVector& q, const FrameVector& qdd, const FrameContacts& contacts);
  /// The bilateral constraint Jacobian Phi_q (60 x 63) at q (exposed for tests).
  [[nodiscard]] Eigen::MatrixXd bilateral_jacobian(const Eigen::VectorXd& q) const;

 private:
  static constexpr int kMaxColumns = 1 + 2 * kMaxContactPoints;  ///< b and (n, t) per contact point
  using Columns = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, coord::kCount, kMaxColumns>;
  void fill_bilateral_jacobian(const FrameVector& q, Eigen::MatrixXd& Phi) const;
  void contact_columns(const FrameVector& qdd, const FrameContacts& contacts, Columns& X) const;
  bool factorise_normal_equations();
  FrameSolution solve_reduced(const Eigen::Ref<const Eigen::MatrixXd>& BpX, const Eigen::Ref<const Eigen::MatrixXd>& UtX,
                              const FrameContacts& contacts);
  /// Feet side by side (SolverOptions::min_split_distance_m): the weight, 1 down to 0, kept of the
  /// 3-equation fit's weakest (moment) direction for this active set (side_by_side_sagittal_weight
  /// of its points' spread along progression).
  [[nodiscard]] double moment_direction_weight(const FrameContacts& contacts, unsigned active) const;
  FrameSolution solve_dense(const Eigen::MatrixXd& B, const FrameVector& qdd, const FrameContacts& contacts);
  const Model& model_;
  SolverOptions options_;
  double belt_velocity_mps_ = 0.0, speed_gate_mps_ = 0.0, flight_speed_gate_mps_ = 0.0;  ///< the trial's (TrialCalibration)
  Eigen::VectorXd mass_, gravity_, weight_bilateral_;
  Eigen::MatrixXd Phi_;  ///< the frame's bilateral Jacobian (60 x 63), reused
  // The structure of N = Phi Phi^T and of its factor, found once (constructor).
  std::array<int, kBilateralCount> order_{};            ///< constraint row -> its place in the factor
  std::vector<std::array<int, 2>> phi_entries_;         ///< (row, coordinate) of Phi's structural non-zeros
  std::vector<int> factor_row_start_, factor_k_;        ///< factor row i: entries [start_i, start_i+1), columns k
  std::vector<int> update_start_;                       ///< per entry: its updates in updates_
  std::vector<std::array<int, 3>> updates_;             ///< (entry L(i, m), entry L(k, m), m)
  std::vector<std::array<int, 3>> products_;            ///< (Phi entry a, Phi entry b, target in N)
  std::vector<double> phi_values_, Lv_;                 ///< the frame's Phi entries and L's entries
  Eigen::Matrix<double, kBilateralCount, 1> D_;
  Columns X_, BpX_;                                     ///< per-frame buffers (no heap)
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxColumns, kBilateralCount> Zt_;
  Eigen::Matrix<double, coord::kCount, 3> U_;           ///< translations (once per trial), rotation (per frame)
  Eigen::Matrix<double, 3, kMaxColumns> UtX_;
};

}  // namespace kin2grf
