// kin2grf validation: an estimate against the force plates of the same trial (paper Sect. 3).
//
// 1. Measured plates -> marker frames (resample_plates). Each marker frame i averages the plate
//    samples within half a frame period of its time, force and moment alike; the COP is then
//    recomputed from the averaged force and moment (averaging COPs would weight unloaded
//    samples like loaded ones). Everything goes to the estimate's sagittal frame:
//      F_x = F . forward, F_y = F . up, m_O = M_O . lateral = x F_y - y F_x  (moment about the
//    lab origin; a plate's free moment is vertical and drops out of the sagittal moment). A
//    turning frame (SagittalFrame) uses each frame's heading and adds x_offset F_y to m_O.
// 2. Stances: runs of frames where a plate's vertical force exceeds the threshold (20 N).
// 3. Plate-to-foot assignment by distance, not by name: the median over the stance of the
//    horizontal distance from the measured COP to the foot's heel-hallux segment (lateral
//    position of the foot from the landmarks). The nearer foot takes the stance if it is within
//    max_assign_distance_m. Excluded, with a reason: a stance cut by the processed window's ends;
//    a plate also under the other foot (a sole point of the other foot at ground level, still,
//    over the plate: a swinging foot's toes skim plates); a foot partly off its plate (a sole
//    point at ground level more than edge_margin_m outside the plate's edges); a foot on two
//    plates at once. Without plate geometry (GRF .mot) the last three
//    cannot be checked, which is said in `notes`.
// 4. Per stance: vertical and anterior GRF, COP along progression (frames loaded above
//    cop_min_force_fraction of body weight: a barely loaded plate's COP is noise), and the
//    sagittal moment about the plate centre (without geometry: about the stance's mean
//    measured COP). Contact onset/offset, estimate - plate: threshold crossings, interpolated;
//    the onsets on a plate filtered before export (step 7) by the loading ramp's zero intercept
//    (ValidationOptions::Timing).
//    Registration check: under more than half the body weight a foot's COP lies between its heel
//    and toe markers, which sit within 1-2 cm of the sole's ends, except briefly at push-off. When
//    the median over those frames of the plate COP's distance beyond that span exceeds
//    max_cop_beyond_foot_m, the plate and the markers disagree on where the foot is (a plate
//    origin or a lab alignment off by centimetres): the stance's COP and moment, which measure
//    that disagreement, are reported but left out of the means and of fit-cop, with a note.
//    Forces do not depend on where the plate is, so vertical and anterior are scored.
// 5. Total: frames where every plate in use belongs to a kept stance and the plates carry the
//    whole body (median |sum of plate F_y - sum m (a_y + g)| < 15 % of body weight over each run
//    of frames with the same plates loaded, sum m(a+g) from the kinematics alone), i.e. every
//    loaded foot is on a plate; and no foot stands on the floor off the plates: a frame where a
//    foot has a sole point within 2 cm of the ground and slower than 0.3 m/s (the kinematics,
//    not the estimate's contact state) outside every kept stance of that foot is left out. Vertical, anterior and the GRM about the midpoint of the plate
//    centres in use (without geometry: the mean measured COP over those frames, the belt's
//    centre on a treadmill).
// 6. The marker-plate time offset (SyncEstimate, below), reported always; applied only when
//    asked (ValidationOptions::sync).
// 7. Whether each plate was low-pass filtered before export, from its noise or its rise
//    (PlateOnsetRise, below): such a plate's threshold crossings lead the contact, so its onsets
//    are timed by the loading ramp (step 4), with a note; one set to zero below a threshold is
//    said in `notes`. The plates' forces are never altered.
#pragma once

#include <Eigen/Dense>
#include <nlohmann/json.hpp>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "kin2grf/trial.hpp"
#include "kin2grf/dynamics/joint_moments_2d.hpp"
#include "kin2grf/dynamics/stance_parameters.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/validation/metrics.hpp"

namespace kin2grf {

/// One plate resampled to the estimate's frames, sagittal frame, SI units.
struct MeasuredPlate {
  std::string name;
  Side side_hint = Side::General;
  bool has_geometry = false;
  Eigen::MatrixX2d force_N;        ///< (anterior, vertical); NaN outside the plate recording
  Eigen::VectorXd force_lateral_N; ///< along the sagittal frame's lateral axis; NaN outside
  Eigen::VectorXd moment_origin_Nm;///< sagittal moment about the lab origin
  Eigen::VectorXd cop_x_m;         ///< NaN where the vertical force is below cop_threshold_N
  Eigen::VectorXd cop_lateral_m;
  double surface_y_m = 0.0;        ///< plate surface height in the sagittal frame
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();  ///< (x, lateral) of the surface centre
  /// The rectangle itself (with geometry), in the same (x, lateral) coordinates: the unit vector
  /// of its edges nearer the progression, and its half length along them and half width across.
  /// A plate at an angle to the progression covers less than its extent.
  Eigen::Vector2d along = Eigen::Vector2d::UnitX();
  double half_along_m = 0.0, half_across_m = 0.0;
  /// Whether (x, lateral) lies on the plate: within `margin_along_m` of it along `along`, within
  /// it across.
  [[nodiscard]] bool covers(double x, double lateral, double margin_along_m = 0.0) const;
  /// The lab-frame force (N) and its moment about the lab origin (N m), free moment included: the
  /// wrench the plate-driven 3D joint moments take (validate_joint_moments_3d); NaN outside.
  Eigen::MatrixX3d force_lab_N, moment_origin_lab_Nm;
};

/// `first_index`: the trial frame of frame_time_s[0] (a turning frame's heading is per trial
/// frame). With turns, a plate's extent and centre are projected with the heading at the middle
/// of its loaded samples (a stance turns by a few degrees at most).
std::vector<MeasuredPlate> resample_plates(const ForcePlateRecording& rec, const SagittalFrame& frame,
                                           const Eigen::VectorXd& frame_time_s, double cop_threshold_N,
                                           Eigen::Index first_index = 0);

struct ValidationOptions {
  double threshold_N = 20.0;               ///< stance: measured vertical force above this
  double cop_min_force_fraction = 0.05;    ///< COP compared where vertical > this x body weight
  double max_assign_distance_m = 0.15;     ///< COP to foot distance for an assignment
  /// Registration check (step 4): the median distance of the loaded COP beyond the heel-toe span.
  /// Every development trial's well-registered plates give 0 mm, the Camargo export's 19-46 mm.
  double max_cop_beyond_foot_m = 0.015;
  double ground_contact_height_m = 0.02;   ///< a sole point this close to the ground touches it
  /// A sole point may lie this far outside a plate edge before the foot counts as partly off:
  /// A and B are under the heel and MT markers, a few cm behind and beside the loaded area.
  double edge_margin_m = 0.03;
  double still_speed_mps = 0.3;            ///< the other foot stands on a plate only when this still
  double total_mismatch_fraction = 0.15;   ///< of body weight (step 5)
  /// The marker-plate time offset (step 6): None compares as recorded and only reports the
  /// estimated offset; Auto compares after shifting the plates by it; Fixed by plate_shift_s.
  enum class Sync { None, Auto, Fixed } sync = Sync::None;
  double plate_shift_s = 0.0;  ///< Sync::Fixed: added to the plates' times (+: the plates led the markers)
  /// How each stance's onset and offset are timed (StanceValidation::onset_error_ms): Crossing,
  /// the threshold's crossings of the estimate and of the plate; Ramp, the loading and unloading
  /// ramps' zero intercepts of both (loading_ramp_onset); Auto, the loading ramp for the onsets of
  /// the stances on a plate filtered before export (step 7: PlateOnsetRise::filtered), the
  /// crossings for every other onset and every offset. A raw plate's crossing is the foot's
  /// contact; a filtered export's leads it by the filter's spread, which an onset compared with it
  /// would read as the estimate's lateness. Measured on the raw-plate walks exported through 6 Hz
  /// (`kin2grf study plate-export`; docs/METHOD-NOTES.md, session 44): the export moves the onsets
  /// timed by the crossings 23-25 ms, by the ramps 8 ms; the offsets by the crossings 5 ms, by the
  /// ramps 8 (a push-off unloads smoothly: little for a filter to spread), so offsets keep theirs.
  enum class Timing { Auto, Crossing, Ramp } timing = Timing::Auto;
};

/// Step 6: the time offset between the markers and the plates, from the whole body. The plates'
/// summed vertical force equals the kinematic total sum m (a_y + g) wherever they carry every
/// loaded foot; the kinematic total depends on the markers alone (not on the contact model). The
/// plates' sum is filtered like the kinematics (zero-lag Butterworth at the dynamics' kinematic
/// cut-off) and shifted by whole frames up to +-kMaxSyncShiftS; over the frames where the plates
/// are loaded, the shift of least median |plates - kinematics| (robust to the frames where a foot
/// stands beside the plates, a minority on a walk over plates), refined by a parabola, is the
/// offset. + = the plates lead the markers (a plate event at t shows in the markers at
/// t + offset); shifting the plates' times by +offset aligns them. Its uncertainty is the
/// half-width of the shifts whose median error lies within 10 % of the least: a flat minimum (a
/// circuit whose feet are mostly off the plates) pins nothing down.
inline constexpr double kMaxSyncShiftS = 0.1;
struct SyncEstimate {
  double offset_s = 0.0;
  double uncertainty_s = 0.0;
  double error_as_recorded_N = 0.0, error_at_offset_N = 0.0;  ///< median |plates - kinematics| at shift 0 and at the offset
  int frames = 0;  ///< frames compared
};

/// Step 7: whether a plate's signal was low-pass filtered before export, from its own samples. A
/// filtered signal's threshold crossings lead the foot's contact (and lag its lift-off) by the
/// filter's spread, which an onset compared with them would read as the estimate's lateness
/// (ValidationOptions::Timing). Two signs tell it, the noise where it can be measured, the rise
/// elsewhere (a raw plate under a soft landing rises slowly and keeps its noise):
/// - The rise. A raw plate's signal leaves its noise (about 1 N) for the threshold within a few
///   ms at a foot strike: from a hundredth of the threshold to the threshold (both crossings
///   interpolated between samples) in 0.5-10 ms on the development trials' C3D analog channels and
///   Camargo's export (the impact loads a plate at several N/ms). A signal low-pass filtered before
///   export creeps there from its smoothed tail: 24-28 ms on Rajagopal's and subject01's GRF .mot
///   files. Only a rise beyond kFilteredRiseMs is told: a 6 Hz filter over a sharp foot strike
///   (8 N/ms) spreads it by about 11 ms and passes for raw, over a soft one (3 N/ms) by more than 15.
/// - The noise. A raw plate carries its amplifier's and converter's noise at every frequency, where
///   a signal filtered below 50 Hz keeps only its rounding. The vertical force's RMS above 50 Hz,
///   over the loaded samples two 50 Hz periods clear of each loaded run's ends (a thresholded
///   export's step there is not noise): 0.24-15 N on the development trials' raw plates (their C3D
///   channels, and the GRF files of Stanford's run, UFABC and OpenCap's drop jump), 0.001-0.009 N on
///   Rajagopal's, subject01's and OpenCap's walking files. Under kRawNoiseFloorN (a fifth of the
///   quietest raw plate, five times the noisiest filtered one) it is filtered. Measured where the
///   plate's rate is at least kNoiseRateHz (50 Hz a fifth of it), so not on plates resampled to a
///   marker rate, where only the rise tells.
/// A signal exactly zero before its onsets and stepping to at least the threshold was set to zero
/// below some level before export (OpenCap's GRF .mot files: 0 N, then 20.7 N): its onsets are that
/// level's crossing, the stance threshold's own when the level is it, so it is said, not corrected.
/// Such a file can be filtered too, and the signs above then tell it (OpenCap's walking files).
inline constexpr double kFilteredRiseMs = 15.0;
inline constexpr double kRawNoiseFloorN = 0.05, kNoiseRateHz = 250.0, kNoiseBandHz = 50.0;
struct PlateOnsetRise {
  std::string plate;
  int onsets = 0;  ///< rising crossings of the threshold in the recording that rise from the floor within 0.1 s
  /// Median time (ms) from the signal's last rise through a hundredth of the threshold (the floor)
  /// to its crossing of the threshold, both interpolated between samples.
  double rise_ms = std::numeric_limits<double>::quiet_NaN();
  /// RMS (N) of the vertical force above kNoiseBandHz (its residual from a zero-lag low-pass
  /// there) over the samples above the threshold; NaN where not measured (a rate under
  /// kNoiseRateHz, non-finite samples, no load).
  double high_frequency_rms_N = std::numeric_limits<double>::quiet_NaN();
  /// Every onset comes from exact zeros with a step to at least the threshold (a thresholded export).
  bool zero_below_threshold = false;
  [[nodiscard]] bool filtered_by_rise() const { return onsets > 0 && rise_ms > kFilteredRiseMs; }
  [[nodiscard]] bool filtered_by_noise() const { return high_frequency_rms_N < kRawNoiseFloorN; }
  /// By its noise where measured, by its rise elsewhere.
  [[nodiscard]] bool filtered() const { return std::isfinite(high_frequency_rms_N) ? filtered_by_noise() : filtered_by_rise(); }
};
/// Each plate's onsets in `rec` (vertical: the force along `up`, lab frame).
std::vector<PlateOnsetRise> plate_onset_rises(const ForcePlateRecording& rec, const Eigen::Vector3d& up, double threshold_N);

struct ComponentMetrics {
  std::optional<SeriesMetrics> vertical, anterior, cop, moment;
  /// The mediolateral force and the COP's lateral place (m), when the estimate has them
  /// (EstimateOptions::mediolateral).
  std::optional<SeriesMetrics> lateral, cop_lateral;
  /// The free moment about the vertical (N m) where the COP is compared: the estimate's is zero
  /// (not estimated), so this reports the plate's own, as the error of that zero.
  std::optional<SeriesMetrics> free_moment;
};

/// One stance's 3D joint moments (ModelKind::ThreeD): driven by the estimate's ground reaction
/// against driven by the plate's, on the same leg kinematics (EstimateResult::legs_3d), so that
/// the difference is the estimate's alone. Components as JointMoments3D's (sagittal, frontal,
/// transverse, internal moments on the distal segment).
struct JointMomentValidation {
  std::array<std::optional<SeriesMetrics>, 3> ankle, knee, hip;
  std::optional<SeriesMetrics> knee_adduction;  ///< the external knee adduction moment (KAM)
  /// The KAM's first and second peaks (N m): its largest value in the first and in the second
  /// half of the stance, estimate-driven and plate-driven.
  std::array<double, 2> kam_peak_estimated_Nm{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  std::array<double, 2> kam_peak_measured_Nm{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  /// The KAM's angular impulse over the stance (N m s; stance_impulse: its positive part's time
  /// integral), estimate-driven and plate-driven.
  double kam_impulse_estimated_Nm_s = std::numeric_limits<double>::quiet_NaN();
  double kam_impulse_measured_Nm_s = std::numeric_limits<double>::quiet_NaN();
};

/// One stance's sagittal joint torques (hip, knee, ankle; every model): against the torques a
/// lab's inverse dynamics takes from the plate, bottom-up from the foot's plate on the estimate's
/// own motion (dynamics/joint_moments_2d.hpp), so that the difference is the estimate's ground
/// reaction's (and the least squares') alone. `least_squares`: kin2grf's own torques, the
/// multipliers of Eq. 7 (EstimateResult::joint_torque_Nm, the CSV's); `bottom_up`: bottom-up from
/// the estimate's ground reaction, its COP on the floor, as a lab's tool run on kin2grf's GRF
/// file (the OpenSim export) computes them on this motion.
struct JointTorqueValidation {
  std::array<std::optional<SeriesMetrics>, 3> least_squares, bottom_up;  ///< hip, knee, ankle; N m
  /// The joint powers (W; joint_angular_velocities): kin2grf's torques times the joints' angular
  /// velocities against the plates' torques times the same, hip, knee, ankle.
  std::array<std::optional<SeriesMetrics>, 3> power;
  /// The joint kinetic peaks a gait report reads (joint_kinetic_peaks: the ankle's plantarflexor
  /// moment, its push-off power, the A2 burst, the knee's extensor moment, the hip's extensor and
  /// flexor moments), kin2grf's and the plates' (over the frames where the plate reads).
  JointKineticPeaks peaks_estimated, peaks_measured;
  double mass_kg = 0.0;  ///< the estimate's body mass, for the RMSE in N m/kg
};

struct StanceValidation {
  int foot = 0;                 ///< 0 right, 1 left
  std::string plate;
  int plate_index = -1;         ///< in ValidationResult::plates
  Eigen::Index first = 0, last = 0;  ///< frames in the estimate's window (inclusive)
  double assign_distance_m = 0.0;
  double body_weight_N = 0.0;  ///< the estimate's (for errors in % body weight)
  /// Step 4's registration check: median over the frames above half the body weight of the plate
  /// COP's distance beyond the foot's heel-toe landmark span (0: inside); NaN without such frames.
  double cop_beyond_foot_m = 0.0;
  /// cop_beyond_foot_m > max_cop_beyond_foot_m: metrics.cop and metrics.moment are kept for the
  /// record but left out of mean_rrmse and of the COP fit; so are metrics.cop_lateral and
  /// moments_3d, whose plate-driven joint moments take the plate's COP as their lever.
  bool cop_reference_suspect = false;
  /// The foot's sole length, heel to toe sole point (median over the stance; NaN without the
  /// sole series): the COP's RMSE is also given in % of it.
  double foot_length_m = std::numeric_limits<double>::quiet_NaN();
  ComponentMetrics metrics;
  /// Contact timing, estimate - plate (ms; + = late): the threshold's crossings or, when
  /// onset_by_ramp (offset_by_ramp), the loading (unloading) ramp's zero intercepts
  /// (ValidationOptions::Timing).
  std::optional<double> onset_error_ms, offset_error_ms;
  bool onset_by_ramp = false, offset_by_ramp = false;
  /// Both timings, whichever scores the stance: the threshold's crossings of both series, and the
  /// ramps' intercepts of both (loading_ramp_onset, unloading_ramp_offset).
  std::optional<double> onset_crossing_error_ms, offset_crossing_error_ms, onset_ramp_error_ms, offset_ramp_error_ms;
  /// The loaded span: the stance's frames with the estimate's loaded frames next to them (its
  /// vertical force above the stance threshold while the plate reads below it, at most 0.2 s on
  /// each side), in the estimate's window, inclusive. The vertical rRMSE above compares the plate's
  /// stance alone, which does not see a foot loaded before it lands or after it lifts; the foot is
  /// in the air there, so the plate's own reading (about 0 N) is its load.
  Eigen::Index span_first = 0, span_last = 0;
  std::optional<SeriesMetrics> vertical_loaded_span;  ///< vertical force over the loaded span
  /// Where the stance's vertical error lies: its RMSE (N) over the frames where the other foot is
  /// loaded too (double support: the estimate or the other foot's plate above the stance
  /// threshold) and over the rest (single support), with their frame counts; NaN where there are
  /// none. On issue 29's held-out walks and on the development ones most of the per-foot error
  /// lies in double support, where the feet share the load (docs/METHOD-NOTES.md).
  double vertical_rmse_double_support_N = std::numeric_limits<double>::quiet_NaN();
  double vertical_rmse_single_support_N = std::numeric_limits<double>::quiet_NaN();
  int double_support_frames = 0, single_support_frames = 0;
  /// The stance's ground reaction parameters (dynamics/stance_parameters.hpp: the vertical
  /// force's peaks and valley, the braking and propulsive peaks, the impulses, the loading rate)
  /// of the estimate's force and of the plate's, over the loaded span [span_first, span_last]
  /// (the plate's stance and the estimate's loaded frames next to it: an early estimate's rise is
  /// seen): what a gait report tabulates.
  StanceParameters parameters_estimated, parameters_measured;
  /// Time shift of the estimate's vertical force that best matches the plate over the stance
  /// (least RMSE over shifts of up to 60 ms, parabolic refinement between frames); + = the
  /// estimate lags, - = it leads.
  std::optional<double> vertical_lag_ms;
  Eigen::Vector2d moment_reference_m = Eigen::Vector2d::Zero();
  std::optional<JointMomentValidation> moments_3d;  ///< ModelKind::ThreeD
  /// The sagittal joint torques (not for a stance whose plate fails the registration check: the
  /// plate-driven torques take its COP as their lever; nor for a cut stance).
  std::optional<JointTorqueValidation> torques;
};

struct TotalValidation {
  std::vector<Eigen::Index> frames;   ///< frames compared (estimate's window)
  Eigen::Vector2d grm_reference_m = Eigen::Vector2d::Zero();
  ComponentMetrics metrics;           ///< vertical, anterior, moment = GRM
  Eigen::VectorXd grm_estimated_Nm, grm_measured_Nm;  ///< over all frames (NaN outside `frames`)
  Eigen::VectorXd vertical_estimated_N, vertical_measured_N;  ///< likewise
  /// Body mass that makes the kinematic vertical total fit the plates best (least squares over
  /// `frames`; the kinematic total is linear in the mass): a check on the mass given.
  double implied_mass_kg = 0.0;
  /// With the estimate's lateral force (--mediolateral, --model 3d; validate_total_3d): the total
  /// ground reaction's frontal moment (M . forward, right-hand rule about the walker's forward
  /// axis) and transverse moment (M . up, the plates' free moments included), N m,
  /// about the GRM reference point on the walker's midline (`lateral_reference_m`, the mean of
  /// the two feet's lateral places over `frames`).
  std::optional<SeriesMetrics> frontal_moment, transverse_moment;
  /// Their series over all frames (NaN outside `frames`), estimate and plates: the report's plots.
  Eigen::VectorXd frontal_estimated_Nm, frontal_measured_Nm, transverse_estimated_Nm, transverse_measured_Nm;
  double lateral_reference_m = 0.0;
};

struct ValidationResult {
  double mass_kg = 0.0;
  int first_frame_number = 1;  ///< file frame number of the estimate's first frame
  std::vector<MeasuredPlate> plates;
  std::vector<StanceValidation> stances;
  /// Plate stances cut by the processed window's ends (a trial that starts or ends on a plate: a
  /// standing start, a squat, the paper's unilateral squat jump from standing), compared as the
  /// others over their frames in the window (their plates in the per-foot measured series, the
  /// report's plots), and kept out of every mean, the 3D moments and the totals (unless the trial
  /// has no complete stance, whose total is then compared over them): a part of a stance has part of its range (Eq. 12 divides by it) and
  /// the filters see one side of it at the window's edge. No onset (offset) where the
  /// stance begins (ends) at the window's edge. Their vertical RMSE in % body weight is the figure
  /// to read on a quiet stance, whose range is a few newtons.
  std::vector<StanceValidation> cut_stances;
  std::optional<TotalValidation> total;
  std::vector<std::string> excluded;  ///< one reason per excluded stance or window
  std::vector<std::string> notes;
  /// Per-frame measured per-foot series (sum of the foot's kept stances, the cut ones included;
  /// NaN elsewhere): the report's plots.
  std::array<Eigen::MatrixX2d, 2> measured_force_N;
  std::array<Eigen::VectorXd, 2> measured_cop_x_m;
  /// Likewise the lateral force (N) and the COP's lateral place (m, where the COP is compared),
  /// with the estimate's lateral force (--mediolateral, --model 3d) only; empty otherwise.
  std::array<Eigen::VectorXd, 2> measured_lateral_N, measured_cop_lateral_m;
  /// Step 6, from the plates as recorded (none with fewer than 10 loaded frames clear of the
  /// recording's ends by the search's reach, or when the best shift lies at the search's limit).
  std::optional<SyncEstimate> sync;
  /// Step 7, per plate of the recording (as recorded): how its vertical force rises at its onsets.
  std::vector<PlateOnsetRise> plate_onsets;
  double plate_shift_s = 0.0;  ///< the shift the comparison above was made with (0 unless Sync::Auto or Fixed)
  /// ModelKind::ThreeD: the 3D joint moments driven by each foot's kept stances' plates (zero
  /// ground reaction elsewhere, so only the kept stances' frames are meaningful).
  std::optional<JointMoments3D> measured_moments_3d;
  /// The sagittal joint torques bottom-up from the plates (validate_joint_torques; N x
  /// kJointCount, the columns of EstimateResult::joint_torque_Nm), over the frames of each leg's
  /// scored stances, NaN elsewhere (empty without any): the report's plots.
  Eigen::MatrixXd measured_joint_torque_Nm;
};

ValidationResult validate(const EstimateResult& estimate, const ForcePlateRecording& plates,
                          const ValidationOptions& options = {});

/// The 3D joint moments' comparison (validate calls it when the estimate has EstimateResult::
/// legs_3d): each foot's kept stances' plate wrenches (force and moment about the lab origin,
/// free moment included) drive joint_moments_3d on the estimate's leg kinematics, into
/// v.measured_moments_3d, and each stance gets its JointMomentValidation.
void validate_joint_moments_3d(const EstimateResult& estimate, ValidationResult& v);
/// The sagittal joint torques' comparison (StanceValidation::torques), on every kept stance whose
/// plate passes the registration check; validate calls it.
void validate_joint_torques(const EstimateResult& estimate, ValidationResult& v);
/// The total's frontal and transverse moments (TotalValidation::frontal_moment), estimate's
/// (both feet's wrenches, lab_foot_frame) against the plates' (every plate's measured force and
/// moment) over the total's frames; validate calls it when the estimate has a lateral force.
void validate_total_3d(const EstimateResult& estimate, ValidationResult& v);

/// Mean (and SD) over the stances of each component's rRMSE, per foot or all.
struct MeanMetrics {
  int n = 0;
  double vertical = 0, anterior = 0, cop = 0, moment = 0, lateral = 0;
  /// Mean vertical rRMSE over each stance's loaded span (StanceValidation::vertical_loaded_span).
  double vertical_loaded_span = 0;
  /// The stances' vertical RMSE in double and in single support (StanceValidation::
  /// vertical_rmse_double_support_N), each the mean over the stances that have such frames, in %
  /// of body weight; and double support's share of the stances' summed squared vertical error, %.
  /// NaN without such frames.
  double vertical_rmse_double_support_percent_bw = 0, vertical_rmse_single_support_percent_bw = 0;
  double double_support_error_share_percent = 0;
  double vertical_sd = 0, anterior_sd = 0, cop_sd = 0, moment_sd = 0, lateral_sd = 0;
  /// Mean mediolateral force RMSE, % body weight (NaN without --mediolateral): its rRMSE divides
  /// by a range of 10-15 % body weight, so a few newtons read large.
  double lateral_rmse_percent_bw = 0;
  double cop_lateral_rmse_mm = 0;  ///< mean over the stances (NaN without --mediolateral)
  /// The COP's RMSE along progression, mm: mean over the stances whose plate passes the
  /// registration check (as `cop`; NaN without such a stance).
  double cop_rmse_mm = 0;
  /// Mean |onset error| (ms) over the stances that have one (NaN without): the contact timing,
  /// which the rRMSEs, scored from the plate's onset on, do not see.
  double onset_abs_ms = 0;
  /// ModelKind::ThreeD (NaN otherwise): mean rRMSE of the knee's sagittal moment and of the
  /// external knee adduction moment, and the KAM's first and second peaks' mean |estimate -
  /// plates| in % of the plate-driven peaks' mean |value| (a ratio of means: one stance's
  /// plate-driven peak near 0 N m would make its own percentage meaningless).
  double knee_sagittal = 0, knee_adduction = 0;
  std::array<double, 2> kam_peak_error_percent{0, 0};
  /// The KAM's angular impulse: mean |estimate - plates| in % of the plate-driven impulses' mean
  /// (a ratio of means, as the peaks'); NaN where no stance has both.
  double kam_impulse_error_percent = 0;
  /// The sagittal joint torques (StanceValidation::torques), hip, knee, ankle: mean rRMSE (%) of
  /// kin2grf's least-squares torques and of the bottom-up ones from its forces, and the mean RMSE
  /// of the least-squares ones in N m per kg of body mass. NaN where no stance has them.
  std::array<double, 3> torque_least_squares{0, 0, 0}, torque_bottom_up{0, 0, 0}, torque_rmse_Nm_per_kg{0, 0, 0};
  /// The joint powers' mean rRMSE (%), hip, knee, ankle; the ankle push-off peak's mean |kin2grf -
  /// plates| and the plates' mean peak, W/kg.
  std::array<double, 3> power{0, 0, 0};
  double ankle_push_off_error_W_per_kg = 0, ankle_push_off_plates_W_per_kg = 0;
  /// The moment peaks' mean |kin2grf - plates| and the plates' mean, N m/kg: the ankle's
  /// plantarflexor, the knee's extensor, the hip's extensor and flexor moments (JointKineticPeaks).
  std::array<double, 4> moment_peak_error_Nm_per_kg{0, 0, 0, 0}, moment_peak_plates_Nm_per_kg{0, 0, 0, 0};
  /// The stance parameters' mean |estimate - plate| over the stances (StanceValidation::
  /// parameters_estimated): the vertical first peak, valley and second peak and the braking and
  /// propulsive peaks in % body weight; the braking and propulsive impulses in body weight x
  /// milliseconds; the loading rate in % of the plates' (mean |error| over mean plate value). NaN
  /// where no stance has the value.
  std::array<double, 5> parameter_peak_error_percent_bw{0, 0, 0, 0, 0};
  std::array<double, 2> parameter_impulse_error_bw_ms{0, 0};
  double loading_rate_error_percent = 0;
};
MeanMetrics mean_rrmse(const std::vector<StanceValidation>& stances, int foot = -1);

/// The `--json` document (schema in docs/FORMATS.md, "validate").
nlohmann::json validation_json(const std::string& trial, const EstimateResult& e, const ValidationResult& v,
                               const nlohmann::json& settings);

/// Plain-text table in the layout of the paper's Table 1 (rRMSE %, mean (SD)).
std::string format_validation_table(const std::string& trial, const ValidationResult& v);

/// `validate --stance-curves`: each scored plate stance (v.stances) time-normalised over the
/// plate's stance (stance_normalised: its first to its last frame, `points` instants), the
/// estimate's and the plate's side by side, as a paper's mean curves of both are drawn: side (0
/// right, 1 left), plate (the index into v.plates), frame_first (the file's frame number), start_s,
/// duration_s, percent, vertical_bw_estimate, vertical_bw_plate, anterior_bw_estimate,
/// anterior_bw_plate, with the lateral force lateral_bw_estimate and lateral_bw_plate, then
/// cop_progression_m_estimate and cop_progression_m_plate: both COPs along progression over the
/// ground (on a treadmill over the belt) from the plate's first COP of the stance (one origin for
/// both, so their difference is the COP's error;
/// NaN where the plate's COP is below its threshold, and for a stance whose plate fails the
/// registration check, whose COP the means leave out too); with ModelKind::ThreeD the external
/// knee adduction moment, N m/kg, by inverse dynamics with kin2grf's and with the plate's ground
/// reaction on the same kinematics (knee_adduction_moment_Nm_per_kg_estimate, _plate; the plate's
/// NaN where its registration fails), then likewise every joint's 3D moment in every plane
/// (joint_moment_curve_name + _estimate, _plate).
ResultsTable validation_stance_curves_table(const EstimateResult& e, const ValidationResult& v, int points = kStanceCurvePoints);
/// The same as CSV (side as right / left, the plate by its name; 6 significant digits, an empty
/// cell where a value does not exist; docs/FORMATS.md).
std::string validation_stance_curves_csv(const EstimateResult& e, const ValidationResult& v);

}  // namespace kin2grf
