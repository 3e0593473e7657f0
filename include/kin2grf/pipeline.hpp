// kin2grf: the whole method on one trial, markers -> landmarks -> model coordinates ->
// kinematics -> contact/inverse dynamics -> filtered results (paper Sect. 2).
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "kin2grf/dynamics/contact.hpp"
#include "kin2grf/dynamics/joint_moments_3d.hpp"
#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/trial.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/markers/landmarks.hpp"
#include "kin2grf/model/model.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {

/// The estimate's model (issue 28): the paper's sagittal model, or the 3D one, which adds to it
/// each foot's mediolateral force (dynamics/mediolateral.hpp) and the ankles', knees' and hips' 3D
/// moments by bottom-up inverse dynamics (dynamics/joint_moments_3d.hpp). The sagittal results
/// (forces, COP along progression, GRM, the 2D joint torques) are the same in both.
enum class ModelKind { Sagittal, ThreeD };
/// "sagittal" or "3d"; model_kind: InputError otherwise.
const char* model_kind_name(ModelKind kind);
ModelKind model_kind(const std::string& name);

struct EstimateOptions {
  std::optional<double> mass_kg;           ///< else the file's (C3D PROCESSING/SUBJECT(S)); none -> error
  /// Body masses outside kMassRangeKg are refused (a file's 0.5 kg, a typo) unless this is set.
  bool allow_unusual_mass = false;
  std::string anthropometry = "de-leva";  ///< kin2grf's default; the paper cites Winter (--paper)
  double kinematic_cutoff_hz = 6.0;        ///< paper: 6 Hz
  double post_cutoff_hz = 12.0;            ///< paper: 12 Hz; see post_cutoff_cycles
  /// The post-filter follows the motion (kin2grf): its cut-off is this many cycles per stance,
  /// post_cutoff_cycles / the trial's median stance duration (median_stance_s), from a slow walk
  /// to a sprint. A stance's force curve is a pulse of its own duration (two humps in walking, one
  /// in running), so its content scales with 1 / stance time; 4 cycles is 6-7 Hz for a 0.6 s
  /// walking stance and 16-20 Hz for a 0.2-0.25 s running one (chosen leave-one-lab-out, `kin2grf
  /// study post-cutoff-cycles`). 0: the fixed post_cutoff_hz (the paper's 12 Hz), which also
  /// serves a trial with no complete stance.
  double post_cutoff_cycles = 4.0;
  /// The per-stance post-filter cut-off (post_cutoff_cycles) is not taken below this multiple of
  /// the dynamics' kinematic cut-off (EstimateResult::kinematic_cutoff_hz); 0: no floor. Why: the
  /// multipliers come from kinematics filtered at that cut-off, and the post-filter is there for
  /// the solve's switching, not to remove what the kinematics kept; 4 cycles over a slow walker's
  /// 1.75 s stance is 2.3 Hz, which clipped a held-out slow walk's loading peak (784 N measured,
  /// 719 estimated; at a fixed 12 Hz its error halved). 0.75 since session 32 (off before): every
  /// development trial's per-stance cut-off (5.0-16.7 Hz) lies above 0.75 x 6 Hz, so `kin2grf study
  /// post-cutoff-floor` cannot tell 0, 0.5 and 0.75 apart (criterion 7.999 %) and 1.0 costs a little
  /// (8.013 %): 0.75 is the highest floor that leaves them as they are, and a slow walker's stance
  /// gets the physical reason's (a synthetic 0.36 m/s walk: the feet's sum 1.85 -> 1.43 % body
  /// weight RMS off the kinematic total).
  double post_cutoff_floor_ratio = 0.75;
  /// Lower the kinematic cut-off to what the markers' noise allows (noise_limited_cutoff; kin2grf)
  /// or keep it fixed (the paper).
  bool cutoff_from_noise = true;
  /// Where the markers' noise lowers the kinematic cut-off (cutoff_from_noise), the dynamics'
  /// kinematics are not taken below this many cycles per stance: min(kinematic_cutoff_hz,
  /// min_kinematic_cycles / the median stance duration, median_stance_s of a first solve at
  /// the lowered cut-off), while the COP function's foot angle keeps the lowered cut-off
  /// (compute_motion's cop_angle_cutoff_hz). Why: the residual analysis judges positions, where
  /// the noise is a signal's equal sooner than in their second derivatives' forces, and a stance's
  /// force is a pulse of its own duration whose harmonics the accelerations must keep (the same
  /// reason as post_cutoff_cycles); the COP function's input is an angle, a position. 0: none.
  /// kin2grf's default chosen leave-one-lab-out on the trials with 2 mm of marker noise (`kin2grf
  /// study min-kinematic-cycles`: 3.0 since session 25, which every lab chooses without itself,
  /// held-out criterion 8.682 % against 3.5's 8.712 %); a trial the residual analysis leaves at
  /// kinematic_cutoff_hz (every development trial as recorded) is not changed by it.
  double min_kinematic_cycles = 3.0;
  /// How the model coordinates' zero-lag filter extends them past the processed window's ends
  /// (kinematics/filter.hpp): OddReflection reads each end's acceleration as zero; Curvature
  /// keeps it (the end's own curvature over half a cut-off period). A window that ends mid-stance
  /// or in flight (a run through a short capture volume) accelerates at 1-3 g there.
  FilterEdge kinematic_edges = FilterEdge::Curvature;
  /// Curvature's span, in periods of the kinematic cut-off: the end's curvature is the least-squares
  /// quadratic's over this much of the window's end (kinematics/filter.hpp, kCurvatureSpanPeriods).
  /// Half a period, the filter's own resolution, set beforehand and chosen by every lab held out
  /// (`kin2grf study kinematic-edge-span`, docs/METHOD-NOTES.md).
  double kinematic_edge_span_periods = kCurvatureSpanPeriods;
  /// The torso's hip-shoulder length: measured per frame (kin2grf) or fixed (the paper).
  TorsoLength torso_length = TorsoLength::Measured;
  /// The torque-scaled multiplier norm's lever (SolverOptions::torque_length_m) as this multiple
  /// of the subject's leg length (thigh + shank, the mean of the two sides), so that the joint
  /// torques weigh against the contact forces in the least squares of Eq. 7 as they would for a
  /// subject of any size: a torque is a force times a lever, a child's torques are smaller than
  /// an adult's by one length more than its forces, and the leg is the lever of the ground
  /// reaction about the hip. 0: the fixed SolverOptions::torque_length_m (0.9 m, kin2grf's lever
  /// until session 39). 1.06 is that lever for the development subjects' mean leg of 0.85 m
  /// (0.76-0.90 m over the 16 trials), not fitted: the same weighting for an average adult, scaled
  /// for a child or a tall subject (`kin2grf study subject-scale`; `kin2grf study torque-length`
  /// for the ratio, docs/METHOD-NOTES.md).
  double torque_length_legs = 1.06;
  /// The upper body's fore-aft lag behind the pelvis, s (kin2grf): the HAT COM's fore-aft
  /// acceleration is delayed (lag_torso_fore_aft) by this time less what the trunk
  /// markers already lag the hip by (measured_torso_lag_s), never below 0. 0: none (the paper).
  double torso_lag_s = 0.03;
  /// Each thigh's fore-aft lag behind its femur, s (kin2grf): the thigh COM's fore-aft
  /// acceleration is delayed (lag_thigh_fore_aft) by this time where the thigh's knee point is a
  /// marker on the bone (a marker or the mean of markers: the epicondyles, a joint centre of
  /// them); a knee point that a thigh cluster carries (static calibration, functional centre)
  /// moves with the thigh's skin and soft tissue, which already lag the bone, and is not delayed.
  /// A trial with flight phases (a run, a jump) keeps the thighs' timing (lag_thigh_stage). 0:
  /// none (the paper). 30 ms: chosen leave-one-lab-out (`kin2grf study thigh-lag`; 20 ms until
  /// session 30, when each foot's force angle kept through the double support moved every lab's
  /// held-out choice to 30 ms).
  double thigh_lag_s = 0.03;
  /// The leg length (thigh + shank, m) the settings in seconds and hertz are for: the kinematic,
  /// torso-vertical, lateral and fixed post-filter cut-offs and the torso's and thighs' lags. A
  /// subject's are scaled by sqrt(its leg / this), the time scale of its gait at the same Froude
  /// number (a child 0.6 times an adult's size walks the same gait at sqrt(0.6) of its times;
  /// Alexander and Jayes 1983): cut-offs divided by it, lags multiplied. 0.85 m is the development
  /// subjects' mean leg (0.76-0.90 m), at which those settings were chosen. 0 (the default): no
  /// fixed reference; the development range below decides. Measured, not the default: on the
  /// development adults the criterion goes 8.380 -> 8.369 % but mixed (walking vertical better,
  /// running's and the GRM worse by hundredths); on their subjects made 0.6 of their size it
  /// takes walking 5.71 / 8.05 % vertical / anterior to 5.4 / 7.4 % and running 5.79 / 11.28 % to
  /// 4.6 / 9.9 % (`kin2grf study subject-scale`, docs/METHOD-NOTES.md). When set, it takes the
  /// place of the development range below, inside the range too.
  double time_scale_leg_m = 0.0;
  /// The development subjects' legs (thigh + shank, m), the range in which the settings in seconds
  /// and hertz were chosen (0.763-0.896 m over the 16 trials): a subject whose leg is shorter than
  /// time_scale_short_leg_m (longer than time_scale_long_leg_m) has them scaled as
  /// time_scale_leg_m does, by sqrt(its leg / that end of the range), the nearest leg they were
  /// chosen for; within the range they are as given. Why: a child's gait is faster in cadence by
  /// about sqrt(adult leg / its leg) at the same Froude number, and a fixed 6 Hz cut-off or 30 ms
  /// lag chosen on adults is then a different share of its stance; the development subjects
  /// themselves are untouched, so their figures are the same (session 50). 0: no scaling on that
  /// side (the paper).
  double time_scale_short_leg_m = 0.76;
  double time_scale_long_leg_m = 0.90;
  /// The upper body's vertical smoothing, Hz (kin2grf): the HAT COM's vertical acceleration is
  /// low-passed at this cut-off (smooth_torso_vertical), since the pelvis markers carry the heel
  /// strike's jolt that the upper body's mass does not pass on. A trial with flight phases (a
  /// run, a jump), whose vertical force is a pulse with real content above it, keeps the chain's
  /// (smooth_torso_vertical_stage). Only below the dynamics' kinematic cut-off. 0: none (the
  /// paper). 4 Hz: chosen leave-one-lab-out (`kin2grf study torso-vertical-cutoff`).
  double torso_vertical_cutoff_hz = 4.0;
  /// A model torso's fore-aft sway (no trunk markers: the marker set's pelvis_up shoulder rule)
  /// in a trial with flight phases (flight_frames: a run, a jump), as a fraction of the hip
  /// centre's fore-aft oscillation (kin2grf): the runner's measured kTrunkSwayGainRunning instead
  /// of the set's walking one (kTrunkSwayGain). A trial without flight phases, or a measured
  /// trunk, is not touched. The set's own sway_gain: as the set has it everywhere.
  double running_sway_gain = kTrunkSwayGainRunning;
  /// Double support's load transfer (kin2grf; after Ren et al. 2008's smooth transition
  /// assumption, J Biomech 41:2750): in each double support of a walk (the leading foot lands
  /// while the trailing foot stands, and the trailing foot leaves while the leading one stands),
  /// the trailing foot's share of the two feet's vertical force is blended with this weight
  /// towards a smooth handover, 1 - 3u^2 + 2u^3 over the double support's time fraction u;
  /// 0: none (the paper). Why: in double support the split comes from the sagittal moment
  /// equation, whose body COP (GRM / F) moves from the trailing to the leading foot in 0.1-0.2 s,
  /// faster than accelerations filtered at 6 Hz can follow; 76 % of the development walks'
  /// per-foot vertical squared error lies there. The total force is unchanged, each foot's COP
  /// too; the joint torques follow the new split (double_support_transition). Double supports
  /// longer than half the median stance (standing, shuffling) are left as solved. kin2grf's
  /// default 0.4, chosen leave-one-lab-out (`kin2grf study double-support-sta`; 0.2 until session
  /// 29, when a grid that stopped there for the ground-level sensitivity was widened: a 1 cm
  /// ground error then costs Rajagopal's walk 0.3 points instead of 0.2, but leaves each of the
  /// five walks that gain below its figure at 0.2 on the true ground).
  double double_support_sta_weight = 0.4;
  /// With the transition above: how far each foot's fore-aft force follows its vertical force's
  /// new share (each foot's tangential multipliers scaled by 1 + a (f - 1), f its normal ones'
  /// factor). 1 (kin2grf's default, session 30): each foot keeps the force angle the solve found
  /// for it; the transition moves load from one foot to the other, it does not turn either foot's
  /// force (the landing foot's braking and the trailing foot's push-off grow and shrink with their
  /// load). 0 (the paper; the transition's rule until session 30): the fore-aft forces as solved,
  /// so a foot the transition unloads kept its whole solved braking or propulsion, the two feet's
  /// sum that the kinematics ask for. Measured leave-one-lab-out (`kin2grf study
  /// double-support-angle`): walking anterior 7.6 -> 7.3 % (docs/METHOD-NOTES.md).
  double double_support_angle = 1.0;
  /// Feet side by side (within SolverOptions::min_split_distance_m along progression; kin2grf, not
  /// the paper): the two feet's vertical forces are blended with this weight (times the solver's
  /// fade of its sagittal split) towards the split the whole body's frontal balance gives
  /// (frontal_balance_right_share; the COM's lateral place from the lab landmarks, filtered at
  /// lateral_cutoff_hz). Why: side by side, the sagittal moment cannot tell the feet apart and the
  /// solve shares the load by the minimum norm, equally for a symmetric posture; across the plane
  /// the feet stand a hip width apart, and where the COM stands between them decides (the drop
  /// jump's landing: 860 against 536 N on its plates; per-foot vertical 13.6 -> 7.5 %). No value
  /// fitted. 0: off (the paper). The total, each foot's COP and (double_support_angle) each foot's
  /// force angle are kept; the joint torques follow (frontal_split).
  double frontal_split_weight = 1.0;
  /// Touchdown from the foot's own motion (kin2grf, issue 29; frames_before_touchdown): a foot
  /// the solve has in contact before its heel or MT head has stopped descending (its descent
  /// fallen to this fraction of its recent peak, seen at 15 Hz) carries no load there. The load is
  /// dropped, not handed to the other foot: it is the 6 Hz kinematics' spread of the impact, not a
  /// force either foot carries; the joint torques lose what it gave them (the solve's
  /// torque_per_normal and torque_per_tangent) and the residual shows it. It acts after the
  /// post-filter and the double-support transition, so the stance after touchdown is as they made
  /// it. Not on a landing from a flight phase. 0.1 since session 32, chosen leave-one-lab-out by
  /// every lab on the criterion whose vertical force counts the loaded span (validate: the walks'
  /// landings were loaded 27-47 ms before the raw plates' onsets, which the plate's stance alone
  /// does not see). 0: off (the paper).
  double touchdown_stop_fraction = 0.1;
  std::optional<double> ground_level_m;    ///< else estimate_ground_level
  ContactModelOptions contact;
  SolverOptions solver;
  LandmarkOptions landmarks;
  /// Whether the result holds every per-frame series. false (a long trial's memory when only the
  /// outputs are wanted): what only validation and COP fitting read is left out (the
  /// window's landmarks are released once the motion is made, r.landmarks keeping its rate and
  /// times; FootResult::sole_m and kinematic_total stay empty), and so are the per-frame totals
  /// (grm_Nm, residual, joint_force_N), which frame_totals() remakes from the motion as the
  /// writers go. The outputs are the same.
  bool keep_all_series = true;
  /// GRM reference point in the sagittal frame (x along progression, y up), m.
  Eigen::Vector2d grm_reference_m = Eigen::Vector2d::Zero();
  /// The mediolateral force (kin2grf; dynamics/mediolateral.hpp): each foot's force along the
  /// sagittal frame's lateral axis, from the whole body's lateral acceleration shared between the
  /// feet (lateral_own_leg_inertia). Off: the sagittal model's outputs, with a zero lateral force.
  /// ModelKind::ThreeD includes it.
  bool mediolateral = false;
  /// The whole body's lateral acceleration's low-pass cut-off, Hz (0: the dynamics' kinematic
  /// cut-off); never above that cut-off. The body's lateral sway is slow (it swings once a stride,
  /// about 1 Hz walking): above about 3 Hz the lateral COM acceleration from skin markers is
  /// mostly their noise and soft tissue. Chosen leave-one-lab-out among 2-5 Hz and the kinematic
  /// cut-off (docs/METHOD-NOTES.md): 3 Hz from session 21 (walking per-foot rRMSE 23.4 -> 18.0 %
  /// held out), 2.5 Hz since session 36, when every lab chose it without itself (the lateral
  /// criterion 22.69 -> 22.20 % held out; walking 15.5 -> 14.4 %).
  double lateral_cutoff_hz = 2.5;
  /// Each foot in contact carries its own lower leg's lateral inertia, the rest shared by load
  /// (dynamics/mediolateral.hpp); false: the load share alone.
  bool lateral_own_leg_inertia = true;
  /// The COP's lateral place past the forefoot's midline end (cop_lateral_on_foot_line): its
  /// medial turn, m per m ahead of the MT heads (kin2grf, session 43). At push-off the COP rolls
  /// from the metatarsal heads onto the hallux, which lies medial of the foot's midline (anatomy:
  /// its pad 2-3 cm medial of the midline, 4-5 cm ahead of the heads, a slope of at most about
  /// 0.6); the plates of 15 of the 16 development walking stances move medially there, by 2-22 mm
  /// from 2 cm behind the heads to 1-2 cm past them. 0.25, chosen leave-one-lab-out by the lateral
  /// COP's RMSE (every lab but Stanford's chooses it without itself, Stanford's 0.5; `validate
  /// --model 3d --toe-medial-slope`, docs/VALIDATION.md): held out 12.6 -> 11.6 mm, the knee
  /// adduction moment's RMSE 0.147 -> 0.146 N m/kg; a landing's least-squares lateral split moves
  /// with it (the drop jump's lateral force 47 -> 51 %). 0: it stays on the midline (sessions 20-42).
  double toe_medial_slope = 0.25;
  /// The arms and the head as segments of their own in the lateral force, where the marker set
  /// names their markers and the file holds them (MarkerSet::upper_body); false: lumped into the
  /// HAT, as the sagittal model has them.
  bool upper_body_segments = true;
  /// The torso's share of the whole body's lateral acceleration takes the upper body's lag
  /// (torso_lag_s, less what the trunk markers already lag the hip by: the fore-aft's own delay),
  /// where trunk markers measure the torso (not the model torso of a set without them) and away
  /// from flight phases; false: none (dynamics/mediolateral.hpp, docs/METHOD-NOTES.md).
  bool lateral_torso_lag = true;
  /// In a landing's bilateral stance (both feet down near a flight phase, outside a walking
  /// handover) the feet's lateral forces split the whole body's by the paper's least squares
  /// with the legs' 3D joint moments (least_squares_lateral_split); false: by the split of
  /// mediolateral_forces, as everywhere else.
  bool lateral_least_squares = true;
  ModelKind model = ModelKind::Sagittal;
  [[nodiscard]] bool lateral_force() const { return mediolateral || model == ModelKind::ThreeD; }
  /// Called with (frames solved, frames in all) every 1 % of the contact solve; empty: none.
  /// The core prints nothing itself: the front end decides what to show.
  std::function<void(long, long)> progress;
};

struct FootResult {
  Eigen::MatrixX2d force_N;      ///< (anterior, vertical), post-filtered, zero when inactive
  Eigen::MatrixX2d raw_force_N;  ///< the solve's, before the post-filter and the double-support transition
  Eigen::VectorXd cop_x_m;       ///< along progression; NaN when inactive
  std::vector<bool> contact;
  Eigen::VectorXd inclination_rad;  ///< theta_A, the paper's foot inclination (contact.hpp)
  Eigen::VectorXd gap_m;            ///< normal gap g_n of the foot's lowest contact point
  Eigen::MatrixXd sole_m;           ///< N x 6: sole points A, B, C (x, y) in the sagittal frame (keep_all_series)
  /// Along the sagittal frame's lateral axis (forward x up), N; zero when inactive; empty unless
  /// EstimateOptions::mediolateral.
  Eigen::VectorXd force_lateral_N;
  /// The COP's lateral coordinate (along the sagittal frame's lateral axis), m: on the line from
  /// the heel to the forefoot's midline (SagittalWindow::foot_line) at the COP's place along it,
  /// the heel's behind the heel, the forefoot's ahead of it; NaN when inactive; empty unless
  /// EstimateOptions::lateral_force(). Without it the lab COP takes the heel-MT midpoint
  /// (EstimateResult::foot_lateral_m).
  Eigen::VectorXd cop_lateral_m;
};

/// The 3D model's legs (ModelKind::ThreeD): their kinematics, made once, and the ankles', knees'
/// and hips' moments with the estimated ground reactions (validate runs the same kinematics with the
/// plates'). The ground reaction: each foot's force (anterior, vertical, mediolateral) at its COP
/// (lab_foot_frame), no free moment.
struct Legs3D {
  LegMotion3D motion;  ///< empty unless EstimateOptions::keep_all_series (validate needs it)
  JointMoments3D moments;
};

struct EstimateResult {
  std::string marker_set;
  double mass_kg = 0.0;
  SagittalFrame frame;
  double kinematic_cutoff_hz = 0.0;  ///< the dynamics' kinematic cut-off (EstimateOptions::cutoff_from_noise, min_kinematic_cycles)
  /// The residual analysis' cut-off for positions (EstimateOptions::cutoff_from_noise), which the
  /// COP function's foot angle takes; kinematic_cutoff_hz when the stance floor did not raise it.
  double position_cutoff_hz = 0.0;
  double post_cutoff_hz = 0.0;       ///< the post-filter cut-off used (EstimateOptions::post_cutoff_cycles)
  /// The model the trial was solved with (one home: the motion's).
  [[nodiscard]] const Model& model() const { return *motion.model; }
  /// The floor (with EstimateOptions::contact.ground_shift_m applied), the soles, the belt
  /// velocity, the progression speed and the speed gate the trial was solved with (measured once,
  /// model_stage and contact_stage).
  TrialCalibration calibration;
  [[nodiscard]] double ground_level_m() const { return calibration.contact.ground_level_m; }
  Eigen::VectorXd time_s;
  Eigen::Index first_index = 0;    ///< first processed frame's index in the trial
  int first_frame_number = 1;      ///< its frame number in the file
  std::array<FootResult, 2> feet;
  Eigen::VectorXd grm_Nm;          ///< sagittal ground reaction moment about grm_reference_m (keep_all_series)
  Eigen::MatrixXd joint_torque_Nm; ///< N x 8, moment on the child body, counter-clockwise +
  Eigen::MatrixXd joint_force_N;   ///< N x 16, force on the child body's subtree (x, y) per joint (keep_all_series)
  Eigen::MatrixX3d residual;       ///< N x 3: dynamic inconsistency (Fx N, Fy N, M N m) (keep_all_series)
  std::vector<int> iterations;
  int cycled_frames = 0, capped_frames = 0;
  std::array<Eigen::VectorXd, 2> foot_lateral_m;
  std::optional<Legs3D> legs_3d;   ///< ModelKind::ThreeD only
  /// The motion the contact forces were solved with (independent coordinates, about 100 bytes a
  /// frame) and the GRM's reference point: what frame_totals() remakes a frame's totals from.
  ModelMotion motion;
  Eigen::Vector2d grm_reference_m = Eigen::Vector2d::Zero();
  SagittalLandmarks landmarks;     ///< the processed window's landmarks (sagittal frame)
  /// Rigid-body totals from the kinematics alone, N x 3: sum m (a + g) (x, y, N) and the sum of
  /// moments about the origin (N m). What all external forces together must equal.
  /// (keep_all_series)
  Eigen::MatrixX3d kinematic_total;
  std::vector<std::string> messages;
  double seconds_kinematics = 0, seconds_dynamics = 0;
};

/// One processed frame's totals: the GRM about r.grm_reference_m, the dynamic residual (the
/// kinematic total less the feet's forces and moments), the kinematic total (sum m (a + g) and
/// the moments about the origin) and each joint's force on its child's subtree (x, y). What
/// estimate() puts into grm_Nm, residual, kinematic_total and joint_force_N, frame by frame from
/// r.motion and the feet's results, for a result that does not hold them (keep_all_series).
struct FrameTotals {
  double grm_Nm = 0.0;
  Eigen::Vector3d residual = Eigen::Vector3d::Zero(), kinematic_total = Eigen::Vector3d::Zero();
  std::array<double, 2 * kJointCount> joint_force_N{};
};
FrameTotals frame_totals(const EstimateResult& r, Eigen::Index i);
/// The same from its parts: the motion (and its model), the feet's results, the floor the COPs
/// stand on and the GRM's reference point.
FrameTotals frame_totals(const ModelMotion& motion, const std::array<FootResult, 2>& feet, double ground_level_m,
                         const Eigen::Vector2d& grm_reference_m, Eigen::Index i);

/// Plausible adult and child body masses (kg): outside, estimate() refuses unless allowed.
inline constexpr double kMassRangeKg[2] = {20.0, 300.0};

/// Every numeric setting checked before any work: InputError naming the setting, its value and
/// the allowed range (NaN, infinities, zero or negative cut-offs, r, gaps...). estimate() calls it.
void check_options(const EstimateOptions& options);

/// The median duration (s) of the trial's complete stances: each foot's runs of contact frames
/// (gaps shorter than 20 ms bridged, runs shorter than 50 ms left out, as no stance is that short),
/// except a run that starts at the first frame or ends at the last, whose length is not known.
/// None when there is no complete stance (a standing trial, a single stance cut by the window).
std::optional<double> median_stance_s(const std::array<std::vector<bool>, 2>& contact, double rate_hz);

/// One foot's stances as gait_events marks them (below): its runs of contact with flickers under
/// 20 ms bridged, runs under 50 ms left out; none without a positive rate.
std::vector<IndexRun> gait_stances(const std::vector<bool>& contact, double rate_hz);

/// A gait event from the estimate's contact states (C3D's and Vicon's names): "Foot Strike" at
/// the first frame of a stance, "Foot Off" at the first frame after it. Stances are the runs of
/// contact with flickers under 20 ms bridged and runs under 50 ms left out (as median_stance_s
/// takes them); a run that begins at the window's first frame has no strike in it, one that ends
/// at its last frame no foot off (the window cut them).
struct GaitEvent {
  std::string label;    ///< "Foot Strike" or "Foot Off"
  int side = 0;         ///< 0 right, 1 left
  Eigen::Index index = 0;  ///< frame in the window (EstimateResult::first_frame_number + index in the file)
  double time_s = 0.0;
};
/// Every foot's events, in time order (at one frame: the right foot first).
std::vector<GaitEvent> gait_events(const std::array<std::vector<bool>, 2>& contact, const Eigen::VectorXd& time_s, double rate_hz);

/// Where the one level floor does not explain the support (kin2grf's contact is with a single
/// floor, Sect. 2.3), for runs of at least kSupportNoteRunS:
/// - a foot that carries more than kLoadedFootFraction of the body weight while its lowest sole
///   point stands more than kRaisedSoleM above the floor: on a box, a step or a stair. A foot on
///   the floor stands within marker placement and floor calibration of it (the development
///   trials' loaded feet within 36 mm, a run's impact within 0.1 m for under 30 ms); a kerb, a
///   step or a box is 0.1-0.4 m. The Alart-Curnier criterion with r = 1000 N/m lets a foot that
///   must carry W newtons do so up to W / r above the floor, so the load is taken there, silently
///   until this note; the COP is placed on the raised sole and the GRM's lever for the fore-aft
///   force is the floor's height.
/// - frames whose kinematics ask more than kSupportedFraction of the body weight of the ground
///   (the vertical force sum m (a_y + g); a flight asks under 0.2) while neither foot is in
///   contact: something else carries the body (a box, a chair, a handrail) or the floor is not
///   where the contact put it. The ground reaction there is zero; the residual holds the load.
/// `vertical_sum_N`: vertical_force_sum_N; `body_weight_N`: the body mass times g; the frame
/// numbers in the notes are the file's (first_frame_number + index).
inline constexpr double kLoadedFootFraction = 0.2, kRaisedSoleM = 0.05, kSupportedFraction = 0.5, kSupportNoteRunS = 0.1;
std::vector<std::string> support_notes(const std::array<FootResult, 2>& feet, const Eigen::VectorXd& vertical_sum_N,
                                       double body_weight_N, double rate_hz, double ground_level_m, int first_frame_number);

/// A walking double support: frames [first, last] where both feet are in contact, the trailing
/// foot alone in contact on the frame before and the leading foot alone on the frame after.
struct DoubleSupport {
  Eigen::Index first = 0, last = 0;
  int trailing = 0;  ///< 0 right, 1 left
};
/// The trial's walking double supports of at most max_frames frames (longer ones are standing
/// or shuffling, not a handover from one step to the next).
std::vector<DoubleSupport> walking_double_supports(const std::array<std::vector<bool>, 2>& contact, Eigen::Index max_frames);
/// The trailing foot's share of the vertical force at time fraction u (0-1) of a double
/// support under the smooth transition assumption: 1 - 3u^2 + 2u^3 (1 at its start, 0 at its
/// end, no step in the force at either).
inline double smooth_transition_share(double u) {
  u = u < 0 ? 0 : u > 1 ? 1 : u;
  return 1 - u * u * (3 - 2 * u);
}

/// The right foot's share of two feet's vertical force from the whole body's frontal balance
/// (EstimateOptions::frontal_split_weight): the ground reaction's line passes through the centre
/// of mass (the whole body's angular momentum about it neglected), so its centre of pressure
/// lies at z_P = z_G - h F_z / F_y (z lateral, h the COM's height above the floor, F_z the whole
/// body's lateral inertial force M a_Gz, F_y the feet's vertical total), and two feet at z_R
/// and z_L carry F_y (z_L - z_P) / (z_L - z_R) and the rest. Clamped to [0, 1]; NaN where the
/// feet stand less than `min_width_m` apart across the plane, or F_y is not positive.
inline double frontal_balance_right_share(double com_lateral_m, double com_height_m, double lateral_total_N, double vertical_total_N,
                                          double right_lateral_m, double left_lateral_m, double min_width_m = 0.05) {
  const double width = left_lateral_m - right_lateral_m;
  if (!(vertical_total_N > 0) || !(std::abs(width) >= min_width_m)) return std::numeric_limits<double>::quiet_NaN();
  const double z_p = com_lateral_m - com_height_m * lateral_total_N / vertical_total_N;
  const double share = (left_lateral_m - z_p) / width;
  return std::clamp(share, 0.0, 1.0);
}

/// A contact point's tangential multiplier after the double-support transition scaled its normal
/// one from `normal_N` to `new_normal_N` (EstimateOptions::double_support_angle = `angle`): the
/// tangential one scaled by 1 + angle (f - 1), f = new_normal_N / normal_N, so at 1 the point's
/// force angle is kept. Growing, it stops at the new normal force (a 45-degree lean, beyond any
/// walking foot's friction; a lightly loaded point's solved angle is not trusted further) or at
/// the solved tangential force, whichever is larger; shrinking needs no bound.
inline double transition_tangent(double tangent_N, double normal_N, double new_normal_N, double angle) {
  if (!(normal_N > 0) || angle <= 0) return tangent_N;
  const double t = tangent_N * (1 + angle * (new_normal_N / normal_N - 1));
  const double limit = std::max(std::abs(tangent_N), std::abs(new_normal_N));
  return std::abs(t) <= limit ? t : std::copysign(limit, t);
}

/// The hip's horizontal speed (m/s), median over the window of its displacement over +-0.25 s.
double progression_speed(const SagittalLandmarks& lm);

EstimateResult estimate(const Trial& trial, const Trial* static_trial, const MarkerSet& set,
                        const EstimateOptions& options);
/// The same, taking the trial: its marker samples are released as soon as the landmarks are made
/// (its path, warnings and everything else are kept), so that a long trial's markers and its
/// results are never held together (the memory of long trials). The results are the same.
EstimateResult estimate(Trial&& trial, const Trial* static_trial, const MarkerSet& set, const EstimateOptions& options);

/// One foot's result at one processed frame in the lab frame of the input: force on the body (N)
/// and COP (m; NaN without contact). A turning trial's frame takes that frame's heading.
struct LabFootFrame {
  Eigen::Vector3d force_N, cop_m;
};
LabFootFrame lab_foot_frame(const EstimateResult& r, int side, Eigen::Index i);
/// FootResult::cop_lateral_m's rule: per frame, on the line (heel x, heel lateral, forefoot x,
/// forefoot lateral) at the COP's fraction of the way from heel to forefoot, clamped to the line's
/// ends; NaN where the COP is (no contact). A line of no length: its midpoint. Past the forefoot
/// end (the push-off's roll onto the toes) the COP turns medially, towards the hallux, by
/// `toe_medial_slope` m per m it lies ahead of that end (EstimateOptions::toe_medial_slope; 0: it
/// stays at the end's lateral place); `side` 0 right, 1 left says which way is medial (the lateral
/// axis points to the walker's right).
Eigen::VectorXd cop_lateral_on_foot_line(const Eigen::MatrixX4d& line, const Eigen::VectorXd& cop_x_m, double toe_medial_slope = 0.0,
                                         int side = 0);
/// Each foot's estimated ground reaction (lab_foot_frame, no free moment) as the wrench the 3D
/// joint moments take.
std::array<FootWrench3D, 2> estimated_wrenches(const EstimateResult& r);
/// The per-foot results as lab-frame force plates (force, COP, free moment), lab_foot_frame for
/// every frame.
std::array<ForcePlate, 2> as_lab_plates(const EstimateResult& r);
/// The same over every frame of the trial (`trial_frames` rows, trial frame = r.first_index + the
/// window's), each force and COP turned by R (an export's frame): zero force and a NaN COP outside
/// the processed window and wherever the foot is not in contact; free moment zero. What the
/// exports write (OpenSim's .mot, the C3D's platforms).
std::array<ForcePlate, 2> trial_foot_plates(const EstimateResult& r, Eigen::Index trial_frames, const Eigen::Matrix3d& R);

}  // namespace kin2grf
