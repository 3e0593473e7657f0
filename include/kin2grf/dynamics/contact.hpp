// kin2grf dynamics: the foot-ground contact models of the paper (Sect. 2.3).
//
// Sole points (FootContactGeometry, below): A under the heel and B under the MT head, both
// on the foot; C under the hallux, on the toes. Foot inclination (paper's theta_A):
//   theta_A = -(theta_foot - theta_foot,flat),
// positive when the heel is raised (plantar flexion against the ground), negative at heel strike
// (toes up), so that the paper's event angles keep their signs (HS -0.3, HO 0, MO 0.15, TO 1 rad).
//
// Foot model 2 ("cop", the paper's, Eq. 2): one contact point D, the COP, with
//   y_D = min(y_A, y_B, y_C),  x_D = the point at arc length s = F(theta_A) x l along the sole
//   polyline A -> B -> C, l the function's length (CopLength): the sole's |AB| + |BC| (the
//   paper's: s = 1 at C) or the heel-to-MT-heads length (FootContactGeometry::heel_mt_length_m);
//   at most 1.25 sole lengths (beyond C along B -> C).
// F is piecewise between the four event angles: half-cosine (sinusoidal) HS->HO and HO->MO,
// linear MO->TO, constant outside, through the positions s_HS, s_HO, s_MO, s_TO (fitted, see
// docs/METHOD-NOTES.md). D* is the foot's material point at D this frame; contact at D*:
// normal gap g_n = y_D* - ground, multipliers lambda_n (normal) and lambda_t (tangential stick).
// Foot model 1 ("three-point"): non-penetration and sticking at A, B and C.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/model/foot_model.hpp"
#include "kin2grf/model/model.hpp"

namespace kin2grf {

/// The sole points of a foot used by the contact models: under the heel (A) and the MT head
/// (B) in the foot frame, under the hallux (C) in the toes frame, at ground level in the
/// foot-flat reference pose (Sect. 2.3).
struct FootContactGeometry {
  Eigen::Vector2d heel_local = Eigen::Vector2d::Zero();    ///< A, foot frame
  Eigen::Vector2d mt_local = Eigen::Vector2d::Zero();      ///< B, foot frame
  Eigen::Vector2d hallux_local = Eigen::Vector2d::Zero();  ///< C, toes frame
  double flat_angle_rad = 0.0;  ///< theta_foot (ankle->MT direction) in the foot-flat pose
  /// The heel-to-MT-heads length (m), the unit of a CopLength::HeelMt COP function: |AB| plus,
  /// where B is a 5th-metatarsal marker, SagittalLandmarks::mt_head_ahead_share of the median
  /// ankle-MT length (the 2nd head lies ahead of the 5th). 0: not measured, |AB| is taken.
  double heel_mt_length_m = 0.0;
};

/// The length (m) a COP function's fractions count in on a foot whose sole segments are l1 = |AB|
/// and l2 = |BC| this frame (CopLength).
inline double cop_length_m(CopLength length, const FootContactGeometry& foot, double l1, double l2) {
  if (length == CopLength::Sole) return l1 + l2;
  return foot.heel_mt_length_m > 0 ? foot.heel_mt_length_m : l1;
}

/// The floor and the soles of one trial (Sect. 2.3), measured once from its foot-flat frames
/// (calibrate_contact) and const afterwards.
struct ContactCalibration {
  double ground_level_m = 0.0;                ///< the floor's height in the sagittal frame
  std::array<FootContactGeometry, 2> feet{};  ///< sole points A, B, C per side
  std::array<int, 2> flat_frames{};           ///< the foot-flat frames they were measured on
  std::string message;                        ///< what calibrate_contact chose when not the usual
};

/// What one trial fixes before its frames are solved. Options hold the user's choices; this
/// holds the trial's measured values, each built once and const afterwards (the Model/Data split:
/// Model the subject, TrialCalibration the trial, ModelMotion and the solver's workspace the frames).
struct TrialCalibration {
  ContactCalibration contact;
  /// Ground velocity along x (m/s): a treadmill's belt, measured on every treadmill trial whatever
  /// the solver's settings (validation's still-foot rule needs it too); 0 overground.
  double belt_velocity_mps = 0.0;
  /// The subject's progression speed (m/s): overground the median over the window of the hip's
  /// horizontal speed over +-0.25 s (a step's average, not its oscillation); on a treadmill the
  /// belt's speed.
  double progression_speed_mps = 0.0;
  double speed_gate_mps = 0.0;  ///< the trial's contact speed gate (speed_gate_for); 0: none
  /// The gate on frames near a flight phase (FrameContacts::near_flight: landings from a jump or
  /// a run's flight), speed_gate_for(..., true); 0: none.
  double flight_speed_gate_mps = 0.0;
};

/// One row of a contact point's Jacobian, d(y)/dq or d(x)/dq (63 wide), by its non-zeros: a
/// point fixed on a body moves with the body's proximal point and its angle, so two entries at
/// most (model 2's D* is a coordinate of q: one). Stored dense it was 1 KB a point a frame.
struct ContactJacobian {
  static constexpr int kMaxEntries = 2;
  std::array<int, kMaxEntries> coordinate{};
  std::array<double, kMaxEntries> value{};
  int entries = 0;
  void add(int q_index, double v) {
    coordinate[static_cast<std::size_t>(entries)] = q_index;
    value[static_cast<std::size_t>(entries++)] = v;
  }
  /// The row as a dense 63-vector.
  [[nodiscard]] Eigen::VectorXd dense() const {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(coord::kCount);
    for (int e = 0; e < entries; ++e) d[coordinate[static_cast<std::size_t>(e)]] = value[static_cast<std::size_t>(e)];
    return d;
  }
};

/// One potential contact point this frame (model 2: D*, model 1: A, B or C).
struct ContactPoint {
  int side = 0;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< lab sagittal, m
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< of the material point, m/s
  double gap_m = 0.0;                                  ///< y - ground
  ContactJacobian jac_normal, jac_tangent;             ///< d(y)/dq and d(x)/dq
};

/// Contact points of one frame at most: three per foot (model 1).
inline constexpr int kMaxContactPoints = 6;

struct FrameContacts {
  std::vector<ContactPoint> points;  ///< model 2: [D*_R, D*_L]; model 1: [A_R,B_R,C_R,A_L,B_L,C_L] (at most kMaxContactPoints)
  std::array<double, 2> foot_inclination_rad{};  ///< theta_A per side
  std::array<double, 2> cop_fraction{};          ///< model 2: s = F(theta_A)
  std::array<std::array<Eigen::Vector2d, 3>, 2> sole{};  ///< sole points A, B, C per side (sole_points)
  /// Per side, the lowest sole point's gap to the ground (m) and its rate (m/s, the material
  /// point's vertical velocity; negative descending): what landing_frames() reads. Filled only
  /// with the touchdown rule on (ContactModelOptions::touchdown_fraction > 0).
  std::array<double, 2> lowest_gap_m{}, lowest_gap_rate_mps{}, lowest_velocity_x_mps{};
  std::array<int, 2> lowest_point{};  ///< per side, which sole point is lowest: 0 A, 1 B, 2 C
  /// Per side, the foot is still landing this frame (landing_frames()): none of its points may be
  /// active. Set by the caller of contact_frame (the pipeline), which knows the whole descent.
  std::array<bool, 2> landing{};
  /// The frame is within flight_frames()' window of a flight phase: the solver takes
  /// TrialCalibration::flight_speed_gate_mps. Set by the caller, as `landing` is.
  bool near_flight = false;
};

/// The contact speed gate's rule (kin2grf, not the paper). The pipeline resolves it once per
/// trial (speed_gate_for) into TrialCalibration::speed_gate_mps and, for the frames near a flight
/// phase, TrialCalibration::flight_speed_gate_mps: the only gates the solver reads.
struct SpeedGateRule {
  /// A fixed gate (m/s), used when ratio is 0: a contact point may be active only while its
  /// horizontal speed relative to the ground (or belt) is below it; <= 0 disables the gate (the paper). kin2grf's default: 1.5
  /// (`kin2grf study speed-gate`: walking flat from 0.5 to 3 m/s, running best at 1-1.5 m/s).
  double fixed_mps = 1.5;
  /// The gate relative to the subject's progression speed v (overground: the hip's; treadmill:
  /// the belt's): when > 0 the trial's gate is max(standstill_mps, ratio x v), and near a flight
  /// phase max(floor_mps, ratio x v); fixed_mps is not used. Why: a stance contact point stays
  /// (nearly) still on the ground at any speed, while a swing foot moves at 2-3 v; a fixed
  /// 1.5 m/s lets a 0.4 m/s walker's swing foot (about 1 m/s, 8-12 mm above the floor) take the
  /// load, and cuts a sprinter's landing. See speed_gate_for() and `kin2grf study speed-gate-ratio`.
  /// kin2grf's default 0.7 x v; near a flight at least 0.75 m/s (`kin2grf study
  /// speed-gate-floor`: on these trials it acts on the drop jump alone, which needs it: its
  /// landing feet still move in the 6 Hz kinematics, which spread the impact's stop over
  /// +-40 ms), elsewhere at least standstill_mps.
  /// Chosen leave-one-lab-out, `kin2grf study speed-gate-ratio --cross-validate lab` with the
  /// ratio alone at the default floor (14 trials, 8 labs): 6 labs' held-out choice is 0.7, 2 take
  /// 0.5; held out, walking 6.6 / 7.8 / 6.1 % (vertical / anterior / COP), GRM 5.6 %, at 1 x v
  /// -> 6.3 / 7.9 / 6.3 %, GRM 5.4 %, the mean of the three 6.86 -> 6.83 %; running and the drop
  /// jump unchanged. A small gain; why a lower ratio is physical: a landing foot's heel slows
  /// below v only in its last tens of milliseconds, which the 6 Hz kinematics spread over
  /// +-40 ms, and on the walks the gate is what switches the landing foot on (PiG_Motion3: 56 ms
  /// early at 1 x v, 46 at 0.7, 26 at 0.3; without a gate the gap would switch it on 80 ms
  /// early). The fixed 1.5 m/s before it: a 0.4 m/s walk's swing foot took load, a 3.3 m/s run
  /// did better with 2 m/s; 2 x v let a fast walker's landing foot in 60-90 ms early
  /// (docs/METHOD-NOTES.md). Crossed with the floor, as this study was until then, a held-out
  /// lab whose trials cannot tell the floors apart took the grid's first floor, which cost the
  /// drop jump 1.7 points and hid the gain. Session 23, with no floor above 0.1 m/s away from
  /// flights (standstill_mps), ratios under 0.7 act on the walks too: 0.5 and 0.7 tie on the
  /// criterion, five labs choose 0.7 held out, three 0.5, and held out 0.5 gains nothing.
  double ratio = 0.7;
  /// The lowest gate near a flight phase (m/s): a landing from a jump or a run.
  double floor_mps = 0.75;
  /// The lowest gate elsewhere (m/s), for a walker however slow and for standing (v ~ 0): a foot
  /// at rest seen through the markers' noise and the 6 Hz filter moves at about 0.02 m/s (2 mm
  /// of noise at 60-100 Hz), so 0.1 m/s leaves it 5 x that margin. Until session 23 the floor
  /// held everywhere: a 0.36 m/s walk was gated at 0.75 m/s, twice its speed, and its swing foot,
  /// hovering 7-10 mm up and slower than that for 200 ms, took load 180 ms before it landed (issue
  /// 29). No development walk is slower than 1.07 m/s (0.7 v > 0.75), so on them the two are one.
  double standstill_mps = 0.1;
};

/// The trial's speed gate (m/s) for a progression speed v (m/s): rule.fixed_mps, or with a ratio
/// max(rule.standstill_mps, rule.ratio x |v|), near a flight phase max(rule.floor_mps,
/// rule.ratio x |v|); 0 = no gate.
double speed_gate_for(const SpeedGateRule& rule, double progression_speed_mps, bool near_flight = false);

struct ContactModelOptions {
  FootModel foot_model = FootModel::Cop;
  CopFunction cop;
  /// Model 2's function on running frames (contact_frame's `running`, from flight_frames); none: `cop` everywhere
  /// (the paper, or a user's own function).
  std::optional<CopFunction> running_cop = CopFunction::running();
  double ground_shift_m = 0.0;  ///< added to the measured ground (the paper's robustness study)
  SpeedGateRule speed_gate;     ///< the contact speed gate (resolved per trial: TrialCalibration::speed_gate_mps)
  /// Touchdown (landing_frames, kin2grf, not the paper): a landing foot takes no load before its
  /// final approach's descent speed has fallen to this fraction of its peak; 0 = off. Off by
  /// default: on the development trials it ties (leave-one-lab-out criterion 8.57 % at 1.0
  /// against 8.59 % off; `kin2grf study touchdown-fraction`) although it takes walking onsets
  /// from a worst trial's mean of 59 ms early to 44 (docs/METHOD-NOTES.md).
  double touchdown_fraction = 0.0;
  /// The contact calibration's foot-flat frames are those where the foot is also still, its angle
  /// turning slower than this (rad/s; 0 = every flat frame, the rule before session 33 and
  /// --paper): a landing's foot slap and a heel rise turn it at 1-5 rad/s, a foot flat on the
  /// floor at about 0. The flat frames alone (both landmarks within 15 mm of their floor) admit
  /// the end of the foot slap and the start of the heel rise, whose share depends on how much of
  /// the trial is stance; model 2's COP moves about 13 mm per 0.75 degrees of this reference in
  /// mid-stance (the COP function's steep HO -> MO segment), so a trial cut to its plate stances
  /// moved walking2's COP rRMSE from 6 to 13 % (docs/METHOD-NOTES.md).
  double still_foot_rad_per_s = 0.5;
};

/// World positions of the sole points A, B, C of a foot in one frame (ModelMotion::frame).
std::array<Eigen::Vector2d, 3> sole_points(const ContactCalibration& soles, const MotionFrame& frame, int side);

/// One frame's contact points into `fc` (its vector is reused: no allocation once it has held a
/// frame) and, for model 2, D*'s q, qd, qdd into `frame` (Sect. 2.3: D* is a coordinate of q).
/// `running`: the frame takes options.running_cop. The pipeline makes each frame's contacts when
/// it solves that frame, so no stage holds them for the whole trial (416 bytes a frame).
void contact_frame(const Model& model, const ContactCalibration& soles, const ContactModelOptions& options, bool running,
                   MotionFrame& frame, FrameContacts& fc);

/// Frame i's flag of a per-frame flag vector; an empty (or short) vector: false.
inline bool flag_at(const std::vector<bool>& flags, Eigen::Index i) {
  return static_cast<Eigen::Index>(flags.size()) > i && flags[static_cast<std::size_t>(i)];
}
/// Whether frame i takes the running COP function (`running`: flight_frames' flags; empty, none).
inline bool is_running_frame(const std::vector<bool>& running, Eigen::Index i) { return flag_at(running, i); }

/// The touchdown rule's values (landing_frames).
struct LandingRule {
  double fraction = 1.0;  ///< the foot has landed when its descent speed, past the final peak, is this fraction of it
  double swing_speed_mps = 0.0;  ///< a sole point faster than this along the ground is in swing (the speed gate); 0: always
  /// A descent is a landing when it drops at least this much: more than the settling of a
  /// planted foot's lowest point (a few mm of heel pad and skin), less than a swing foot's
  /// clearance (15-20 mm).
  double min_drop_m = 0.010;
  /// and its final approach reaches at least this descent speed (m/s): the pipeline takes
  /// max(0.1 m/s, 0.1 x the progression speed), above a planted foot's drift (0.08 m/s on a
  /// 1.2 m/s walk), below a heel's approach (0.25-0.9 m/s on the development walks).
  double min_speed_mps = 0.1;
  /// A later peak of the same descent is the final approach only if it reaches this share of the
  /// descent's fastest (a landed foot settling at a few cm/s after a 2 m/s drop is not one).
  double min_peak_share = 0.25;
};

/// The frames in which a foot is still landing (kin2grf, not the paper): none of its points may
/// take load there. Per frame, the foot's lowest sole point: its gap (m), the rate of the gap
/// (m/s, negative descending), its speed along the ground (m/s, relative to a belt) and which
/// point it is (0 A, 1 B, 2 C). A landing is a descent of one sole point (a run of frames moving
/// down; a switch of the lowest point, the forefoot slapping down after a heel strike, begins a
/// new run) of a foot that has been in swing since it last landed, that drops at least
/// rule.min_drop_m; its frames before the final approach's descent speed has fallen to
/// rule.fraction of its peak are landing frames. Why: the gap criterion (Eq. 8) with any r that
/// tolerates a lab's 10 mm ground calibration error let a foot take load while still descending,
/// 20-66 ms before the plates' onsets on 6 of the 9 development walks. The kinematics are
/// low-pass filtered without lag, so a sole that stops at impact comes out decelerating smoothly
/// around that instant: the filtered descent speed peaks before the impact and passes half of its
/// pre-impact value at it (a zero-lag filter's step response is one half at the step). The
/// plates' onsets on the development trials lie between the two (rajagopal-walk: at the peak;
/// PiG_Motion3: at the half). The rule scales with the foot's own descent, not with a height or
/// a fixed speed. rule.fraction <= 0: no landing frames.
std::vector<bool> landing_frames(const Eigen::VectorXd& gap_m, const Eigen::VectorXd& gap_rate_mps, const Eigen::VectorXd& ground_speed_mps,
                                 const std::vector<int>& lowest_point, const LandingRule& rule);

/// Touchdown from the foot's own motion (issue 29; kin2grf, not the paper): the rule of
/// frames_before_touchdown. Off (fraction 0) unless EstimateOptions::touchdown_stop_fraction.
struct TouchdownStopRule {
  double fraction = 0.0;  ///< a landmark has stopped once its descent is this fraction of its recent peak; 0: off
  /// The heel's and MT head's heights are differentiated at this cut-off (at most what the rate
  /// allows): sharp enough that a stop is placed within about +-15 ms (the dynamics' 6 Hz spreads
  /// it over +-40 ms), low enough that 2 mm of marker noise moves a 1 m/s descent by a few cm/s.
  double cutoff_hz = 15.0;
  double window_s = 0.15;        ///< the recent peak is the fastest descent within this before; the stop is looked for this long after activation
  double height_band_m = 0.02;   ///< and only where the landmark is this close to its own floor height (its 10th percentile)
  double min_descent_mps = 0.1;  ///< a recent peak slower than this is no landing (a planted foot settling); a landmark descending faster has not stopped
};

/// The frames, per foot, in which the solve has the foot in contact before it has landed
/// (kin2grf, not the paper). `contact`: the foot's contact state per frame (the solve's);
/// `heel_height_m`, `mt_height_m`: its heel's and MT head's landmark heights (unfiltered). For each
/// contact run that follows a frame without contact, scanned from its first frame for at most
/// rule.window_s: the foot has landed at the first frame where its heel or its MT head lies within
/// rule.height_band_m of its floor height and descends no faster than rule.fraction of its fastest
/// descent over the window before (at least rule.min_descent_mps) and no faster than
/// rule.min_descent_mps itself (a landmark still sinking as fast as the slowest landing approach
/// has not stopped: Plug-in Gait's flat-foot walker's heel brakes from 1.4 to 0.11 m/s 5 mm above
/// its floor and sinks on at 0.11-0.16 m/s for 70 ms before its plate loads; session 34); the
/// run's frames before that are returned. A run in which no landmark lands within the window (no
/// descent: a foot set down slowly, a trial's first stance) returns none, nor does one that begins
/// on a frame of `near_flight` (flight_frames; empty: none): in flight the whole body's kinematics
/// ask for no load until the impact, so a run's or a jump's contact does not begin early (the runs'
/// onsets are 3-10 ms early), and a runner's heel and MT head go on sinking into the shoe and the
/// heel pad for 20-30 ms after it. Why: a zero-lag 6 Hz filter spreads the impact's
/// deceleration over about +-40 ms, so the whole body's kinematics ask for a ground force before
/// the foot arrives and the least squares hands it to the landing foot. On the development walks
/// with raw plate signals the solve's contact began 13-48 ms before the plates' onsets (32 ms mean
/// |onset|), and the heel's own stop, seen at 12-20 Hz, lies within -20..+10 ms of them.
std::vector<bool> frames_before_touchdown(const std::vector<bool>& contact, const Eigen::VectorXd& heel_height_m, const Eigen::VectorXd& mt_height_m,
                                          double rate_hz, const TouchdownStopRule& rule, const std::vector<bool>& near_flight = {});

/// A normal walk's stance, s: up to it the touchdown rule keeps TouchdownStopRule's window and
/// least descent (the development walks' median stances are 0.52-0.71 s).
inline constexpr double kTouchdownNormalStanceS = 0.75;
/// The touchdown rule for a walker whose median stance (the solve's, median_stance_s) is
/// `stance_s`: a slower walker's foot comes down over a longer time and more slowly, so beyond
/// kTouchdownNormalStanceS the window grows and the least descent shrinks by stance / 0.75 s
/// (their product, a descent of about 15 mm, kept). With the fixed window a walker slowed 2.5
/// times lost the rule where the solve's contact began more than 150 ms before the heel stopped
/// or the heel came down slower than 0.1 m/s (the development walks on a clock stretched 2.5 x,
/// markers and plates alike: mean |onset| 67 ms without the rule, 62 with the fixed one, 40 scaled;
/// PiG_Motion3 -120 -> 0 ms). No stance (nullopt): the fixed values.
TouchdownStopRule touchdown_stop_rule(double fraction, std::optional<double> stance_s);

/// The whole body's vertical kinematic force sum per frame, sum m (a_y + g) over the segments
/// (N): what the ground must carry in all (zero in free fall).
Eigen::VectorXd vertical_force_sum_N(const Model& model, const ModelMotion& motion);

/// Running frames: those within `window_s` of a flight frame, where the whole body's vertical
/// kinematic force sum m (a_y + g) is below `flight_fraction` of body weight and no sole point of
/// either foot is within `clearance_m` of the ground. In flight the body is in free fall (0) with
/// both feet up; a run's 6 Hz-filtered flights reach about -0.2 body weight. Walking keeps a foot
/// on the ground: the 7 development walks never go below 0.42, but a 2 m/s walk (UWA
/// Fast_Walking_9) dips to 0.10 at mid single support (its plate: 0.26) with the stance foot flat,
/// which the force sum alone called running. 2 cm: validation's "touches the ground" height.
std::vector<bool> flight_frames(const Model& model, const ModelMotion& motion, const ContactCalibration& soles,
                                double flight_fraction = 0.2, double window_s = 0.4, double clearance_m = 0.02);
/// The same with the frames' vertical force sums already made (vertical_force_sum_N of the same
/// model and motion).
std::vector<bool> flight_frames(const Model& model, const ModelMotion& motion, const ContactCalibration& soles,
                                const Eigen::VectorXd& vertical_sum_N, double flight_fraction = 0.2, double window_s = 0.4,
                                double clearance_m = 0.02);

}  // namespace kin2grf

namespace kin2grf {

/// The contact calibration's still foot: its angle is differentiated at this cut-off (Hz, the
/// dynamics' own).
inline constexpr double kStillFootCutoffHz = 6.0;

/// Contact calibration (Sect. 2.3: "A, B, C at ground level under heel, MT and hallux"):
/// per foot, the foot-flat frames are those where both the heel and the MT landmark are within
/// 15 mm of their 10th-percentile height and, with still_foot_rad_per_s > 0, the foot is still
/// (its angle turning slower than that; all flat frames when fewer than 3 are still); there,
/// theta_foot,flat is the median foot angle and A, B (foot frame) and C (toes frame) are the medians of the points at ground level straight
/// below the heel, MT and hallux landmarks. A foot whose flat frames stand more than 30 mm
/// higher than the other's never touches the floor: it takes the other foot's geometry. When
/// both feet's heel landmarks stay more than 150 mm above the floor, neither foot stands on it:
/// the soles go 40 mm below the heel landmarks (no stance is invented). Its `message` says which.
ContactCalibration calibrate_contact(const SagittalLandmarks& lm, double ground_level_m, double still_foot_rad_per_s = 0.0);

/// The belt velocity of a treadmill trial (m/s), gathered frame by frame: the median horizontal
/// velocity of the contact points within 10 mm of the floor; none when no point comes that close.
struct BeltVelocitySamples {
  std::vector<double> v_mps;
  void add(const FrameContacts& fc);  ///< one frame's points, in frame order
  [[nodiscard]] std::optional<double> median_mps() const;
};

/// The heights a heel or MT-head skin marker's centre stands above the floor at flat foot: at
/// least a marker's radius, at most about 60 mm (24-55 mm on the development trials). The lowest
/// flat-stance foot landmark outside them is reported as a likely marker-floor offset.
inline constexpr double kMinFootMarkerHeightM = 0.008, kMaxFootMarkerHeightM = 0.070;

/// Automatic ground level: 0 (the lab floor, where capture systems put it) when the feet's
/// flat-stance landmarks stand 0-150 mm above it; otherwise the lowest of them (a raised or
/// offset walkway), with a message.
struct GroundLevel {
  double level_m = 0.0;  ///< the floor's height in the sagittal frame
  std::string message;   ///< how it was chosen
};
GroundLevel estimate_ground_level(const SagittalLandmarks& lm);

}  // namespace kin2grf
