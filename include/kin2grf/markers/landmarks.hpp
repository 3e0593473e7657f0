// kin2grf markers: marker sets (presets or a user mapping file) -> the model's 12 landmarks.
//
// A marker set is data (JSON, data/presets/*.json, read by io/marker_presets.hpp outside the core;
// format in docs/MARKERSETS.md): for each landmark a rule, one of
//   {"marker": "RKNE"}                        one marker
//   {"mean": ["RMT1", "RMT2"]}                the mean of several markers
//   {"harrington": {"rasis": .., "lasis": .., "rpsis"|"sacrum": .., "lpsis": ..}}
//       hip: the mean of both hip joint centres by Harrington et al. 2007 (J Biomech 40:595):
//       in the pelvis frame (origin mid-ASIS, x anterior, y superior, z right, mm)
//       x = -0.24 PD - 9.9, y = -0.30 PW - 10.9 (PW ASIS width, PD mid-ASIS to mid-PSIS); the
//       lateral terms cancel in the mean of the two sides.
//   {"static": ["R.Knee.Lat", "R.Knee.Med"], "cluster": ["R.Thigh.Upper", ...]}
//       a virtual landmark: the mean of the static markers, expressed in the cluster's frame in
//       the static trial, carried by the cluster (least-squares rigid fit) in the motion trial.
//   {"functional": {"proximal": ["RTH1", ..], "distal": ["RTB1", ..]}}
//       a joint centre from the motion itself, no static trial (SCoRE, Ehrig et al. 2006, J
//       Biomech 39:2798): the point fixed in both clusters' frames by least squares over the
//       trial; a hinge's place along its axis (which the motion does not tell, and a sagittal model
//       does not need) is taken from the midpoint of the two clusters.
//   {"pelvis_up": 0.50}                       shoulder fallback when a set has no upper-body
//       markers: the given length straight up (lab vertical) from the hip centre: a rigid
//       upright torso (an approximation; the pelvis's tilt and oscillations are not the trunk's).
//   any of the above with "surface": "lateral" (knee, ankle and MT landmarks): the marker is on the
//       skin over the joint's lateral side (Plug-in Gait's KNE, ANK), not the joint centre, or on
//       the 5th metatarsal head, not the foot's midline. The sagittal model takes it as it is (its
//       projection is the same); the 3D joint moments move a knee or ankle medially by half the
//       joint's width plus the marker's radius (dynamics/joint_moments_3d.hpp), the COP's lateral
//       line moves its forefoot end medially by kLateralMtToMidline of the heel-MT length.
//       For the COP function's heel-to-MT-heads length (CopLength::HeelMt) the 2nd head lies
//       kLateralMtToeExtraShare of the ankle-MT length ahead of a 5th-metatarsal marker
//       (SagittalLandmarks::mt_head_ahead_share).
//   {"virtual_hallux": 0.30}                  hallux fallback: a toes segment of that fraction of
//       the ankle-MT length, straight along the foot in swing, held at the MT head's foot-flat
//       height while the heel rises (the toes stay on the ground at push-off); from a
//       5th-metatarsal marker kLateralMtToeExtraShare longer (its head lies behind the 2nd's).
// A marker's longer gap inside the trial is first filled from three markers that move rigidly
// with it (fill_marker_gaps_rigidly, below). Gaps of up to max_gap_frames are filled by cubic
// (Catmull-Rom) interpolation between the neighbouring valid samples; longer gaps left end the
// processed window (the longest run of frames where every landmark is defined), with a message
// naming the marker and frames.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "kin2grf/trial.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/model/model.hpp"

namespace kin2grf {

/// How a landmark is made from markers (the mapping file's rule names: rule_kind_name).
enum class RuleKind { Marker, Mean, Harrington, Static, Functional, PelvisUp, VirtualHallux };
/// The mapping file's name of a rule kind ("marker", "mean", "harrington", "static", "functional",
/// "pelvis_up", "virtual_hallux").
const char* rule_kind_name(RuleKind kind);
/// The landmark follows the bone: a marker, or the mean of markers, placed on the skin over it
/// (an epicondyle, a malleolus) or a joint centre made of such markers. Not a point a cluster
/// carries (static calibration, a functional centre): a cluster rides on a segment's skin and
/// soft tissue, which move late against the bone (EstimateOptions::thigh_lag_s).
constexpr bool follows_the_bone(RuleKind kind) { return kind == RuleKind::Marker || kind == RuleKind::Mean; }

struct LandmarkRule {
  RuleKind kind = RuleKind::Marker;
  std::vector<std::string> markers;  ///< marker / mean / static markers; functional: the distal cluster; pelvis_up without pelvis: hip centres
  std::vector<std::string> cluster;  ///< static: tracking cluster; functional: the proximal cluster
  std::map<std::string, std::string> pelvis;  ///< harrington / pelvis_up: rasis, lasis, rpsis, lpsis | sacrum
  double value = 0.0;                ///< pelvis_up length (m), virtual_hallux fraction
  /// pelvis_up: the shoulder point's horizontal sway as a fraction of the hip centre's (see
  /// kTrunkSwayGain); 1 keeps the torso rigidly upright.
  double sway_gain = 0.0;
  /// "surface": "lateral": a knee or ankle marker on the joint's lateral skin (see above).
  bool lateral_surface = false;
};

/// The horizontal acceleration of the shoulder point (acromia) as a fraction of the hip
/// centre's, in walking: measured on the 6 development walking trials with trunk markers
/// (5 labs), 0.28-0.67, mean 0.48 (docs/METHOD-NOTES.md, "torso without trunk markers"). A rigid
/// upright torso (gain 1) gives the heavy HAT segment the pelvis's whole fore-aft oscillation,
/// which over-brakes the body at heel strike and moves load to the leading foot too early.
inline constexpr double kTrunkSwayGain = 0.5;
/// The same fraction in running: 0.04 on the one development run with trunk markers (Rajagopal's
/// treadmill run, 3.9 m/s; least squares of the shoulder point's fore-aft acceleration on the hip
/// centre's, both at 6 Hz), against 0.26-0.63 on the 8 walks with them (docs/METHOD-NOTES.md). A
/// runner's pelvis oscillates fore-aft at 2.6-3 steps a second, a walker's at 1.6-2.3, and the
/// trunk's mass on its compliant spine follows the faster oscillation less; why it follows it
/// hardly at all was not measured apart. Measured, not fitted to any outcome; the pipeline gives it
/// to a model torso in a trial with flight phases (EstimateOptions::running_sway_gain).
inline constexpr double kTrunkSwayGainRunning = 0.05;
/// Toes (sagittal_landmarks): the presets' virtual toes are 0.3 x the ankle-MT length (the hallux
/// tip about a third of that ahead of the MT head); a toe marker nearer the MT head than half
/// of it is not on the toe and is replaced by them, with a message.
inline constexpr double kVirtualToeShare = 0.3, kMinToeShare = 0.15;
/// Virtual toes grown from a 5th-metatarsal marker ("surface": "lateral") are longer by this
/// share of the ankle-MT length: the 5th metatarsal head lies behind the 2nd's, the metatarsal
/// break running about 60-70 degrees to the foot's long axis (Isman and Inman 1969) across the
/// 55-65 mm from the 2nd head to the 5th, about 30 mm, 0.2 of an adult's 140-150 mm ankle-MT5
/// length. Anatomy, not fitted; measured in study toe-ablation (docs/METHOD-NOTES.md).
inline constexpr double kLateralMtToeExtraShare = 0.2;
/// A 5th-metatarsal head marker's distance (lateral skin, marker centre) to the foot's midline
/// (the 2nd metatarsal head) as a fraction of the heel-MT5 length: about 45 mm on an adult's
/// 180 mm (the MT1-MT5 heads' breadth is about 0.4 of the foot's length, the 2nd head a quarter
/// of it from the 1st, plus the soft tissue and the marker's radius). Anatomy, not fitted.
inline constexpr double kLateralMtToMidline = 0.25;

/// The upper body's landmarks for the arms and the head as segments of their own (the 3D model's
/// lateral force; the sagittal model keeps them in its HAT): a marker set's optional
/// "upper_body" object names each one's markers (their mean).
enum UpperBodyLandmark : int { kShoulderR = 0, kElbowR, kWristR, kShoulderL, kElbowL, kWristL, kHead, kUpperBodyCount };
/// "shoulder_r", "elbow_r", "wrist_r", "shoulder_l", "elbow_l", "wrist_l", "head".
const char* upper_body_name(int id);

struct MarkerSet {
  std::string name;
  std::string description;
  std::vector<std::string> signature;  ///< markers whose presence recognises the set
  std::array<LandmarkRule, kLandmarkCount> rules;
  /// Per UpperBodyLandmark, the markers whose mean it is; empty: none in this set.
  std::array<std::vector<std::string>, kUpperBodyCount> upper_body;
  bool preset = false;  ///< one of kin2grf's built-in presets (not a user's mapping file)
  /// Every marker a motion trial must have.
  [[nodiscard]] std::vector<std::string> motion_markers() const;
};

/// The set as if the trial had no trunk or arm markers (an ablation: how much the estimate owes
/// to them): the shoulder point becomes the model torso above the pelvis (pelvis_up, swaying by
/// kTrunkSwayGain), above the hip centre of the hip's rule (its pelvis markers, or the mean of
/// its hip-centre markers), and the arms and head are lumped (no upper_body). None when the hip
/// centre is made otherwise (`why` says so); a set without trunk markers already is returned as it
/// is, without upper_body.
std::optional<MarkerSet> without_trunk_markers(const MarkerSet& set, std::string& why);

/// The model torso's fore-aft sway (a pelvis_up shoulder rule): the shoulder point's fore-aft
/// coordinate moves by (to_gain - from_gain) times the hip centre's fore-aft oscillation, the hip's
/// position less its own 0.5 Hz zero-lag trend (below the step frequency, so that the torso's mean
/// lean and the progression are untouched). sagittal_landmarks applies the set's sway_gain (from 1,
/// the rigidly upright torso); the pipeline changes it to the runner's (kTrunkSwayGainRunning) in a
/// trial with flight phases. The vertical is the hip's (a gain of 0.97-1.03 on trunk markers).
void sway_model_torso(SagittalLandmarks& lm, double from_gain, double to_gain);

/// A landmark's name in marker-set files ("shoulder", "hip", "knee_r", ...).
const char* landmark_name(int id);

/// A preset's marker that the file holds more than once (the readers name the k-th NAME#k; a
/// Helen-Hayes file with medial and lateral markers under one label): the lateral occurrence, the
/// one farther from the body's centre line in the horizontal plane, is taken, and `messages` says
/// which. The set with those names, or nothing when no marker it uses is repeated. A mapping file
/// names the occurrence itself (NAME#1, NAME#2).
std::optional<MarkerSet> choose_repeated_markers(const MarkerSet& set, const MarkerTrajectories& m, std::vector<std::string>& messages);

struct LandmarkOptions {
  int max_gap_frames = 10;
  /// Longer gaps inside a marker's trajectory filled from the markers that move rigidly with it
  /// (fill_marker_gaps_rigidly); false: they end the processed window.
  bool rigid_fill = true;
  std::optional<Axis> up_axis;      ///< default: the file's
  std::optional<int> progression_sign;  ///< +1/-1 along the detected axis; default: detected
  std::optional<Axis> progression_axis;
  /// Make the upper-body landmarks too (MarkerSet::upper_body): the 3D model's lateral force.
  bool upper_body = false;
};

/// 3D landmarks in the lab frame, N x 3 each, NaN where undefined.
struct Landmarks3D {
  std::array<Eigen::MatrixX3d, kLandmarkCount> p;
  /// With LandmarkOptions::upper_body, per UpperBodyLandmark whose markers are all in the file;
  /// empty otherwise.
  std::array<Eigen::MatrixX3d, kUpperBodyCount> upper_body;
  std::vector<std::string> messages;
  /// Half the distance between the two hip joint centres (m), where the hip rule makes them (the
  /// mean of two hip-centre markers, or Harrington's, whose lateral term is 0.33 PW + 7.3 mm); the
  /// median over the frames. The 3D model's hips (dynamics/joint_moments_3d.hpp).
  std::optional<double> hip_half_width_m;
};

/// The sagittal frame: x along progression, y up, origin the lab origin.
///
/// A walker who turns (a circuit, a curved path) has no one progression direction: the frame then
/// follows the heading. Per trial frame i, heading f_i (the direction of the pelvis's slow path, a
/// 0.5 Hz trend below the step frequency) and x = p . f_i + x_offset_i, where the offset makes
/// the path's own x its arc length: x measures the distance walked along the path, so
/// velocities and accelerations along it are those of the 2D model (the centripetal part, across
/// the plane, is left out, as a sagittal model must). Without turns both per-frame arrays are
/// empty and the fixed `forward` holds for every frame (bit for bit the straight-line frame).
struct SagittalFrame {
  Eigen::Vector3d forward = Eigen::Vector3d::UnitX();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d lateral = Eigen::Vector3d::UnitY();  ///< forward x up (to the right)
  bool treadmill = false;           ///< the pelvis does not progress (belt velocity: TrialCalibration)
  std::string how;                  ///< how progression was found
  Eigen::MatrixX3d heading;         ///< N x 3 per trial frame (turning only), lab unit vectors
  Eigen::VectorXd x_offset_m;       ///< N (turning only)
  [[nodiscard]] bool turning() const { return heading.rows() > 0; }
  [[nodiscard]] Eigen::Vector3d forward_at(Eigen::Index i) const {
    return turning() ? Eigen::Vector3d(heading.row(std::clamp<Eigen::Index>(i, 0, heading.rows() - 1)).transpose()) : forward;
  }
  [[nodiscard]] Eigen::Vector3d lateral_at(Eigen::Index i) const { return turning() ? forward_at(i).cross(up) : lateral; }
  [[nodiscard]] double x_offset_at(Eigen::Index i) const {
    return turning() ? x_offset_m[std::clamp<Eigen::Index>(i, 0, x_offset_m.size() - 1)] : 0.0;
  }
  [[nodiscard]] Eigen::Vector2d to_sagittal(const Eigen::Vector3d& p) const { return {p.dot(forward), p.dot(up)}; }
  /// At trial frame i (the frame the point was seen in).
  [[nodiscard]] Eigen::Vector2d to_sagittal(const Eigen::Vector3d& p, Eigen::Index i) const {
    return turning() ? Eigen::Vector2d(p.dot(forward_at(i)) + x_offset_at(i), p.dot(up)) : to_sagittal(p);
  }
  /// The lab point at sagittal (x, y) and lateral coordinate l, trial frame i.
  [[nodiscard]] Eigen::Vector3d to_lab(double x, double y, double l, Eigen::Index i) const {
    return (x - x_offset_at(i)) * forward_at(i) + y * up + l * lateral_at(i);
  }
};

/// Marker samples no body can produce become gaps (filled later like any gap, up to the longest
/// gap filled), each with a message naming the marker and frame:
///  - a coordinate beyond kMaxLabCoordinateM (no capture volume is 10 km; 1e300 would overflow);
///  - a one-frame spike: a sample farther than kMaxMarkerSpeedMps x dt + 2 cm from both neighbours
///    while the neighbours are within that of each other (a marker does not leave and come back in
///    two frames faster than a thrown ball);
///  - a one-frame excursion from the neighbours' midpoint of more than kMaxMarkerAccelMps2 x dt^2 / 2
///    and 2 cm: 100 g, beyond a skin marker's heel-strike transient (tens of g); two markers swapped
///    for one frame (5 cm at 100 Hz).
/// `only`: the markers to check (a set's motion_markers()); empty: all. Returns the cleaned copy,
/// or nothing (and no copy) when every sample is usable.
inline constexpr double kMaxLabCoordinateM = 1e4, kMaxMarkerSpeedMps = 30.0, kMaxMarkerAccelMps2 = 1000.0;
std::optional<MarkerTrajectories> without_marker_outliers(const MarkerTrajectories& markers, const std::vector<std::string>& only,
                                                          std::vector<std::string>& messages);
/// The same, in place (no copy: for a caller that has given the trial up). Returns the number of
/// samples turned into gaps.
std::size_t remove_marker_outliers(MarkerTrajectories& markers, const std::vector<std::string>& only,
                                   std::vector<std::string>& messages);

/// A marker's gap longer than the landmarks' cubic fill reaches (LandmarkOptions::max_gap_frames),
/// inside its trajectory (seen on the frames just before and just after it), filled from three
/// markers that move rigidly with it: a skin or cluster marker occluded for a few tenths of a
/// second (a heel marker hidden by the other foot at a plate, a pelvis marker by the arm) would
/// otherwise end the processed window there, and half a trial's stances with it.
/// Candidates: the labelled markers seen on every frame from the one before the gap to the one
/// after it whose distance to the marker varies by at most kMaxRigidPartnerSdM (SD over the
/// frames both are seen, at least kMinRigidFrames; markers on one segment move against each other
/// by the skin's few mm, across a joint by centimetres), the kMaxRigidCandidates least varying.
/// Unlabelled trajectories (Vicon's "*12") are none: they are not known to be one marker.
/// Partners: of the candidate triples that keep their distances to each other within the same SD
/// (one body: a marker on a joint's axis keeps its distance to both segments' markers) and span a
/// triangle at the frame before the gap whose every height is at least kMinRigidPartnerSpanM (a
/// narrow triangle's rotation about its long side is its markers' few mm of noise and skin motion
/// over its height, and a marker 8 cm off that side moves by as much times 8 cm over the height:
/// at 2 cm subject01's medial toe marker, filled from the lateral border's heel, midfoot and toe,
/// was 96 mm off), the one whose largest SD of its six distances is least: the most rigid body.
/// Fill: at each frame of the gap, the partners' rigid motion from the frame before the gap
/// (least squares, as a cluster's pose) carries the marker's position there, and likewise from
/// the frame after; the two are blended linearly in time, so that the fill meets the data at both
/// ends. A gap at the trial's start or end (no data on one side: the subject entering or leaving
/// the volume) is not filled, nor a gap whose partners are not found: the processed window then
/// ends there, and its message names the frames. `only`: the markers to fill (a set's
/// motion_markers()). Each fill is named in `messages` with its partners. Returns the number of
/// gaps filled.
inline constexpr double kMaxRigidPartnerSdM = 0.008, kMinRigidPartnerSpanM = 0.03;
inline constexpr Eigen::Index kMinRigidFrames = 20;
inline constexpr std::size_t kMaxRigidCandidates = 12;
std::size_t fill_marker_gaps_rigidly(MarkerTrajectories& markers, const std::vector<std::string>& only, int longer_than_frames,
                                     std::vector<std::string>& messages);
/// fill_marker_gaps_rigidly in its two steps, for a caller that copies the markers only when
/// there is a fill to write: the fills made from `markers` as given (each named in `messages`),
/// then written.
struct RigidGapFill {
  std::size_t marker = 0;
  Eigen::Index first = 0;         ///< the gap's first frame
  Eigen::MatrixX3d positions_m;   ///< the gap's frames
};
std::vector<RigidGapFill> rigid_gap_fills(const MarkerTrajectories& markers, const std::vector<std::string>& only,
                                          int longer_than_frames, std::vector<std::string>& messages);
void write_gap_fills(MarkerTrajectories& markers, const std::vector<RigidGapFill>& fills);
/// Whether fill_marker_gaps_rigidly has a gap to look at (one of `only`'s interior gaps is longer
/// than `longer_than_frames`).
bool has_long_marker_gap(const MarkerTrajectories& markers, const std::vector<std::string>& only, int longer_than_frames);

/// `release`: `motion` itself, when the caller has no further use for its samples: each
/// marker's samples are released (left 0 x 3) after the last landmark that reads them, and those
/// of markers no landmark reads at once, so that a long trial's markers and landmarks are not
/// held whole together (the memory of long trials). The names, times and rate stay.
Landmarks3D compute_landmarks(const MarkerSet& set, const MarkerTrajectories& motion,
                              const MarkerTrajectories* static_trial, const LandmarkOptions& options,
                              const std::string& path,
                              MarkerTrajectories* release = nullptr);

SagittalFrame detect_sagittal_frame(const Landmarks3D& lm, const MarkerTrajectories& motion,
                                    const LandmarkOptions& options);

struct SagittalWindow {
  SagittalLandmarks landmarks;  ///< only the processed window
  Eigen::Index first = 0;       ///< index of its first frame in the trial
  std::array<Eigen::VectorXd, 2> foot_lateral_m;  ///< per side: lateral coordinate of the foot (heel-MT midpoint)
  std::optional<double> hip_half_width_m;          ///< Landmarks3D's
  /// When asked (keep_lateral), per side, N x 4: the line the COP's lateral place follows along
  /// the foot, (heel x, heel lateral, forefoot x, forefoot lateral) in the sagittal frame, m; the
  /// forefoot end on the foot's midline (a 5th-metatarsal marker moved by kLateralMtToMidline).
  std::array<Eigen::MatrixX4d, 2> foot_line;
  /// When asked (the mediolateral force): every landmark's lab position (m), N x 3 each, with the
  /// virtual hallux at the MT head, and each frame's lateral axis (SagittalFrame::lateral_at),
  /// N x 3. Empty otherwise.
  std::array<Eigen::MatrixX3d, kLandmarkCount> lab_m;
  Eigen::MatrixX3d lateral_axis;
  /// When asked (sagittal_landmarks' lab_sums): each weighted sum of the landmarks' lab positions,
  /// N x 3, m.
  std::vector<Eigen::MatrixX3d> lab_sums_m;
  /// Likewise the upper-body landmarks (lab, m) defined on every frame of the window (short gaps
  /// filled); empty where not (the part is then lumped into the HAT, and `messages` says so).
  std::array<Eigen::MatrixX3d, kUpperBodyCount> upper_body_lab_m;
  std::vector<std::string> messages;
};

/// Gap filling, the longest fully defined window, projection on the sagittal plane, and the
/// virtual hallux when the set has none. `lm` is taken (gaps are filled in it): moved in, it is
/// not copied. Of `m` only the frame count, numbers, times and rate are read. `keep_lateral`: the
/// lab positions, lateral axes and the COP's lateral lines (SagittalWindow::lab_m, lateral_axis,
/// foot_line; the lateral model's). `lab_sums`: each a weight per landmark, of which
/// SagittalWindow::lab_sums_m holds the weighted sum of the landmarks' lab positions (the whole
/// body's centre of mass, made without holding every landmark's lab position), with the lateral
/// axes and the upper body's lab positions beside it (a virtual hallux counts at its MT head).
SagittalWindow sagittal_landmarks(Landmarks3D lm, const MarkerSet& set, const SagittalFrame& frame,
                                  const MarkerTrajectories& motion, const LandmarkOptions& options,
                                  const std::string& path, bool keep_lateral = false,
                                  const std::vector<std::array<double, kLandmarkCount>>& lab_sums = {});

}  // namespace kin2grf
