// kin2grf kinematics: sagittal landmarks -> model coordinates q, qd, qdd (paper Sect. 2.2).
//
// Independent coordinates (11): hip x, y, torso angle and the 8 joint angles. They are read
// from the landmarks, low-pass filtered (filter.hpp, 6 Hz default) and differentiated by
// central differences. The dependent coordinates are then rebuilt by forward kinematics of the
// chain with FIXED segment lengths, at position, velocity and acceleration level:
//   r_X = r_P + R(theta) rho_X,  v_X = v_P + w k x (r_X - r_P),
//   a_X = a_P + alpha k x (r_X - r_P) - w^2 (r_X - r_P),
// so q, qd, qdd satisfy the bilateral constraints (and their time derivatives) to round-off.
// Exception (kin2grf's default, not the paper's): the torso (HAT) may take its measured,
// filtered hip-shoulder length L(t) instead of the fixed median, its points scaled by
// k = L(t) / L0 (d = k R rho; d'' = k'' e + 2 k' e' + k e''). The shoulders move up and down
// against the hip by 2-3 cm in running (spine, shoulder girdle), and the HAT is 60 % of the
// body mass: with a fixed length its vertical momentum misses that motion (running vertical
// 5.8 -> 4.3 %, docs/METHOD-NOTES.md). The bilateral constraints then hold with a time-varying
// torso length (a rheonomic constraint like the joint drivers); their Jacobian is unchanged.
// Contact constraints play no part here (the paper's decoupling).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/model/model.hpp"

namespace kin2grf {

/// The 12 landmarks in the sagittal frame (x forward, y up), metres, N x 2 each; no NaN.
struct SagittalLandmarks {
  double rate_hz = 0.0;
  Eigen::VectorXd time_s;
  std::array<Eigen::MatrixX2d, kLandmarkCount> p;
  /// Per side, how far ahead of the MT landmark the foot's 2nd metatarsal head lies, as a share of
  /// the ankle-MT length: the marker set's (kLateralMtToeExtraShare for a 5th-metatarsal marker,
  /// markers/landmarks.hpp), 0 for a landmark on the 2nd head or the heads' midpoint. The contact
  /// calibration's heel-to-MT-heads length takes it (FootContactGeometry::heel_mt_length_m).
  std::array<double, 2> mt_head_ahead_share{};
  [[nodiscard]] Eigen::Index frames() const { return time_s.size(); }
};

/// The kinematic cut-off the landmarks' noise allows: residual_analysis_cutoff over the x and y of
/// every landmark, at most `upper_hz` (the paper's 6 Hz). Double differentiation multiplies noise
/// by (2 pi f)^2: where the markers are noisy, a lower cut-off keeps the accelerations, and with
/// them the forces, from carrying it.
double noise_limited_cutoff(const SagittalLandmarks& lm, double upper_hz);

/// Medians over the frames of the landmark distances (fixed-length model) and of the heel's
/// place in the foot frame.
BodyGeometry measure_geometry(const SagittalLandmarks& lm);

/// Columns: 0 hip x, 1 hip y, 2 torso angle, 3..10 joint angles phi_j (unwrapped), 11 the
/// hip-shoulder distance (m), N x 12.
Eigen::MatrixXd independent_coordinates(const SagittalLandmarks& lm);

/// The most independent coordinates a motion has (independent_coordinates: the torso's length as
/// the 12th): the size of a frame's derivatives (ModelMotion::derivatives_at).
inline constexpr std::size_t kMaxIndependent = 12;

/// q, qd, qdd of one frame (63 each, on the stack: the per-frame solve allocates nothing).
struct MotionFrame {
  Eigen::Matrix<double, coord::kCount, 1> q, qd, qdd;
  /// Per side (right, left): the foot's absolute angle the COP function reads (rad), NaN: the
  /// foot's own theta in q (ModelMotion::cop_foot_angle_rad).
  std::array<double, 2> cop_foot_angle_rad{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

/// The whole body's centre of mass (x forward, y up; m) in frame f: sum m_s r_G,s / sum m_s.
Eigen::Vector2d whole_body_com(const Model& model, const MotionFrame& f);

/// The model's motion over a trial, held as what determines it: the independent coordinates and
/// their derivatives (N x 11 or 12 each) and the HAT COM's fore-aft acceleration as used (N: the
/// torso lag replaces it). D* (zero here) is the contact model's: contact_frame puts it into a
/// frame as that frame is solved.
/// q, qd, qdd of a frame are rebuilt by frame(i), the same forward kinematics for every caller,
/// bit for bit. Why not N x 63 matrices: three of them were 1.5 KB a frame, 44 % of a long
/// trial's peak memory; rebuilding each frame where it is used (the contact stage,
/// the solve, the totals) costs the pipeline about 5 % (scripts/speed-compare.sh).
struct ModelMotion {
  double rate_hz = 0.0;
  Eigen::VectorXd time_s;
  /// The bodies frame() places: shared, not copied, with whoever else holds the model (an
  /// estimate's result reads its model from here).
  std::shared_ptr<const Model> model;
  Eigen::MatrixXd x;                   ///< independent coordinates (independent_coordinates' columns)
  /// x's first and second time derivatives: stored (reconstruct_motion), or, when empty, x's
  /// central differences (central_difference, second_difference) taken per frame by
  /// derivatives_at(). compute_motion keeps x only: the derivatives were two thirds of a long
  /// trial's motion (the memory of long trials), and a frame's differences cost a few operations. The
  /// same numbers either way, bit for bit.
  Eigen::MatrixXd xd, xdd;
  Eigen::VectorXd torso_ax_mps2;       ///< N: the HAT COM's fore-aft acceleration (lag_torso_fore_aft)
  /// Per side (right, left): the thigh COM's fore-aft acceleration as lag_thigh_fore_aft delays
  /// it (N), or empty: the chain's, in frame().
  std::array<Eigen::VectorXd, 2> thigh_ax_mps2;
  /// The HAT COM's vertical acceleration as smooth_torso_vertical low-passes it (N), or empty:
  /// the chain's, in frame().
  Eigen::VectorXd torso_ay_mps2;
  /// N x 2 (right, left), or empty: the feet's absolute angles (rad) filtered at the positions'
  /// cut-off, for the COP function, when the dynamics take a higher one (compute_motion's
  /// cop_angle_cutoff_hz). The COP function maps an angle to a place: a position, whose noise
  /// the residual analysis judges, not an acceleration.
  Eigen::MatrixX2d cop_foot_angle_rad;
  [[nodiscard]] Eigen::Index frames() const { return time_s.size(); }
  /// Row i of xd and xdd into xd_i and xdd_i (x.cols() numbers each).
  void derivatives_at(Eigen::Index i, double* xd_i, double* xdd_i) const;
  /// Column c of xdd, the whole trial.
  [[nodiscard]] Eigen::VectorXd xdd_column(int c) const;
  /// q, qd, qdd of frame i into f.
  void frame(Eigen::Index i, MotionFrame& f) const;
  [[nodiscard]] MotionFrame frame(Eigen::Index i) const {
    MotionFrame f;
    frame(i, f);
    return f;
  }
};

/// Forward kinematics of the chain from the independent coordinates and their first and second
/// time derivatives (N x 11: fixed lengths; N x 12: the torso takes column 11's length). xd and
/// xdd empty: x's central differences, per frame (ModelMotion::derivatives_at).
ModelMotion reconstruct_motion(std::shared_ptr<const Model> model, Eigen::MatrixXd x, Eigen::MatrixXd xd, Eigen::MatrixXd xdd,
                               double rate_hz, Eigen::VectorXd time_s);
/// The same with a copy of `model` (a test's or a benchmark's own model).
inline ModelMotion reconstruct_motion(const Model& model, Eigen::MatrixXd x, Eigen::MatrixXd xd, Eigen::MatrixXd xdd, double rate_hz,
                                      Eigen::VectorXd time_s) {
  return reconstruct_motion(std::make_shared<const Model>(model), std::move(x), std::move(xd), std::move(xdd), rate_hz, std::move(time_s));
}

enum class TorsoLength {
  Measured,  ///< the filtered hip-shoulder distance of each frame (kin2grf's default)
  Fixed      ///< the median over the trial (the paper's rigid model)
};

/// The model's independent coordinates as compute_motion filters them: independent_coordinates,
/// without the torso length column for TorsoLength::Fixed; at least 8 frames.
Eigen::MatrixXd model_coordinates(const SagittalLandmarks& lm, TorsoLength torso);

/// compute_motion from model_coordinates' columns (unfiltered), their rate and times. `edges`: how
/// the coordinates' filter extends them past the window's ends (kinematics/filter.hpp; the
/// pipeline's EstimateOptions::kinematic_edges, and its span in cut-off periods); the COP
/// function's foot angles, positions, keep the odd reflection.
ModelMotion motion_from_coordinates(std::shared_ptr<const Model> model, Eigen::MatrixXd x, double rate_hz, Eigen::VectorXd time_s,
                                    double cutoff_hz, double cop_angle_cutoff_hz = 0.0, FilterEdge edges = FilterEdge::OddReflection,
                                    double edge_span_periods = kCurvatureSpanPeriods);

/// The whole kinematic step: independent coordinates, filter at cutoff_hz, differentiate,
/// reconstruct. cop_angle_cutoff_hz > 0 (and not cutoff_hz): the COP function's foot angles
/// are filtered at it instead (ModelMotion::cop_foot_angle_rad).
ModelMotion compute_motion(std::shared_ptr<const Model> model, const SagittalLandmarks& lm, double cutoff_hz,
                           TorsoLength torso = TorsoLength::Measured, double cop_angle_cutoff_hz = 0.0,
                           FilterEdge edges = FilterEdge::OddReflection);
/// The same with a copy of `model`.
inline ModelMotion compute_motion(const Model& model, const SagittalLandmarks& lm, double cutoff_hz,
                                  TorsoLength torso = TorsoLength::Measured, double cop_angle_cutoff_hz = 0.0,
                                  FilterEdge edges = FilterEdge::OddReflection) {
  return compute_motion(std::make_shared<const Model>(model), lm, cutoff_hz, torso, cop_angle_cutoff_hz, edges);
}

/// The upper body's fore-aft lag (kin2grf, not in the paper). The HAT is one rigid segment whose
/// COM follows the hip and shoulder landmarks, but most of its mass (viscera, arms, head, soft
/// tissue) hangs on a compliant spine and follows the pelvis's fore-aft oscillation late: upper-
/// body accelerations lag the pelvis's in walking. With the skeleton's timing the model's braking
/// force and ground moment lead the plates in double support and load moves to the leading foot
/// early (docs/METHOD-NOTES.md). The HAT COM's fore-aft acceleration (its inertial force m a_x,
/// paper Eq. 5's M qdd) is replaced by itself delayed by tau:
///   a(t) = a_x(t - tau), linearly interpolated between frames; a_x(0) before the first frame.
/// A delay, as what the trunk markers already lag the hip by is measured (measured_torso_lag_s,
/// a cross-correlation peak); a first-order lag of time constant tau was tried before it,
/// which also attenuated (docs/METHOD-NOTES.md compares them). Its position and velocity, its
/// vertical and angular accelerations and every other segment are unchanged (torso_ax_mps2 is
/// the one series it writes). tau_s = 0 leaves the motion as it is (the paper).
void lag_torso_fore_aft(ModelMotion& m, double tau_s);

/// The thigh's fore-aft lag (kin2grf, not in the paper; EstimateOptions::thigh_lag_s). A thigh is
/// mostly muscle and fat around the femur, a wobbling mass (Gruber et al. 1998): at a
/// heel strike the femur stops, its soft tissue follows late, and the ground sees the thigh's
/// braking late. With the skeleton's timing (knee markers on the bone) the model's braking leads
/// the plates in double support, after the torso's lag, and load moves to the landing foot early
/// (docs/METHOD-NOTES.md). The thigh COM's fore-aft acceleration (its m a_x in paper Eq. 5) is
/// replaced by itself delayed by tau, as lag_torso_fore_aft does the HAT's:
///   a(t) = a_x(t - tau), linearly interpolated between frames; a_x(0) before the first frame.
/// Into m.thigh_ax_mps2[side] (0 right, 1 left); every other acceleration is unchanged.
/// tau_s = 0 leaves the motion as it is.
void lag_thigh_fore_aft(ModelMotion& m, int side, double tau_s);

/// The upper body's vertical smoothing (kin2grf, not in the paper; EstimateOptions::
/// torso_vertical_cutoff_hz). The HAT rides on the hip centre, which the pelvis markers place:
/// skin over the iliac crests, which at each heel strike moves with the soft tissue (the hip
/// centre's vertical acceleration is 1.1-1.5 x the centre of mass's that the plates imply on the
/// development walks), while the upper body's mass (viscera, arms, head on a compliant spine)
/// passes on less of the heel strike's jolt the higher its frequency (gait accelerometry: the
/// head's vertical acceleration is the pelvis's attenuated, Menz et al. 2003, J Gerontol A
/// 58:M1034; the standing body's vertical resonance lies at 4-6 Hz, Matsumoto and Griffin 1998,
/// J Sound Vib 212:85). The walks' plates see the model's vertical inertial force above 3 Hz at
/// about 0.45 of its size (docs/METHOD-NOTES.md). The HAT COM's vertical acceleration (its m a_y
/// in paper Eq. 5's M qdd) is replaced by itself low-passed at cutoff_hz (butterworth_filtfilt:
/// zero-lag, as the walks' vertical timing is right; delaying it was measured worse). A body
/// property, not a gait one: a fixed frequency, not cycles over the stance, which in a slow walk
/// would clip the loading peak. Its position, velocity, fore-aft and angular accelerations and
/// every other segment are unchanged (torso_ay_mps2 is the one series it writes). cutoff_hz <= 0
/// leaves the motion as it is.
void smooth_torso_vertical(ModelMotion& m, double cutoff_hz);

/// How late the HAT COM's fore-aft acceleration already follows the hip's in `m`, s: the lag of
/// the peak of their cross-correlation within +-80 ms over the middle 80 % of the frames (at most
/// a minute of them), refined by a parabola through the peak, taken both ways round and halved.
/// Trunk markers that lag the pelvis carry part of the upper body's lag themselves (0 for the
/// model torso without them, which follows the hip in phase). 0 for fewer than 20 frames or no
/// positive correlation.
double measured_torso_lag_s(const ModelMotion& m);

}  // namespace kin2grf
