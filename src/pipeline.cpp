#include "kin2grf/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <memory>
#include <tuple>

#include "kin2grf/dynamics/mediolateral.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/parallel.hpp"

namespace kin2grf {

double progression_speed(const SagittalLandmarks& lm) {
  const Eigen::Index n = lm.frames();
  if (n < 3 || lm.rate_hz <= 0) return 0.0;
  const Eigen::Index h = std::max<Eigen::Index>(1, std::min<Eigen::Index>(static_cast<Eigen::Index>(0.25 * lm.rate_hz), (n - 1) / 2));
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(n));
  const auto& hip = lm.p[kHip];
  for (Eigen::Index i = h; i + h < n; ++i) v.push_back(std::abs(hip(i + h, 0) - hip(i - h, 0)) * lm.rate_hz / static_cast<double>(2 * h));
  return v.empty() ? 0.0 : median(v);
}

namespace {
/// One foot's runs of contact, a flicker inside a stance (under 20 ms) bridged.
std::vector<IndexRun> stance_runs(const std::vector<bool>& c, double rate_hz) {
  const auto bridge = static_cast<Eigen::Index>(0.02 * rate_hz);
  return merge_close_runs(runs_where(static_cast<Eigen::Index>(c.size()), [&](Eigen::Index i) { return c[static_cast<std::size_t>(i)]; }),
                          bridge);
}
}  // namespace

std::vector<IndexRun> gait_stances(const std::vector<bool>& c, double rate_hz) {
  std::vector<IndexRun> out;
  if (!(rate_hz > 0)) return out;
  for (const IndexRun& run : stance_runs(c, rate_hz))
    if (static_cast<double>(run.last - run.first + 1) >= 0.05 * rate_hz) out.push_back(run);  // no stance is that short
  return out;
}

std::optional<double> median_stance_s(const std::array<std::vector<bool>, 2>& contact, double rate_hz) {
  if (!(rate_hz > 0)) return std::nullopt;
  std::vector<double> durations;
  for (const auto& c : contact) {
    const auto n = static_cast<Eigen::Index>(c.size());
    for (const IndexRun& run : gait_stances(c, rate_hz))
      if (run.first > 0 && run.last < n - 1) durations.push_back(static_cast<double>(run.last - run.first + 1) / rate_hz);
  }
  if (durations.empty()) return std::nullopt;
  return median(durations);
}

std::vector<GaitEvent> gait_events(const std::array<std::vector<bool>, 2>& contact, const Eigen::VectorXd& time_s, double rate_hz) {
  std::vector<GaitEvent> out;
  if (!(rate_hz > 0)) return out;
  for (int side = 0; side < 2; ++side) {
    const auto& c = contact[static_cast<std::size_t>(side)];
    const auto n = static_cast<Eigen::Index>(std::min<std::size_t>(c.size(), static_cast<std::size_t>(time_s.size())));
    for (const IndexRun& run : gait_stances(c, rate_hz)) {
      if (run.first > 0 && run.first < n) out.push_back({"Foot Strike", side, run.first, time_s[run.first]});
      if (run.last + 1 < n) out.push_back({"Foot Off", side, run.last + 1, time_s[run.last + 1]});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const GaitEvent& a, const GaitEvent& b) {
    return a.index != b.index ? a.index < b.index : a.side < b.side;
  });
  return out;
}

std::vector<DoubleSupport> walking_double_supports(const std::array<std::vector<bool>, 2>& contact, Eigen::Index max_frames) {
  std::vector<DoubleSupport> out;
  const auto n = static_cast<Eigen::Index>(std::min(contact[0].size(), contact[1].size()));
  const auto on = [&](int side, Eigen::Index i) { return static_cast<bool>(contact[static_cast<std::size_t>(side)][static_cast<std::size_t>(i)]); };
  for (const IndexRun& run : runs_where(n, [&](Eigen::Index i) { return on(0, i) && on(1, i); })) {
    if (run.first == 0 || run.last == n - 1 || run.last - run.first + 1 > max_frames) continue;
    for (int t = 0; t < 2; ++t)
      if (on(t, run.first - 1) && !on(1 - t, run.first - 1) && !on(t, run.last + 1) && on(1 - t, run.last + 1))
        out.push_back({run.first, run.last, t});
  }
  return out;
}

namespace {

std::string format_number(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

void require(bool ok, const std::string& setting, double value, const std::string& allowed) {
  if (ok) return;
  char b[64];
  std::snprintf(b, sizeof b, "%g", value);
  throw InputError("setting " + setting + " = " + b + ": must be " + allowed);
}

}  // namespace

void check_options(const EstimateOptions& o) {
  const auto finite = [](double x) { return std::isfinite(x); };
  require(finite(o.kinematic_cutoff_hz) && o.kinematic_cutoff_hz > 0, "kinematic cut-off (Hz)", o.kinematic_cutoff_hz,
          "a number above 0 (paper: 6)");
  require(finite(o.post_cutoff_hz) && o.post_cutoff_hz >= 0, "post-filter cut-off (Hz)", o.post_cutoff_hz,
          "0 (no post-filter) or a number above 0 (paper: 12)");
  require(finite(o.post_cutoff_cycles) && o.post_cutoff_cycles >= 0 && o.post_cutoff_cycles <= 50, "post-filter cycles per stance",
          o.post_cutoff_cycles, "between 0 (the fixed post-filter cut-off) and 50 (kin2grf: 4)");
  require(finite(o.post_cutoff_floor_ratio) && o.post_cutoff_floor_ratio >= 0 && o.post_cutoff_floor_ratio <= 10,
          "post-filter floor (x the kinematic cut-off)", o.post_cutoff_floor_ratio, "between 0 (none) and 10");
  require(finite(o.min_kinematic_cycles) && o.min_kinematic_cycles >= 0 && o.min_kinematic_cycles <= 20, "kinematic cycles per stance",
          o.min_kinematic_cycles, "between 0 (no floor) and 20 (kin2grf: 3.0)");
  require(finite(o.kinematic_edge_span_periods) && o.kinematic_edge_span_periods > 0 && o.kinematic_edge_span_periods <= 5,
          "the kinematics' edge span (cut-off periods)", o.kinematic_edge_span_periods, "above 0 and at most 5 (kin2grf: 0.5)");
  require(finite(o.solver.r_N_per_m) && o.solver.r_N_per_m > 0, "activation parameter r (N/m)", o.solver.r_N_per_m,
          "a number above 0 (kin2grf: 1000, paper: 10000)");
  require(finite(o.contact.ground_shift_m) && std::abs(o.contact.ground_shift_m) <= 1.0, "ground shift (m)", o.contact.ground_shift_m,
          "between -1 and 1");
  if (o.ground_level_m)
    require(finite(*o.ground_level_m) && std::abs(*o.ground_level_m) <= 10.0, "ground level (m)", *o.ground_level_m, "between -10 and 10");
  require(o.landmarks.max_gap_frames >= 0 && o.landmarks.max_gap_frames <= 100000, "longest gap filled (frames)",
          o.landmarks.max_gap_frames, "between 0 and 100000");
  require(finite(o.contact.speed_gate.fixed_mps) && o.contact.speed_gate.fixed_mps >= 0 && o.contact.speed_gate.fixed_mps <= 20, "speed gate (m/s)",
          o.contact.speed_gate.fixed_mps, "between 0 (none) and 20");
  require(finite(o.contact.speed_gate.ratio) && o.contact.speed_gate.ratio >= 0 && o.contact.speed_gate.ratio <= 20,
          "speed gate ratio", o.contact.speed_gate.ratio, "between 0 (a fixed gate) and 20");
  require(finite(o.contact.speed_gate.floor_mps) && o.contact.speed_gate.floor_mps >= 0 && o.contact.speed_gate.floor_mps <= 20,
          "speed gate floor (m/s)", o.contact.speed_gate.floor_mps, "between 0 and 20");
  require(finite(o.contact.speed_gate.standstill_mps) && o.contact.speed_gate.standstill_mps >= 0 &&
              o.contact.speed_gate.standstill_mps <= 20,
          "speed gate at standstill (m/s)", o.contact.speed_gate.standstill_mps, "between 0 and 20");
  require(finite(o.solver.min_split_distance_m) && o.solver.min_split_distance_m >= 0 && o.solver.min_split_distance_m <= 1,
          "split distance (m)", o.solver.min_split_distance_m, "between 0 (none) and 1");
  require(finite(o.time_scale_leg_m) && o.time_scale_leg_m >= 0 && o.time_scale_leg_m <= 3, "time scale's leg (m)",
          o.time_scale_leg_m, "between 0 (the settings as given) and 3");
  require(finite(o.time_scale_short_leg_m) && o.time_scale_short_leg_m >= 0 && o.time_scale_short_leg_m <= 3,
          "time scale's shortest unscaled leg (m)", o.time_scale_short_leg_m, "between 0 (none) and 3");
  require(finite(o.time_scale_long_leg_m) && o.time_scale_long_leg_m >= 0 && o.time_scale_long_leg_m <= 3,
          "time scale's longest unscaled leg (m)", o.time_scale_long_leg_m, "between 0 (none) and 3");
  if (o.time_scale_short_leg_m > 0 && o.time_scale_long_leg_m > 0 && o.time_scale_short_leg_m > o.time_scale_long_leg_m) {
    char b[200];
    std::snprintf(b, sizeof b, "time scale: the shortest unscaled leg (%.3g m, --time-scale-short-leg) is longer than the longest (%.3g m, "
                  "--time-scale-long-leg)", o.time_scale_short_leg_m, o.time_scale_long_leg_m);
    throw InputError(b);
  }
  require(finite(o.torque_length_legs) && o.torque_length_legs >= 0 && o.torque_length_legs <= 10, "torque length (leg lengths)",
          o.torque_length_legs, "between 0 (the fixed lever) and 10");
  require(finite(o.torso_lag_s) && o.torso_lag_s >= 0 && o.torso_lag_s <= 0.2, "torso lag (s)", o.torso_lag_s,
          "between 0 (none, the paper) and 0.2");
  require(finite(o.thigh_lag_s) && o.thigh_lag_s >= 0 && o.thigh_lag_s <= 0.2, "thigh lag (s)", o.thigh_lag_s,
          "between 0 (none, the paper) and 0.2");
  require(finite(o.torso_vertical_cutoff_hz) && o.torso_vertical_cutoff_hz >= 0 && o.torso_vertical_cutoff_hz <= 100,
          "torso vertical cut-off (Hz)", o.torso_vertical_cutoff_hz, "between 0 (none, the paper) and 100");
  require(finite(o.running_sway_gain) && o.running_sway_gain >= 0 && o.running_sway_gain <= 1.5, "running torso sway gain",
          o.running_sway_gain, "between 0 (the shoulders still) and 1.5");
  require(finite(o.double_support_sta_weight) && o.double_support_sta_weight >= 0 && o.double_support_sta_weight <= 1,
          "double-support transition weight", o.double_support_sta_weight, "between 0 (none, the paper) and 1");
  require(finite(o.double_support_angle) && o.double_support_angle >= 0 && o.double_support_angle <= 1,
          "double-support force angle share", o.double_support_angle, "between 0 (none, the paper) and 1");
  require(finite(o.frontal_split_weight) && o.frontal_split_weight >= 0 && o.frontal_split_weight <= 1,
          "frontal split weight", o.frontal_split_weight, "between 0 (off, the paper) and 1");
  require(finite(o.contact.still_foot_rad_per_s) && o.contact.still_foot_rad_per_s >= 0 && o.contact.still_foot_rad_per_s <= 10,
          "still foot rate", o.contact.still_foot_rad_per_s, "between 0 (off, the paper) and 10 rad/s");
  require(finite(o.touchdown_stop_fraction) && o.touchdown_stop_fraction >= 0 && o.touchdown_stop_fraction <= 1,
          "touchdown stop fraction", o.touchdown_stop_fraction, "between 0 (off, the paper) and 1");
  require(finite(o.toe_medial_slope) && std::abs(o.toe_medial_slope) <= 2, "toe medial slope", o.toe_medial_slope, "between -2 and 2");
  require(o.grm_reference_m.allFinite(), "GRM reference (m)", o.grm_reference_m.x() + o.grm_reference_m.y(), "finite");
  if (o.mass_kg)
    require(finite(*o.mass_kg) && *o.mass_kg > 0 && (o.allow_unusual_mass || (*o.mass_kg >= kMassRangeKg[0] && *o.mass_kg <= kMassRangeKg[1])),
            "body mass (kg)", *o.mass_kg, "between 20 and 300 (--force-mass takes an unusual one)");
}

namespace {

/// The body mass: the user's, else the file's (checked against kMassRangeKg unless allowed).
double resolve_mass(const Trial& trial, const EstimateOptions& o) {
  if (o.mass_kg) return *o.mass_kg;  // checked by check_options
  if (!trial.body_mass_kg)
    throw InputError(trial.path + ": no body mass: the file stores none (PROCESSING:Bodymass, SUBJECT(S):WEIGHT); give the mass (--mass KG)");
  const double m = *trial.body_mass_kg;
  if (!o.allow_unusual_mass && !(m >= kMassRangeKg[0] && m <= kMassRangeKg[1])) {
    char b[200];
    std::snprintf(b, sizeof b, ": the file's body mass %g kg is outside 20-300 kg; give the mass (--mass KG), or --force-mass to take it", m);
    throw InputError(trial.path + b);
  }
  return m;
}

using Messages = std::vector<std::string>;

void append(Messages& to, Messages&& from) {
  to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
}

/// The lateral force's and the frontal balance's cut-off: EstimateOptions::lateral_cutoff_hz, at
/// most `kinematic_cutoff_hz` (0: the kinematic one).
double lateral_cutoff(const EstimateOptions& o, double kinematic_cutoff_hz) {
  return o.lateral_cutoff_hz > 0 ? std::min(o.lateral_cutoff_hz, kinematic_cutoff_hz) : kinematic_cutoff_hz;
}

/// The options as this subject's, from its leg length: the torque-scaled norm's lever
/// (EstimateOptions::torque_length_legs) and the settings in seconds and hertz scaled by
/// sqrt(leg / the reference leg), its gait's time scale at the same Froude number, said in
/// `messages`: the reference is EstimateOptions::time_scale_leg_m when given, else the nearer end
/// of the development range (time_scale_short_leg_m, time_scale_long_leg_m) for a leg outside it;
/// none within it. Everything after the model reads these.
EstimateOptions options_for_subject(const EstimateOptions& o, const Model& model, double rate_hz, Messages& messages) {
  EstimateOptions s = o;
  const double leg = leg_length_m(model);
  if (o.torque_length_legs > 0) s.solver.torque_length_m = o.torque_length_legs * leg;
  double reference = 0;
  const char* against = "against the settings' %.3f m";
  if (o.time_scale_leg_m > 0) reference = o.time_scale_leg_m;
  else if (o.time_scale_short_leg_m > 0 && leg < o.time_scale_short_leg_m)
    reference = o.time_scale_short_leg_m, against = "shorter than the shortest leg the settings were chosen for (%.3f m)";
  else if (o.time_scale_long_leg_m > 0 && leg > o.time_scale_long_leg_m)
    reference = o.time_scale_long_leg_m, against = "longer than the longest leg the settings were chosen for (%.3f m)";
  if (!(reference > 0) || !std::isfinite(leg) || !(leg > 0)) return s;
  const double f = std::sqrt(leg / reference);
  // A raised cut-off stays below what a zero-lag filter at this marker rate takes.
  const double limit = 0.95 * max_zero_lag_cutoff_hz(rate_hz);
  s.kinematic_cutoff_hz = std::min(s.kinematic_cutoff_hz / f, std::max(limit, o.kinematic_cutoff_hz));
  s.post_cutoff_hz = std::min(s.post_cutoff_hz / f, std::max(limit, o.post_cutoff_hz));
  s.torso_vertical_cutoff_hz /= f;
  s.lateral_cutoff_hz /= f;
  s.torso_lag_s *= f;
  s.thigh_lag_s *= f;
  char ref[96], b[320];
  std::snprintf(ref, sizeof ref, against, reference);
  std::snprintf(b, sizeof b,
                "time scale: the leg (thigh + shank) is %.3f m, %s, so the settings' cut-offs are divided and their lags multiplied by "
                "%.3f (kinematic cut-off %.2f Hz, lags %.0f ms)",
                leg, ref, f, s.kinematic_cutoff_hz, 1000 * s.torso_lag_s);
  messages.emplace_back(b);
  return s;
}

/// Whether the frontal split (EstimateOptions::frontal_split_weight) acts: where the solver fades
/// its sagittal split of feet side by side (SolverOptions::min_split_distance_m).
bool frontal_split_on(const EstimateOptions& o) { return o.frontal_split_weight > 0 && o.solver.min_split_distance_m > 0; }

/// What the sagittal stage makes of the markers: the frame, the processed window's landmarks and
/// where that window lies in the trial.
struct SagittalStage {
  SagittalFrame frame;
  SagittalLandmarks landmarks;
  Eigen::Index first_index = 0;
  int first_frame_number = 1;
  std::array<Eigen::VectorXd, 2> foot_lateral_m;
  std::array<Eigen::MatrixX4d, 2> foot_line;                    ///< with EstimateOptions::lateral_force()
  std::vector<Eigen::MatrixX3d> com_sums_m;  ///< with the frontal split: com_landmark_weights' sums (frontal_balance)
  std::optional<double> hip_half_width_m;                       ///< the hip rule's (Landmarks3D)
  bool trunk_measured = true;  ///< the shoulder point from upper-body markers, not the model torso (pelvis_up)
  double torso_sway_gain = 1.0;  ///< the model torso's fore-aft sway (its rule's sway_gain; trunk_measured: unused)
  /// Per side: the knee point is a marker on the bone (the set's knee rule a marker or a mean of
  /// markers), not a point a thigh cluster carries (EstimateOptions::thigh_lag_s).
  std::array<bool, 2> knee_on_bone{false, false};
  std::array<Eigen::MatrixX3d, kLandmarkCount> landmark_lab_m;  ///< with EstimateOptions::mediolateral
  Eigen::MatrixX3d lateral_axis;                                ///< likewise, per frame
  std::array<Eigen::MatrixX3d, kUpperBodyCount> upper_body_lab_m;  ///< likewise (SagittalWindow's)
  Messages messages;
};

/// markers -> landmarks -> the sagittal frame and window. `release` (the trial, when the caller
/// gave it up): its marker samples are released once the landmarks are made, the last use of them.
SagittalStage sagittal_stage(const Trial& trial, Trial* release, const Trial* static_trial, const MarkerSet& given_set,
                             const EstimateOptions& o) {
  SagittalStage out;
  std::vector<std::string> repeated;
  const std::optional<MarkerSet> chosen = given_set.preset ? choose_repeated_markers(given_set, trial.markers, repeated) : std::nullopt;
  const MarkerSet& set = chosen ? *chosen : given_set;
  if (trial.markers.frames() == 0) throw InputError(trial.path + ": the trial has no marker frames");
  std::vector<std::string> cleaning;
  // A trial the caller gave up is cleaned in place (`release` is `trial` then); otherwise the
  // cleaned copy is made only when there is an outlier.
  std::optional<MarkerTrajectories> cleaned;
  const std::vector<std::string> motion_markers = set.motion_markers();
  if (release) remove_marker_outliers(release->markers, motion_markers, cleaning);
  else cleaned = without_marker_outliers(trial.markers, motion_markers, cleaning);
  // Gaps beyond the landmarks' cubic fill, from the markers that move rigidly with the marker
  // (the outliers just removed are gaps too); the markers copied first only when there is a fill.
  if (o.landmarks.rigid_fill) {
    const MarkerTrajectories& source = release ? release->markers : cleaned ? *cleaned : trial.markers;
    const std::vector<RigidGapFill> fills = rigid_gap_fills(source, motion_markers, o.landmarks.max_gap_frames, cleaning);
    if (!fills.empty()) write_gap_fills(release ? release->markers : cleaned ? *cleaned : cleaned.emplace(trial.markers), fills);
  }
  // The samples the landmarks are made of are released as they are used (the trial's, when the
  // caller gave it up).
  MarkerTrajectories* releasable = release ? &release->markers : nullptr;
  LandmarkOptions lo = o.landmarks;
  // The arms and the head as segments of their own: the lateral model's, and the frontal balance's
  // (an arm held out sideways moves the centre of mass across the feet).
  lo.upper_body = (o.lateral_force() || frontal_split_on(o)) && o.upper_body_segments;
  Landmarks3D lm3 = compute_landmarks(set, cleaned ? *cleaned : trial.markers, static_trial ? &static_trial->markers : nullptr, lo,
                                      trial.path, releasable);
  // Every sample is released now (compute_landmarks lets go of unread markers too). From here on,
  // only the markers' frame count, numbers, times, rate and up axis are read (the trial's, which
  // the cleaned copy shares).
  cleaned.reset();
  const MarkerTrajectories& markers = trial.markers;
  // What the readers noticed (duplicate labels, rows cut short, an up axis corrected...) goes with
  // the results, so that estimate's and validate's outputs say it too.
  Messages& msg = out.messages;
  for (const auto& w : trial.warnings) msg.push_back("input: " + w);
  if (static_trial)
    for (const auto& w : static_trial->warnings) msg.push_back("static trial: " + w);
  append(msg, std::move(repeated));
  append(msg, std::move(cleaning));
  append(msg, std::move(lm3.messages));
  out.frame = detect_sagittal_frame(lm3, markers, o.landmarks);
  // The frontal split's centre of mass: two weighted sums of the landmarks (com_landmark_weights;
  // the table's fractions, not the lengths, enter, so a model of any lengths gives them).
  const std::vector<std::array<double, kLandmarkCount>> sums =
      frontal_split_on(o) ? com_landmark_weights(build_model(BodyGeometry{}, 1.0, anthropometric_table(o.anthropometry)))
                          : std::vector<std::array<double, kLandmarkCount>>{};
  SagittalWindow win = sagittal_landmarks(std::move(lm3), set, out.frame, markers, lo, trial.path, o.lateral_force(), sums);
  out.com_sums_m = std::move(win.lab_sums_m);
  out.landmark_lab_m = std::move(win.lab_m);
  out.upper_body_lab_m = std::move(win.upper_body_lab_m);
  out.lateral_axis = std::move(win.lateral_axis);
  append(msg, std::move(win.messages));
  out.first_index = win.first;
  out.first_frame_number = trial.markers.first_frame + static_cast<int>(win.first);
  out.foot_lateral_m = std::move(win.foot_lateral_m);
  out.foot_line = std::move(win.foot_line);
  out.hip_half_width_m = win.hip_half_width_m;
  out.trunk_measured = set.rules[kShoulder].kind != RuleKind::PelvisUp;
  out.torso_sway_gain = set.rules[kShoulder].sway_gain;
  for (int side = 0; side < 2; ++side)
    out.knee_on_bone[static_cast<std::size_t>(side)] = follows_the_bone(set.rules[landmark(side, kKnee)].kind);
  out.landmarks = std::move(win.landmarks);
  const SagittalLandmarks& lm = out.landmarks;
  // The zero-lag filter's single pass runs at cut-off / 0.802 (Winter's correction), which must
  // be below the Nyquist frequency.
  const double limit = max_zero_lag_cutoff_hz(lm.rate_hz);
  for (const auto& [value, name] : {std::pair{o.kinematic_cutoff_hz, "kinematic cut-off (--kinematic-cutoff)"},
                                    std::pair{o.post_cutoff_hz, "post-filter cut-off (--post-cutoff)"}})
    if (value >= limit)
      throw InputError(trial.path + ": the " + name + " of " + format_number(value) + " Hz is too high for the marker rate of " +
                       format_number(lm.rate_hz) + " Hz: a zero-lag Butterworth filter takes cut-offs below " + format_number(limit) +
                       " Hz (half the rate times Winter's two-pass correction 0.802)");
  return out;
}

/// The 3D knee and ankle centres' medial offsets (dynamics/joint_moments_3d.hpp) for the set's
/// lateral markers: half the joint's width (the trial's measured width, else kKneeWidthPerShank
/// or kAnkleWidthPerShank of the model's shank) plus the marker's radius. A message says, per
/// side, what was used; a joint marked as its centre moves nothing. The hip centres: half their
/// distance from the hip rule (`hip_half_width_m`), else kHipHalfWidthPerThigh of the thigh.
JointCentreOffsets joint_centre_offsets(const MarkerSet& set, const Trial& trial, const Model& model,
                                        const std::optional<double>& hip_half_width_m, Messages& messages) {
  JointCentreOffsets out;
  const double thigh = 0.5 * (model.bodies[kThighR].length_m + model.bodies[kThighL].length_m);
  out.hip_half_width_m = hip_half_width_m.value_or(kHipHalfWidthPerThigh * thigh);
  char hip[240];
  std::snprintf(hip, sizeof hip, "hips: the 3D hip centres %.0f mm either side of the hip landmark (%s)", 1000 * out.hip_half_width_m,
                hip_half_width_m ? "the hip rule's own centres" : "no hip centres of the hip rule's own: from the thigh's length");
  messages.emplace_back(hip);
  const double diameter = trial.marker_diameter_m.value_or(kDefaultMarkerDiameterM);
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    const double shank = model.bodies[static_cast<std::size_t>(segment(side, kShank))].length_m;
    struct Joint { int landmark; const std::optional<double>& measured; double per_shank; double& offset; const char* name; };
    for (const Joint& j : {Joint{landmark(side, kKnee), trial.knee_width_m[k], kKneeWidthPerShank, out.knee_m[k], "knee"},
                           Joint{landmark(side, kAnkle), trial.ankle_width_m[k], kAnkleWidthPerShank, out.ankle_m[k], "ankle"}}) {
      if (!set.rules[static_cast<std::size_t>(j.landmark)].lateral_surface) continue;
      const double width = j.measured.value_or(j.per_shank * shank);
      j.offset = 0.5 * width + 0.5 * diameter;
      char text[320];
      std::snprintf(text, sizeof text, "%s: a lateral marker; the 3D %s centre is %.0f mm medial of it (half the %s width %.0f mm, %s, "
                    "plus the marker radius %.1f mm%s)", landmark_name(j.landmark), j.name, 1000 * j.offset, j.name, 1000 * width,
                    j.measured ? "the file's" : "from the shank's length", 500 * diameter, trial.marker_diameter_m ? ", the file's" : "");
      messages.emplace_back(text);
    }
  }
  return out;
}

/// The model (fixed segment lengths, the medians over the window, and anthropometry) and the
/// trial's floor and soles (ground level, contact calibration).
struct ModelStage {
  std::shared_ptr<const Model> model;
  /// The floor the contacts and the results take: the measured (or given) ground plus
  /// ContactModelOptions::ground_shift_m, applied here only, after the soles are measured, so
  /// that every later stage (the contacts, the flight test, the totals, the lab-frame COP) sees
  /// one floor.
  ContactCalibration soles;
  Messages messages;
};
ModelStage model_stage(const EstimateOptions& o, const SagittalLandmarks& lm, double mass_kg) {
  ModelStage out;
  const GroundLevel ground = o.ground_level_m ? GroundLevel{*o.ground_level_m, ""} : estimate_ground_level(lm);
  if (!ground.message.empty()) out.messages.push_back(ground.message);
  out.soles = calibrate_contact(lm, ground.level_m, o.contact.still_foot_rad_per_s);
  if (!out.soles.message.empty()) out.messages.push_back(out.soles.message);
  for (int s = 0; s < 2; ++s)
    if (out.soles.flat_frames[static_cast<std::size_t>(s)] < 3)
      out.messages.push_back(std::string(side_name(s)) + " foot: only " +
                             std::to_string(out.soles.flat_frames[static_cast<std::size_t>(s)]) +
                             " foot-flat frames for the contact calibration");
  out.soles.ground_level_m += o.contact.ground_shift_m;
  const BodyGeometry geometry = measure_geometry(lm);
  append(out.messages, segment_proportion_notes(geometry));
  out.model = std::make_shared<const Model>(build_model(geometry, mass_kg, anthropometric_table(o.anthropometry)));
  return out;
}

/// Model coordinates and their derivatives, filtered at the kinematic cut-off.
struct KinematicsStage {
  ModelMotion motion;
  double kinematic_cutoff_hz = 0.0;  ///< the dynamics' (the user's, or lowered by the markers' noise)
  double position_cutoff_hz = 0.0;   ///< the residual analysis' (the COP function's foot angle)
  /// The unfiltered coordinates, kept only where the noise lowered the cut-off and the stance
  /// floor (min_kinematic_cycles) may raise it again in a second pass (half the landmarks' size).
  Eigen::MatrixXd unfiltered;
  Messages messages;
};
/// `noise_from`: a first pass on the same markers, whose noise-limited cut-off (and its message) is
/// taken as it is rather than measured again (the running torso stage moves one landmark by a
/// smooth sway, not by noise).
KinematicsStage kinematics_stage(const EstimateOptions& o, const std::shared_ptr<const Model>& model, const SagittalLandmarks& lm,
                                 const KinematicsStage* noise_from = nullptr) {
  KinematicsStage out;
  // The kinematic cut-off: the user's (6 Hz), lowered where the markers' own noise needs it
  // (Winter's residual analysis on the landmarks, noise_limited_cutoff).
  out.kinematic_cutoff_hz = o.kinematic_cutoff_hz;
  if (noise_from) {
    out.kinematic_cutoff_hz = noise_from->kinematic_cutoff_hz;
    out.messages = noise_from->messages;
  } else if (o.cutoff_from_noise) {
    const double fc = noise_limited_cutoff(lm, o.kinematic_cutoff_hz);
    if (fc < o.kinematic_cutoff_hz) {
      out.kinematic_cutoff_hz = fc;
      char b[200];
      std::snprintf(b, sizeof b, "kinematic cut-off lowered from %.1f to %.2f Hz: the markers' noise (residual analysis)",
                    o.kinematic_cutoff_hz, fc);
      out.messages.emplace_back(b);
    }
  }
  out.position_cutoff_hz = out.kinematic_cutoff_hz;
  Eigen::MatrixXd x = model_coordinates(lm, o.torso_length);
  if (o.min_kinematic_cycles > 0 && out.kinematic_cutoff_hz < o.kinematic_cutoff_hz) out.unfiltered = x;
  out.motion = motion_from_coordinates(model, std::move(x), lm.rate_hz, lm.time_s, out.kinematic_cutoff_hz, 0.0, o.kinematic_edges,
                                       o.kinematic_edge_span_periods);
  return out;
}

/// A model torso in a trial with flight phases (a run, a jump) takes the runner's fore-aft sway
/// (EstimateOptions::running_sway_gain) instead of the marker set's walking one. The flight test
/// (flight_frames) reads the whole body's vertical acceleration and the soles, which the torso's
/// fore-aft sway does not move, so the first pass's motion decides it. True when the landmarks
/// changed (the kinematics are then made again); a measured trunk is never touched.
bool running_torso_stage(const EstimateOptions& o, const ModelStage& mod, const ModelMotion& motion, SagittalStage& sag) {
  if (sag.trunk_measured || o.running_sway_gain == sag.torso_sway_gain) return false;
  const std::vector<bool> near_flight = flight_frames(*mod.model, motion, mod.soles);
  if (std::find(near_flight.begin(), near_flight.end(), true) == near_flight.end()) return false;
  sway_model_torso(sag.landmarks, sag.torso_sway_gain, o.running_sway_gain);
  char b[240];
  std::snprintf(b, sizeof b, "shoulder: the trial has flight phases, so the model torso sways by %.2f x the hip's fore-aft oscillation "
                "(a runner's, --running-sway-gain) instead of %.2f (a walker's)", o.running_sway_gain, sag.torso_sway_gain);
  sag.messages.emplace_back(b);
  sag.torso_sway_gain = o.running_sway_gain;
  return true;
}

/// The upper body's fore-aft lag: what the trunk markers do not already show of it
/// (lag_torso_fore_aft, measured_torso_lag_s). The motion is changed in place.
Messages lag_torso_stage(const EstimateOptions& o, ModelMotion& motion, double& added_s) {
  Messages out;
  added_s = 0.0;
  if (!(o.torso_lag_s > 0)) return out;
  const double measured = measured_torso_lag_s(motion);
  const double added = std::clamp(o.torso_lag_s - measured, 0.0, o.torso_lag_s);
  if (added < o.torso_lag_s) {
    char b[200];
    std::snprintf(b, sizeof b, "torso lag: the trunk markers already lag the hip by %.0f ms; %.0f of the %.0f ms added",
                  1000 * measured, 1000 * added, 1000 * o.torso_lag_s);
    out.emplace_back(b);
  }
  lag_torso_fore_aft(motion, added);
  added_s = added;
  return out;
}

/// The thighs' fore-aft lag (lag_thigh_fore_aft) on the sides whose knee point is a marker on
/// the bone; a knee a thigh cluster carries already moves with the thigh's soft tissue. The
/// motion is changed in place.
Messages lag_thigh_stage(const EstimateOptions& o, ModelMotion& motion, const std::array<bool, 2>& knee_on_bone, bool has_flight) {
  Messages out;
  if (!(o.thigh_lag_s > 0) || !(knee_on_bone[0] || knee_on_bone[1])) return out;
  if (has_flight) {
    out.emplace_back("thigh lag: none, the trial has flight phases (measured on walks; the one landing with knee markers on the bone "
                     "lost with it)");
    return out;
  }
  int lagged = 0;
  for (int side = 0; side < 2; ++side)
    if (knee_on_bone[static_cast<std::size_t>(side)]) {
      lag_thigh_fore_aft(motion, side, o.thigh_lag_s);
      ++lagged;
    }
  char b[240];
  if (lagged == 2)
    std::snprintf(b, sizeof b, "thigh lag: each thigh's fore-aft inertial force delayed by %.0f ms (its knee marker is on the bone)",
                  1000 * o.thigh_lag_s);
  else if (lagged == 1)
    std::snprintf(b, sizeof b, "thigh lag: the %s thigh's fore-aft inertial force delayed by %.0f ms (its knee marker is on the bone); "
                  "the %s knee point rides on a thigh cluster, whose soft tissue already lags", knee_on_bone[0] ? "right" : "left",
                  1000 * o.thigh_lag_s, knee_on_bone[0] ? "left" : "right");
  out.emplace_back(b);
  return out;
}

/// The upper body's vertical smoothing (smooth_torso_vertical) below the dynamics' kinematic
/// cut-off, in a trial without flight phases: a run's or a landing's vertical force is a pulse
/// with real content above the cut-off (measured: the runs' vertical 4.7 -> 6.1 % and the drop
/// jump's 13.6 -> 14.9 % with it at 4 Hz), and a trial that has them keeps its timing throughout,
/// as the thighs' lag does, rather than switching filters mid-trial. The motion is changed in place.
Messages smooth_torso_vertical_stage(const EstimateOptions& o, ModelMotion& motion, double kinematic_cutoff_hz, bool has_flight) {
  Messages out;
  const double hz = o.torso_vertical_cutoff_hz;
  if (!(hz > 0) || !(hz < kinematic_cutoff_hz)) return out;
  if (has_flight) {
    out.emplace_back("torso: its vertical inertial force as the markers give it, the trial has flight phases (a run's or a "
                     "landing's force has content above the smoothing's cut-off)");
    return out;
  }
  smooth_torso_vertical(motion, hz);
  char b[240];
  std::snprintf(b, sizeof b, "torso: its vertical inertial force low-passed at %.1f Hz (the upper body does not pass on the pelvis "
                "markers' heel-strike jolt)", hz);
  out.emplace_back(b);
  return out;
}

/// Which frames take the running COP function, the rest of the trial's calibration (the belt
/// velocity, always, on a treadmill, from every frame's contact points; the progression speed and
/// the speed gate) and, with the touchdown rule, each foot's landing frames (landing_frames).
struct ContactPlan {
  std::vector<bool> near_flight;              ///< frames near a flight phase (flight_frames), on every trial
  Eigen::VectorXd vertical_sum_N;             ///< the whole body's vertical force sum per frame (vertical_force_sum_N)
  std::vector<bool> running;                  ///< frames that take the running COP function
  std::array<std::vector<bool>, 2> landing;   ///< per side, frames where the foot is still landing (landing_frames)
  TrialCalibration calibration;
  Messages messages;
};
/// `hip_speed_mps`: the overground progression speed (progression_speed of the landmarks); a
/// treadmill's is its belt's.
ContactPlan contact_stage(const EstimateOptions& o, const Model& model, ContactCalibration soles, bool treadmill, double hip_speed_mps,
                          const ModelMotion& motion) {
  ContactPlan plan;
  const ContactModelOptions& co = o.contact;
  const bool running_cop = co.foot_model == FootModel::Cop && co.running_cop;
  // The flight phases, always: the running COP function, the speed gate's floor near a flight
  // (SpeedGateRule::floor_mps), the touchdown rule, the lateral force's torso lag and a landing's
  // least squares, the thighs' lag and the torso's vertical smoothing all read them, each under
  // its own option. A list of those options here had to be kept in step with every new reader
  // (the vertical smoothing, missing from it, would have smoothed a jump with --thigh-lag 0
  // --running-cop off and the speed gate's floor at its standstill value); with the defaults the
  // flight test ran anyway.
  const SpeedGateRule& gate = co.speed_gate;
  plan.vertical_sum_N = vertical_force_sum_N(model, motion);
  plan.near_flight = flight_frames(model, motion, soles, plan.vertical_sum_N);
  if (running_cop) {
    plan.running = plan.near_flight;
    const auto nrun = std::count(plan.running.begin(), plan.running.end(), true);
    if (nrun > 0) {
      char b[160];
      std::snprintf(b, sizeof b, "running: %ld of %ld frames are near a flight phase and take the running COP function",
                    static_cast<long>(nrun), static_cast<long>(plan.running.size()));
      plan.messages.push_back(b);
    }
  }
  TrialCalibration& cal = plan.calibration;
  cal.contact = std::move(soles);
  const bool touchdown = co.touchdown_fraction > 0;
  const Eigen::Index n = motion.frames();
  std::array<std::vector<int>, 2> lowest;
  std::array<Eigen::VectorXd, 2> gap, rate, speed;  // per side, the lowest sole point's (touchdown rule)
  if (treadmill || touchdown) {
    // The belt: measured on every treadmill trial, whatever the solver's settings (validation's
    // still-foot rule takes it too). The lowest sole points' descents, for the touchdown rule.
    BeltVelocitySamples samples;
    MotionFrame f;
    FrameContacts fc;
    if (touchdown)
      for (int side = 0; side < 2; ++side) {
        gap[side].resize(n), rate[side].resize(n), speed[side].resize(n);
        lowest[side].resize(static_cast<std::size_t>(n));
      }
    for (Eigen::Index i = 0; i < n; ++i) {
      motion.frame(i, f);
      contact_frame(model, cal.contact, co, is_running_frame(plan.running, i), f, fc);
      if (treadmill) samples.add(fc);
      if (touchdown)
        for (int side = 0; side < 2; ++side) {
          gap[side][i] = fc.lowest_gap_m[side], rate[side][i] = fc.lowest_gap_rate_mps[side];
          speed[side][i] = fc.lowest_velocity_x_mps[side], lowest[side][static_cast<std::size_t>(i)] = fc.lowest_point[side];
        }
    }
    if (const auto belt = treadmill ? samples.median_mps() : std::nullopt) {
      cal.belt_velocity_mps = *belt;
      char b[128];
      std::snprintf(b, sizeof b, std::abs(*belt) < 0.05 ? "no progression (stationary trial): ground velocity %.2f m/s"
                                                        : "treadmill: belt velocity %.3f m/s",
                    *belt);
      plan.messages.push_back(b);
    }
  }
  cal.progression_speed_mps = treadmill ? std::abs(cal.belt_velocity_mps) : hip_speed_mps;
  cal.speed_gate_mps = speed_gate_for(gate, cal.progression_speed_mps);
  cal.flight_speed_gate_mps = speed_gate_for(gate, cal.progression_speed_mps, true);
  if (gate.ratio > 0) {
    char b[240];
    std::snprintf(b, sizeof b, "contact speed gate %.2f m/s (%.2f x the progression speed %.2f m/s, at least %.2f)", cal.speed_gate_mps,
                  gate.ratio, cal.progression_speed_mps, gate.standstill_mps);
    std::string said = b;
    const auto near = std::count(plan.near_flight.begin(), plan.near_flight.end(), true);
    if (near > 0 && cal.flight_speed_gate_mps != cal.speed_gate_mps) {
      std::snprintf(b, sizeof b, "; %.2f m/s (at least %.2f) on the %ld frames near a flight phase, where a landing foot still moves in the "
                    "filtered kinematics", cal.flight_speed_gate_mps, gate.floor_mps, static_cast<long>(near));
      said += b;
    }
    plan.messages.push_back(said);
  }
  if (touchdown) {
    LandingRule rule;
    rule.fraction = co.touchdown_fraction;
    rule.min_speed_mps = std::max(0.1, 0.1 * cal.progression_speed_mps);
    rule.swing_speed_mps = cal.speed_gate_mps;
    for (int side = 0; side < 2; ++side) {
      speed[side] = (speed[side].array() - cal.belt_velocity_mps).abs().matrix();
      plan.landing[side] = landing_frames(gap[side], rate[side], speed[side], lowest[side], rule);
    }
  }
  return plan;
}

/// The per-frame solve's raw results (before the post-filter).
struct RawSolve {
  Eigen::MatrixXd lambda, torque;  ///< N x 2 np contact multipliers (n, t); N x 8 joint torques
  std::vector<std::array<bool, kMaxContactPoints>> active;
  // What the per-foot results take of each frame's contact points (contact_frame), kept as the
  // frames are solved instead of the points themselves.
  std::vector<int> point_side;                     ///< each contact point's foot (fixed over the frames)
  Eigen::MatrixXd point_x_m, point_gap_m;          ///< N x np: along progression; normal gap
  std::array<Eigen::VectorXd, 2> inclination_rad;  ///< per side: theta_A
  std::array<Eigen::MatrixXd, 2> sole_m;           ///< per side, N x 6: A, B, C (x, y)
  // For the double-support transition (EstimateOptions::double_support_sta_weight): the frames
  // where both feet are active, in order, and for each the solve's torque_per_normal (kJointCount
  // x np, column-major), then, when both_feet_tangent_map (EstimateOptions::double_support_angle),
  // its torque_per_tangent. Only those frames: a long walk holds a fifth of its frames' worth.
  std::vector<Eigen::Index> both_feet_frames;
  std::vector<double> both_feet_torque_map;
  bool both_feet_tangent_map = false;
  std::vector<int> iterations;  ///< semi-smooth Newton iterations per frame
  int cycled_frames = 0, capped_frames = 0;
  // The touchdown rule (EstimateOptions::touchdown_stop_fraction; touchdown_stage): per side, the
  // frames the foot is in contact before it has landed; the frames where either is, in order, and
  // for each the solve's torque_per_normal then torque_per_tangent (2 x kJointCount x np).
  std::array<std::vector<bool>, 2> before_touchdown;
  std::vector<Eigen::Index> touchdown_frames;
  std::vector<double> touchdown_torque_map;
};

/// What the per-foot results take of one solved frame i: its contact points' places and gaps, each
/// foot's inclination and sole, the multipliers, torques and active set.
void record_frame(RawSolve& raw, Eigen::Index i, const FrameContacts& fc, const FrameSolution& s, bool keep_sole) {
  const auto np = static_cast<Eigen::Index>(raw.point_side.size());
  for (Eigen::Index j = 0; j < np; ++j) {
    const ContactPoint& p = fc.points[static_cast<std::size_t>(j)];
    raw.point_x_m(i, j) = p.position.x();
    raw.point_gap_m(i, j) = p.gap_m;
  }
  for (int side = 0; side < 2; ++side) {
    const auto s_ = static_cast<std::size_t>(side);
    raw.inclination_rad[s_][i] = fc.foot_inclination_rad[s_];
    if (keep_sole)
      for (int c = 0; c < 3; ++c) raw.sole_m[s_].block<1, 2>(i, 2 * c) = fc.sole[s_][static_cast<std::size_t>(c)].transpose();
  }
  raw.lambda.row(i) = s.contact_lambda.transpose();
  raw.torque.row(i) = s.joint_torque_Nm.transpose();
  raw.active[static_cast<std::size_t>(i)] = s.contact_active;
  raw.iterations[static_cast<std::size_t>(i)] = s.iterations;
}

/// The chunks' torque maps (frames with both feet active) joined in frame order, each chunk's let
/// go once copied.
void join_torque_maps(std::vector<std::pair<std::vector<Eigen::Index>, std::vector<double>>>& chunk_maps, RawSolve& raw) {
  std::size_t frames = 0, values = 0;
  for (const auto& [f, v] : chunk_maps) frames += f.size(), values += v.size();
  raw.both_feet_frames.reserve(frames);
  raw.both_feet_torque_map.reserve(values);
  for (auto& [f, v] : chunk_maps) {
    raw.both_feet_frames.insert(raw.both_feet_frames.end(), f.begin(), f.end());
    raw.both_feet_torque_map.insert(raw.both_feet_torque_map.end(), v.begin(), v.end());
    std::vector<Eigen::Index>().swap(f);
    std::vector<double>().swap(v);
  }
}

/// Eqs. 5-10 on every frame (least squares, activation, semi-smooth iterations). `path` and
/// `first_frame_number` name a frame the solve could not make finite.
RawSolve solve_stage(const EstimateOptions& o, const Model& model, const TrialCalibration& calibration, const ModelMotion& motion,
                     const ContactPlan& plan, const std::function<void(long, long)>& progress, const std::string& path,
                     int first_frame_number) {
  const Eigen::Index n = motion.frames();
  const std::vector<bool>& running = plan.running;
  RawSolve raw;
  {
    MotionFrame f;
    FrameContacts fc;
    motion.frame(0, f);
    contact_frame(model, calibration.contact, o.contact, is_running_frame(running, 0), f, fc);
    for (const auto& p : fc.points) raw.point_side.push_back(p.side);
  }
  const auto np = static_cast<Eigen::Index>(raw.point_side.size());
  raw.lambda.resize(n, 2 * np);
  raw.torque.resize(n, kJointCount);
  raw.active.resize(static_cast<std::size_t>(n));
  raw.point_x_m.resize(n, np);
  raw.point_gap_m.resize(n, np);
  for (int side = 0; side < 2; ++side) {
    raw.inclination_rad[side].resize(n);
    if (o.keep_all_series) raw.sole_m[side].resize(n, 6);
  }
  raw.iterations.resize(static_cast<std::size_t>(n));
  std::vector<char> cycled(static_cast<std::size_t>(n)), capped(static_cast<std::size_t>(n));
  // Frames are independent: each chunk of frames (about 10 us each) has its own solver
  // (workspace) and writes only its own rows. The first chunk, on the calling thread, reports
  // the progress.
  // Each chunk keeps its own frames' torque maps (for_chunks makes at most thread_count() chunks),
  // joined in chunk order after the loop.
  // The double-support transition and the frontal split (EstimateOptions::frontal_split_weight)
  // move load between the feet after the post-filter: their torques move through these maps.
  const bool keep_torque_map = o.double_support_sta_weight > 0 || frontal_split_on(o);
  raw.both_feet_tangent_map = keep_torque_map && o.double_support_angle > 0;
  std::vector<std::pair<std::vector<Eigen::Index>, std::vector<double>>> chunk_maps(
      keep_torque_map ? static_cast<std::size_t>(std::max(1, thread_count())) : 0);
  for_chunks(static_cast<std::size_t>(n), min_chunk_for(10e-6), [&](std::size_t chunk, std::size_t begin, std::size_t end) {
    ContactSolver solver(model, calibration, o.solver);
    MotionFrame f;
    FrameContacts fc;
    const auto step = std::max<std::size_t>(1, (end - begin) / 100);
    for (std::size_t k = begin; k < end; ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      if (chunk == 0 && progress && (k - begin) % step == 0)
        progress(static_cast<long>(static_cast<double>(k) / static_cast<double>(end) * static_cast<double>(n)), static_cast<long>(n));
      motion.frame(i, f);
      contact_frame(model, calibration.contact, o.contact, is_running_frame(running, i), f, fc);
      for (int side = 0; side < 2; ++side) fc.landing[side] = flag_at(plan.landing[side], i);
      fc.near_flight = flag_at(plan.near_flight, i);
      const FrameSolution s = solver.solve(f.q, f.qdd, fc);
      record_frame(raw, i, fc, s, o.keep_all_series);
      if (keep_torque_map) {
        std::array<bool, 2> on{false, false};
        for (Eigen::Index j = 0; j < np; ++j)
          if (s.contact_active[static_cast<std::size_t>(j)]) on[static_cast<std::size_t>(raw.point_side[static_cast<std::size_t>(j)])] = true;
        if (on[0] && on[1]) {
          auto& [frames, values] = chunk_maps[chunk];
          frames.push_back(i);
          values.insert(values.end(), s.torque_per_normal.data(), s.torque_per_normal.data() + s.torque_per_normal.size());
          if (raw.both_feet_tangent_map)
            values.insert(values.end(), s.torque_per_tangent.data(), s.torque_per_tangent.data() + s.torque_per_tangent.size());
        }
      }
      cycled[k] = s.cycled;
      capped[k] = s.capped;
    }
  });
  join_torque_maps(chunk_maps, raw);
  raw.cycled_frames = static_cast<int>(std::count(cycled.begin(), cycled.end(), 1));
  raw.capped_frames = static_cast<int>(std::count(capped.begin(), capped.end(), 1));
  if (progress) progress(static_cast<long>(n), static_cast<long>(n));
  // No NaN leaves the library: a frame the solve could not make finite is named, not written.
  for (Eigen::Index i = 0; i < n; ++i)
    if (!raw.lambda.row(i).allFinite() || !raw.torque.row(i).allFinite())
      throw InputError(path + ": the contact solve gave a non-finite force at frame " +
                       std::to_string(first_frame_number + static_cast<int>(i)) + " (check the markers there)");
  return raw;
}

/// One pass of the dynamics on a motion: the torso lag (the motion is changed in place), the
/// contact plan and the solve. The stance floor's second pass is a second call.
struct DynamicsPass {
  ContactPlan plan;  ///< its messages: the torso lag's first, then the contact stage's
  RawSolve raw;
  double seconds_kinematics = 0, seconds_dynamics = 0;
  double torso_lag_added_s = 0;  ///< the upper body's delay lag_torso_stage added (the lateral force takes it too)
};
DynamicsPass dynamics_pass(const EstimateOptions& o, const Model& model, const ContactCalibration& soles, bool treadmill,
                           double hip_speed_mps, const std::array<bool, 2>& knee_on_bone, double kinematic_cutoff_hz, ModelMotion& motion,
                           const std::function<void(long, long)>& progress, const std::string& path, int first_frame_number) {
  using clock = std::chrono::steady_clock;
  const auto ta = clock::now();
  DynamicsPass pass;
  Messages lag = lag_torso_stage(o, motion, pass.torso_lag_added_s);
  pass.plan = contact_stage(o, model, soles, treadmill, hip_speed_mps, motion);
  // The contact plan reads no fore-aft acceleration, so the thighs' lag may follow it and take its
  // flight phases. Its flight test reads the vertical, the chain's; the torso's vertical smoothing,
  // only in a trial where that test finds no flight, then replaces the HAT's for the solve.
  const auto& flight = pass.plan.near_flight;
  const bool has_flight = std::find(flight.begin(), flight.end(), true) != flight.end();
  append(lag, lag_thigh_stage(o, motion, knee_on_bone, has_flight));
  append(lag, smooth_torso_vertical_stage(o, motion, kinematic_cutoff_hz, has_flight));
  pass.plan.messages.insert(pass.plan.messages.begin(), std::make_move_iterator(lag.begin()), std::make_move_iterator(lag.end()));
  const auto tb = clock::now();
  pass.raw = solve_stage(o, model, pass.plan.calibration, motion, pass.plan, progress, path, first_frame_number);
  pass.seconds_kinematics = std::chrono::duration<double>(tb - ta).count();
  pass.seconds_dynamics = std::chrono::duration<double>(clock::now() - tb).count();
  return pass;
}

/// Each foot's contact state per frame from the solve: any of its points active.
std::array<std::vector<bool>, 2> foot_contact_states(const RawSolve& raw, Eigen::Index n) {
  std::array<std::vector<bool>, 2> contact{std::vector<bool>(static_cast<std::size_t>(n)), std::vector<bool>(static_cast<std::size_t>(n))};
  const auto np = raw.point_side.size();
  for (Eigen::Index i = 0; i < n; ++i)
    for (std::size_t j = 0; j < np; ++j)
      if (raw.active[static_cast<std::size_t>(i)][j]) contact[static_cast<std::size_t>(raw.point_side[j])][static_cast<std::size_t>(i)] = true;
  return contact;
}

/// The landmarks' heights the touchdown rule reads (per side: heel, MT head), copied before the
/// landmarks are let go; empty with the rule off.
using FootHeights = std::array<std::array<Eigen::VectorXd, 2>, 2>;
FootHeights foot_heights(const EstimateOptions& o, const SagittalLandmarks& lm) {
  FootHeights h;
  if (o.touchdown_stop_fraction > 0)
    for (int side = 0; side < 2; ++side) {
      h[side][0] = lm.p[landmark(side, kHeel)].col(1);
      h[side][1] = lm.p[landmark(side, kMt)].col(1);
    }
  return h;
}

/// The touchdown rule (EstimateOptions::touchdown_stop_fraction): each foot's frames in contact
/// before it has landed (frames_before_touchdown, on the solve's contact states), and for each
/// such frame the solve's torque maps, from the frame solved again (the solve is deterministic;
/// a few per cent of a walk's frames, so the per-frame solve keeps no map it would rarely need).
Messages touchdown_stage(const EstimateOptions& o, const Model& model, const ContactPlan& plan, const ModelMotion& motion,
                         const FootHeights& heights, RawSolve& raw) {
  Messages out;
  if (!(o.touchdown_stop_fraction > 0) || heights[0][0].size() != motion.frames()) return out;
  const Eigen::Index n = raw.lambda.rows();
  const auto contact = foot_contact_states(raw, n);
  const TouchdownStopRule rule = touchdown_stop_rule(o.touchdown_stop_fraction, median_stance_s(contact, motion.rate_hz));
  long landings = 0, frames = 0;
  for (int side = 0; side < 2; ++side) {
    auto& before = raw.before_touchdown[static_cast<std::size_t>(side)];
    // A landing from a flight phase (a run's, a jump's) is left as solved.
    before = frames_before_touchdown(contact[static_cast<std::size_t>(side)], heights[side][0], heights[side][1], motion.rate_hz, rule,
                                     plan.near_flight);
    for (Eigen::Index i = 0; i < n; ++i)
      if (before[static_cast<std::size_t>(i)]) {
        ++frames;
        if (i == 0 || !before[static_cast<std::size_t>(i - 1)]) ++landings;
      }
  }
  if (frames == 0) return out;
  const int np = static_cast<int>(raw.point_side.size());
  ContactSolver solver(model, plan.calibration, o.solver);
  MotionFrame f;
  FrameContacts fc;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!flag_at(raw.before_touchdown[0], i) && !flag_at(raw.before_touchdown[1], i)) continue;
    motion.frame(i, f);
    contact_frame(model, plan.calibration.contact, o.contact, is_running_frame(plan.running, i), f, fc);
    for (int side = 0; side < 2; ++side) fc.landing[side] = flag_at(plan.landing[side], i);
    fc.near_flight = flag_at(plan.near_flight, i);
    const FrameSolution s = solver.solve(f.q, f.qdd, fc);
    raw.touchdown_frames.push_back(i);
    raw.touchdown_torque_map.insert(raw.touchdown_torque_map.end(), s.torque_per_normal.data(), s.torque_per_normal.data() + kJointCount * np);
    raw.touchdown_torque_map.insert(raw.touchdown_torque_map.end(), s.torque_per_tangent.data(), s.torque_per_tangent.data() + kJointCount * np);
  }
  char b[320];
  std::snprintf(b, sizeof b,
                "touchdown: %ld landing(s) carry no load for their first %ld frames (%.0f ms in all), before the foot's heel or MT head "
                "had stopped descending; the 6 Hz kinematics' spread of the impact there is dropped (the residual shows it)",
                landings, frames, 1000.0 * static_cast<double>(frames) / motion.rate_hz);
  out.emplace_back(b);
  return out;
}

/// The touchdown rule's frames (touchdown_stage) lose their foot's load: its points turn inactive
/// and, once the multipliers are post-filtered and moved by the transition and the frontal split
/// (`lamf`, filtered with the dropped load, so that the stance after touchdown is as solved), the
/// joint torques lose what that load gave them (the solve's maps, linear in the multipliers).
/// Returns the dropped (frame, point) pairs; `lamf` and the torques are changed by
/// drop_touchdown_load.
std::vector<std::pair<Eigen::Index, int>> touchdown_points(RawSolve& raw) {
  std::vector<std::pair<Eigen::Index, int>> dropped;
  const int np = static_cast<int>(raw.point_side.size());
  for (Eigen::Index i : raw.touchdown_frames)
    for (int j = 0; j < np; ++j) {
      auto& active = raw.active[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      if (active && flag_at(raw.before_touchdown[static_cast<std::size_t>(raw.point_side[static_cast<std::size_t>(j)])], i)) {
        active = false;
        dropped.emplace_back(i, j);
      }
    }
  return dropped;
}
void drop_touchdown_load(const std::vector<std::pair<Eigen::Index, int>>& dropped, RawSolve& raw, Eigen::MatrixXd& lamf,
                         Eigen::MatrixXd& joint_torque_Nm) {
  const int np = static_cast<int>(raw.point_side.size());
  for (const auto& [i, j] : dropped) {
    const auto it = std::lower_bound(raw.touchdown_frames.begin(), raw.touchdown_frames.end(), i);
    const double* G = raw.touchdown_torque_map.data() + (it - raw.touchdown_frames.begin()) * 2 * kJointCount * np;
    for (int q = 0; q < kJointCount; ++q)
      joint_torque_Nm(i, q) -= lamf(i, 2 * j) * G[j * kJointCount + q] + lamf(i, 2 * j + 1) * G[(np + j) * kJointCount + q];
    lamf(i, 2 * j) = lamf(i, 2 * j + 1) = 0.0;
    raw.lambda(i, 2 * j) = raw.lambda(i, 2 * j + 1) = 0.0;  // the raw forces say the same
  }
}

/// The layout of the solve's both-feet torque maps (RawSolve::both_feet_torque_map) for a move of
/// load with force angle share `angle`: whether the tangential maps are there and used, and the
/// doubles per frame.
struct TorqueMapLayout {
  bool tangent = false;
  Eigen::Index per_frame = 0;
};
TorqueMapLayout torque_map_layout(const RawSolve& raw, double angle) {
  const bool tangent = angle > 0 && raw.both_feet_tangent_map;
  return {tangent, (tangent ? 2 : 1) * kJointCount * static_cast<Eigen::Index>(raw.point_side.size())};
}

/// Frame k's load moved between the feet (the double-support transition, the frontal split): each
/// foot's normal multipliers scaled by its `factor` (its COP does not move), its tangential ones
/// following by `angle` (transition_tangent; 0: as they are), and the joint torques with them
/// through the solve's maps `G` (torque_per_normal, then with `angle` torque_per_tangent), which
/// are linear in the multipliers.
void move_load(const std::array<double, 2>& factor, double angle, const double* G, const std::vector<int>& point_side, Eigen::Index k,
               Eigen::MatrixXd& lamf, Eigen::MatrixXd& joint_torque_Nm) {
  const int np = static_cast<int>(point_side.size());
  for (int j = 0; j < np; ++j) {
    const double normal = lamf(k, 2 * j);
    const double d = (factor[static_cast<std::size_t>(point_side[static_cast<std::size_t>(j)])] - 1) * normal;
    lamf(k, 2 * j) += d;
    for (int q = 0; q < kJointCount; ++q) joint_torque_Nm(k, q) += d * G[j * kJointCount + q];
    if (angle > 0) {
      const double dt = transition_tangent(lamf(k, 2 * j + 1), normal, lamf(k, 2 * j), angle) - lamf(k, 2 * j + 1);
      lamf(k, 2 * j + 1) += dt;
      for (int q = 0; q < kJointCount; ++q) joint_torque_Nm(k, q) += dt * G[(np + j) * kJointCount + q];
    }
  }
}

/// The double-support transition (EstimateOptions::double_support_sta_weight) on the
/// post-filtered multipliers: in each walking double support the trailing foot's share of the
/// vertical force becomes (1 - w) x its share + w x smooth_transition_share(u); each foot's
/// normal multipliers are scaled to their new total (a foot's COP does not move), the sum is
/// kept, and the joint torques move with the multipliers (the solve's torque_per_normal, linear
/// in them). Each foot's tangential multipliers follow (transition_tangent: scaled by
/// 1 + `angle` (f - 1), f its normal multipliers' factor; EstimateOptions::double_support_angle,
/// 0: left as solved), their torques with them (torque_per_tangent).
Messages double_support_transition(double w, double angle, const std::array<std::vector<bool>, 2>& contact, double stance_s, double rate_hz,
                                   const RawSolve& raw, Eigen::MatrixXd& lamf, Eigen::MatrixXd& joint_torque_Nm) {
  const auto max_frames = static_cast<Eigen::Index>(0.5 * stance_s * rate_hz);
  const int np = static_cast<int>(raw.point_side.size());
  // The maps' layout is the solve's (RawSolve::both_feet_tangent_map), which kept the tangential
  // ones when `angle` asked for them.
  const TorqueMapLayout map = torque_map_layout(raw, angle);
  const auto supports = walking_double_supports(contact, max_frames);
  for (const DoubleSupport& ds : supports) {
    const auto t = static_cast<std::size_t>(ds.trailing);
    const double frames = static_cast<double>(ds.last - ds.first + 1);
    for (Eigen::Index k = ds.first; k <= ds.last; ++k) {
      std::array<double, 2> fy{0.0, 0.0};
      for (int j = 0; j < np; ++j) fy[static_cast<std::size_t>(raw.point_side[static_cast<std::size_t>(j)])] += lamf(k, 2 * j);
      if (!(fy[0] > 1.0 && fy[1] > 1.0)) continue;  // a foot the post-filter left without load: nothing to scale
      const double total = fy[0] + fy[1];
      const double u = (static_cast<double>(k - ds.first) + 0.5) / frames;
      const double trailing = (1 - w) * fy[t] + w * smooth_transition_share(u) * total;
      std::array<double, 2> factor{};
      factor[t] = trailing / fy[t];
      factor[1 - t] = (total - trailing) / fy[1 - t];
      const auto it = std::lower_bound(raw.both_feet_frames.begin(), raw.both_feet_frames.end(), k);
      // Every frame of a double support has both feet active in the solve (the contact states
      // are the solve's), so it has its map; the test is a guard, not a case.
      if (it == raw.both_feet_frames.end() || *it != k) continue;
      const double* G = raw.both_feet_torque_map.data() + (it - raw.both_feet_frames.begin()) * map.per_frame;
      move_load(factor, map.tangent ? angle : 0.0, G, raw.point_side, k, lamf, joint_torque_Nm);
    }
  }
  Messages out;
  if (!supports.empty()) {
    char b[200];
    std::snprintf(b, sizeof b, "double support: %zu handovers blended (weight %g) towards a smooth transition", supports.size(), w);
    out.emplace_back(b);
  }
  return out;
}

/// What the frontal split needs of the whole body (frontal_split): its COM's lateral place (m) and
/// lateral inertial force (N; whole_body_lateral), each foot's lateral place (the heel-MT
/// midpoint, m), per frame.
struct FrontalBalance {
  Eigen::VectorXd com_lateral_m, lateral_total_N;
  std::array<Eigen::VectorXd, 2> foot_lateral_m;
};

/// The whole body's frontal balance from the landmarks' sums (whole_body_lateral: the lateral
/// model's centre of mass and whole-body lateral force), at the lateral force's cut-off
/// (EstimateOptions::lateral_cutoff_hz: the body's sway is slow, the skin markers' noise is not),
/// at most the kinematic cut-off asked for (EstimateOptions::kinematic_cutoff_hz: the noise rule's
/// lowered one is made later, and where it falls under the lateral cut-off the balance keeps the
/// lateral one; the lateral model takes the lower). The torso's lateral lag is
/// not applied: the split acts on a landing, near its flight, where the lateral model does not
/// lag either, and on standing, where the lateral force is about nil.
FrontalBalance frontal_balance(const EstimateOptions& o, const SagittalStage& sag, const Model& model) {
  const UpperBodySegments upper = upper_body_segments(sag.upper_body_lab_m, anthropometric_table(o.anthropometry));
  WholeBodyLateral wb =
      whole_body_lateral(model, sag.com_sums_m, &upper, sag.lateral_axis, sag.landmarks.rate_hz, lateral_cutoff(o, o.kinematic_cutoff_hz));
  return FrontalBalance{std::move(wb.com_lateral_m), std::move(wb.total_N), sag.foot_lateral_m};
}

/// The frontal split (EstimateOptions::frontal_split_weight = w) on the post-filtered
/// multipliers: where both feet carry load and their active points lie within `split_distance_m`
/// along progression, the right foot's share of the two feet's vertical force becomes (1 - w f) x
/// its share + w f x frontal_balance_right_share, f = 1 - side_by_side_sagittal_weight (the
/// solver's: 1 within half the distance, 0 beyond it), the COM's height from `motion` above
/// `ground_level_m`. As in the double-support transition, each foot's normal multipliers are
/// scaled (its COP stays), the sum is kept, the tangential ones follow by `angle`
/// (transition_tangent) and the torques through the solve's maps.
Messages frontal_split(double w, double split_distance_m, double angle, const FrontalBalance& fb, const ModelMotion& motion,
                       double ground_level_m, const RawSolve& raw, Eigen::MatrixXd& lamf, Eigen::MatrixXd& joint_torque_Nm) {
  const int np = static_cast<int>(raw.point_side.size());
  const TorqueMapLayout map = torque_map_layout(raw, angle);
  const Model& model = *motion.model;
  long frames = 0;
  MotionFrame f;
  for (std::size_t m = 0; m < raw.both_feet_frames.size(); ++m) {
    const Eigen::Index k = raw.both_feet_frames[m];
    // Each foot's load as the transition takes it; the points' spread along progression as the
    // solver's fade takes it (its active points).
    std::array<double, 2> fy{0.0, 0.0};
    double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
    for (int j = 0; j < np; ++j) {
      fy[static_cast<std::size_t>(raw.point_side[static_cast<std::size_t>(j)])] += lamf(k, 2 * j);
      if (!raw.active[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)]) continue;
      xmin = std::min(xmin, raw.point_x_m(k, j)), xmax = std::max(xmax, raw.point_x_m(k, j));
    }
    if (!(fy[0] > 1.0 && fy[1] > 1.0)) continue;
    const double weight = w * (1 - side_by_side_sagittal_weight(xmax - xmin, split_distance_m));
    if (!(weight > 0)) continue;
    motion.frame(k, f);
    const double com_y = whole_body_com(model, f).y();
    const double total = fy[0] + fy[1];
    const double share = frontal_balance_right_share(fb.com_lateral_m[k], com_y - ground_level_m, fb.lateral_total_N[k], total,
                                                     fb.foot_lateral_m[0][k], fb.foot_lateral_m[1][k]);
    if (!std::isfinite(share)) continue;
    const double right = (1 - weight) * fy[0] + weight * share * total;
    const std::array<double, 2> factor{right / fy[0], (total - right) / fy[1]};
    move_load(factor, map.tangent ? angle : 0.0, raw.both_feet_torque_map.data() + static_cast<Eigen::Index>(m) * map.per_frame,
              raw.point_side, k, lamf, joint_torque_Nm);
    ++frames;
  }
  Messages out;
  if (frames > 0) {
    char b[240];
    std::snprintf(b, sizeof b, "feet side by side: %ld frames' vertical split between the feet from the whole body's frontal balance (weight %g)",
                  frames, w);
    out.emplace_back(b);
  }
  return out;
}

/// Stances near the window's ends: the zero-lag filters see data on one side only there.
/// Measured by cutting development walks short: the total vertical force is 12-53 %
/// body weight RMS off at the cut, 4-10 % 40 ms in and 1-4 % by 60 ms, at a 6 Hz kinematic
/// cut-off; half a period of that cut-off (83 ms at 6 Hz) covers it and scales with the filter.
Messages window_edge_messages(const std::array<std::vector<bool>, 2>& contact, double rate_hz, double cutoff_hz, int first_frame_number) {
  Messages out;
  if (!(rate_hz > 0) || !(cutoff_hz > 0)) return out;
  const double settle_s = 0.5 / cutoff_hz;
  const auto reach = static_cast<Eigen::Index>(std::ceil(settle_s * rate_hz));
  for (int side = 0; side < 2; ++side) {
    const auto& c = contact[static_cast<std::size_t>(side)];
    const auto n = static_cast<Eigen::Index>(c.size());
    for (const IndexRun& run : stance_runs(c, rate_hz)) {
      const bool at_start = run.first < reach, at_end = run.last > n - 1 - reach;
      if (!at_start && !at_end) continue;
      char b[320];
      std::snprintf(b, sizeof b,
                    "%s foot: the stance at frames %ld-%ld %s within %.0f ms of the window's %s (half a period of the %.1f Hz "
                    "kinematic cut-off): the filters see one side of it there, so its forces near that edge are less certain",
                    side_name(side), static_cast<long>(first_frame_number + run.first),
                    static_cast<long>(first_frame_number + run.last), at_start && at_end ? "lies" : at_start ? "begins" : "ends",
                    1000 * settle_s, at_start && at_end ? "ends" : at_start ? "start" : "end", cutoff_hz);
      out.emplace_back(b);
    }
  }
  return out;
}

/// The post-filter's cut-off (Sect. 2.6): post_cutoff_cycles over the median stance, at least the
/// floor (post_cutoff_floor_ratio x the kinematic cut-off), within what the rate allows; or the
/// fixed post_cutoff_hz. With the message that says which.
std::pair<double, std::string> post_cutoff(const EstimateOptions& o, std::optional<double> stance, double rate_hz,
                                           double kinematic_cutoff_hz) {
  if (!(o.post_cutoff_cycles > 0)) return {o.post_cutoff_hz, ""};
  char b[200];
  double hz = o.post_cutoff_hz;
  if (stance) {
    const double per_stance = o.post_cutoff_cycles / *stance, floor_hz = o.post_cutoff_floor_ratio * kinematic_cutoff_hz;
    hz = std::min(std::max(per_stance, floor_hz), 0.4 * rate_hz);
    if (per_stance >= floor_hz)
      std::snprintf(b, sizeof b, "post-filter cut-off %.1f Hz: %g cycles over the median stance of %.3f s", hz, o.post_cutoff_cycles,
                    *stance);
    else
      std::snprintf(b, sizeof b,
                    "post-filter cut-off %.1f Hz: %g x the kinematic cut-off, above %g cycles over the median stance of %.3f s "
                    "(%.1f Hz)",
                    hz, o.post_cutoff_floor_ratio, o.post_cutoff_cycles, *stance, per_stance);
  } else {
    std::snprintf(b, sizeof b, "post-filter cut-off %g Hz (fixed): no complete stance to scale it to", o.post_cutoff_hz);
  }
  return {hz, b};
}

/// What the feet stage makes of the solve: the post-filtered per-foot results and joint torques.
struct FeetStage {
  std::array<FootResult, 2> feet;
  Eigen::MatrixXd joint_torque_Nm;
  double post_cutoff_hz = 0.0;
  Messages messages;
};

/// One foot's force, COP, contact state, gap and sole from the post-filtered multipliers `lamf`
/// and the raw ones; the raw solve's per-side series are taken.
FootResult foot_result(int side, const std::vector<bool>& contact, const Eigen::MatrixXd& lamf, RawSolve& raw) {
  const Eigen::Index n = raw.lambda.rows();
  const int np = static_cast<int>(raw.point_side.size());
  const Eigen::MatrixXd& lam = raw.lambda;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  FootResult f;
  f.force_N = Eigen::MatrixX2d::Zero(n, 2);
  f.raw_force_N = Eigen::MatrixX2d::Zero(n, 2);
  f.cop_x_m = Eigen::VectorXd::Constant(n, nan);
  f.contact = contact;
  f.inclination_rad = std::move(raw.inclination_rad[side]);
  f.gap_m = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  f.sole_m = std::move(raw.sole_m[side]);
  for (Eigen::Index i = 0; i < n; ++i) {
    double mx = 0;
    for (int j = 0; j < np; ++j) {
      if (raw.point_side[static_cast<std::size_t>(j)] != side) continue;
      f.gap_m[i] = std::min(f.gap_m[i], raw.point_gap_m(i, j));
      f.force_N(i, 0) += lamf(i, 2 * j + 1);
      f.force_N(i, 1) += lamf(i, 2 * j);
      f.raw_force_N(i, 0) += lam(i, 2 * j + 1);
      f.raw_force_N(i, 1) += lam(i, 2 * j);
      mx += lamf(i, 2 * j) * raw.point_x_m(i, j);
    }
    if (f.contact[static_cast<std::size_t>(i)]) {
      if (np == 2) f.cop_x_m[i] = raw.point_x_m(i, side);
      else if (std::abs(f.force_N(i, 1)) > 1e-6) f.cop_x_m[i] = mx / f.force_N(i, 1);
    }
  }
  return f;
}

/// The post-filter (Sect. 2.6), the double-support transition, the frontal split of feet side by
/// side (`frontal`: none when it is off) and each foot's result.
FeetStage feet_stage(const EstimateOptions& o, RawSolve raw, const ModelMotion& motion, double kinematic_cutoff_hz, int first_frame_number,
                     double ground_level_m, const FrontalBalance* frontal) {
  const double rate_hz = motion.rate_hz;
  FeetStage out;
  const Eigen::Index n = raw.lambda.rows();
  const int np = static_cast<int>(raw.point_side.size());
  // The stance duration the post-filter scales with, and the handovers the transition blends, are
  // the solve's; the touchdown rule acts last (below).
  std::array<std::vector<bool>, 2> contact = foot_contact_states(raw, n);
  const std::optional<double> stance = median_stance_s(contact, rate_hz);
  // Final filtering (Sect. 2.6): all multipliers at the post-filter cut-off, then inactive ones
  // back to zero.
  std::string why;
  std::tie(out.post_cutoff_hz, why) = post_cutoff(o, stance, rate_hz, kinematic_cutoff_hz);
  if (!why.empty()) out.messages.push_back(std::move(why));
  const double post = out.post_cutoff_hz;
  Eigen::MatrixXd lamf = post > 0 ? butterworth_filtfilt(raw.lambda, rate_hz, post) : raw.lambda;
  // In place (nothing below reads the raw torques): a long trial holds them once.
  out.joint_torque_Nm = post > 0 ? butterworth_filtfilt(std::move(raw.torque), rate_hz, post) : std::move(raw.torque);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int j = 0; j < np; ++j)
      if (!raw.active[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]) lamf(i, 2 * j) = lamf(i, 2 * j + 1) = 0.0;
  if (o.double_support_sta_weight > 0 && stance)
    append(out.messages,
           double_support_transition(o.double_support_sta_weight, o.double_support_angle, contact, *stance, rate_hz, raw, lamf,
                                     out.joint_torque_Nm));
  if (frontal)
    append(out.messages, frontal_split(o.frontal_split_weight, o.solver.min_split_distance_m, o.double_support_angle, *frontal, motion,
                                       ground_level_m, raw, lamf, out.joint_torque_Nm));
  // The touchdown rule (touchdown_stage) last: a landing foot's load before it has landed goes,
  // and the stance after touchdown stays as the post-filter and the transition made it. Applied
  // before them, it moved the handover's start to the touchdown and slowed the landing foot's
  // loading after it (UWA's walk: 306 against 440 N 12 ms after the plate's onset, 512 measured).
  const auto dropped = touchdown_points(raw);
  if (!dropped.empty()) {
    drop_touchdown_load(dropped, raw, lamf, out.joint_torque_Nm);
    contact = foot_contact_states(raw, n);
  }
  Messages edge = window_edge_messages(contact, rate_hz, kinematic_cutoff_hz, first_frame_number);
  out.messages.insert(out.messages.begin(), std::make_move_iterator(edge.begin()), std::make_move_iterator(edge.end()));
  bool any = false;
  for (int side = 0; side < 2; ++side) {
    out.feet[side] = foot_result(side, contact[static_cast<std::size_t>(side)], lamf, raw);
    for (bool c : out.feet[side].contact) any = any || c;
  }
  if (!any) {
    char b[200];
    std::snprintf(b, sizeof b, "no stance: neither foot touches the ground (%.3f m) in the processed window; the GRF is zero "
                               "throughout (check --ground-level)", ground_level_m);
    out.messages.push_back(b);
  }
  return out;
}

/// The mediolateral force (EstimateOptions::mediolateral) into each foot's result.
void mediolateral_stage(const ModelMotion& motion, const SagittalStage& sag, double cutoff_hz, double leg_cutoff_hz, bool own_leg_inertia,
                        double upper_body_lag_s, const std::vector<bool>& near_flight,
                        const AnthropometricTable& table, std::array<FootResult, 2>& feet, Messages& messages) {
  std::array<Eigen::VectorXd, 2> vertical{feet[0].force_N.col(1), feet[1].force_N.col(1)};
  std::array<FootLoad, 2> loads;
  for (int k = 0; k < 2; ++k) loads[k] = {&vertical[k], &feet[k].contact};
  const UpperBodySegments upper = upper_body_segments(sag.upper_body_lab_m, table);
  if (!upper.parts.empty())
    messages.push_back("upper body: " + upper.description +
                       (upper.description.find(" and ") != std::string::npos ? " are segments of their own" : " is a segment of its own") +
                       " in the lateral force");
  // The lag acts only away from flight phases: a run, near them throughout, skips its work.
  const auto away = static_cast<long>(motion.frames()) - std::count(near_flight.begin(), near_flight.end(), true);
  if (away == 0) upper_body_lag_s = 0.0;
  if (upper_body_lag_s > 0) {
    char b[200];
    std::snprintf(b, sizeof b, "lateral force: the torso's share delayed by %.0f ms, as its fore-aft force, on the %ld of %ld frames away "
                  "from flight phases", 1000 * upper_body_lag_s, away, static_cast<long>(motion.frames()));
    messages.push_back(b);
  }
  MediolateralForces ml =
      mediolateral_forces(motion, sag.landmark_lab_m, sag.lateral_axis, cutoff_hz, loads, leg_cutoff_hz, own_leg_inertia, &upper, upper_body_lag_s,
                          &near_flight);
  for (int k = 0; k < 2; ++k) feet[k].force_lateral_N = std::move(ml.foot_N[k]);
}

/// A landing's bilateral stance: frames near a flight phase (`near_flight`, flight_frames) with
/// both feet in contact outside a walking handover (walking_double_supports, at most half the
/// median stance).
std::vector<bool> bilateral_frames(const std::array<FootResult, 2>& feet, double rate_hz, const std::vector<bool>& near_flight) {
  const std::array<std::vector<bool>, 2> contact{feet[0].contact, feet[1].contact};
  const auto n = std::min(contact[0].size(), contact[1].size());
  std::vector<bool> out(n, false);
  for (std::size_t i = 0; i < n; ++i)
    out[i] = contact[0][i] && contact[1][i] && i < near_flight.size() && near_flight[i];
  if (const auto stance = median_stance_s(contact, rate_hz))
    for (const DoubleSupport& ds : walking_double_supports(contact, static_cast<Eigen::Index>(0.5 * *stance * rate_hz)))
      for (Eigen::Index i = ds.first; i <= ds.last; ++i) out[static_cast<std::size_t>(i)] = false;
  return out;
}

/// Each foot's COP's lateral coordinate on its lateral line (FootResult::cop_lateral_m).
void lateral_cop_stage(const std::array<Eigen::MatrixX4d, 2>& foot_line, double toe_medial_slope, std::array<FootResult, 2>& feet) {
  for (int k = 0; k < 2; ++k) {
    FootResult& f = feet[static_cast<std::size_t>(k)];
    f.cop_lateral_m = cop_lateral_on_foot_line(foot_line[static_cast<std::size_t>(k)], f.cop_x_m, toe_medial_slope, k);
  }
}

/// Every frame's totals (frame_totals), unless the result is not to hold them (keep_all_series).
struct TotalsStage {
  Eigen::VectorXd grm_Nm;
  Eigen::MatrixX3d residual, kinematic_total;
  Eigen::MatrixXd joint_force_N;
};
TotalsStage totals_stage(const EstimateOptions& o, const ModelMotion& motion, const std::array<FootResult, 2>& feet,
                         double ground_level_m) {
  TotalsStage out;
  if (!o.keep_all_series) return out;
  const Eigen::Index n = motion.frames();
  out.grm_Nm = Eigen::VectorXd::Zero(n);
  out.residual = Eigen::MatrixX3d::Zero(n, 3);
  out.kinematic_total = Eigen::MatrixX3d::Zero(n, 3);
  out.joint_force_N = Eigen::MatrixXd::Zero(n, 2 * kJointCount);
  for (Eigen::Index i = 0; i < n; ++i) {
    const FrameTotals t = frame_totals(motion, feet, ground_level_m, o.grm_reference_m, i);
    out.grm_Nm[i] = t.grm_Nm;
    out.residual.row(i) = t.residual.transpose();
    out.kinematic_total.row(i) = t.kinematic_total.transpose();
    for (int j = 0; j < 2 * kJointCount; ++j) out.joint_force_N(i, j) = t.joint_force_N[static_cast<std::size_t>(j)];
  }
  return out;
}

}  // namespace

std::vector<std::string> support_notes(const std::array<FootResult, 2>& feet, const Eigen::VectorXd& vertical_sum_N,
                                       double body_weight_N, double rate_hz, double ground_level_m, int first_frame_number) {
  std::vector<std::string> out;
  const Eigen::Index n = vertical_sum_N.size();
  if (!(rate_hz > 0) || !(body_weight_N > 0)) return out;
  const auto shortest = static_cast<Eigen::Index>(std::ceil(kSupportNoteRunS * rate_hz - 1e-9));
  // A run as the file numbers its frames, "first-last".
  const auto span = [&](const IndexRun& run) {
    return std::to_string(first_frame_number + run.first) + "-" + std::to_string(first_frame_number + run.last);
  };
  const auto seconds = [&](Eigen::Index frames) {
    char b[32];
    std::snprintf(b, sizeof b, " (%.2f s)", static_cast<double>(frames) / rate_hz);
    return std::string(b);
  };
  const auto in_contact = [&](int side, Eigen::Index i) {
    const auto& c = feet[static_cast<std::size_t>(side)].contact;
    return static_cast<std::size_t>(i) < c.size() && c[static_cast<std::size_t>(i)];
  };
  for (int side = 0; side < 2; ++side) {
    const FootResult& f = feet[static_cast<std::size_t>(side)];
    if (f.force_N.rows() != n || f.gap_m.size() != n) continue;
    const auto raised = [&](Eigen::Index i) {
      return f.force_N(i, 1) > kLoadedFootFraction * body_weight_N && std::isfinite(f.gap_m[i]) && f.gap_m[i] > kRaisedSoleM;
    };
    std::string where;
    Eigen::Index frames = 0;
    double gap_lo = std::numeric_limits<double>::infinity(), gap_hi = 0, load_hi = 0;
    for (const IndexRun& run : runs_where(n, raised)) {
      const Eigen::Index len = run.last - run.first + 1;
      if (len < shortest) continue;
      where += (where.empty() ? "" : ", ") + span(run);
      frames += len;
      gap_lo = std::min(gap_lo, f.gap_m.segment(run.first, len).minCoeff());
      gap_hi = std::max(gap_hi, f.gap_m.segment(run.first, len).maxCoeff());
      load_hi = std::max(load_hi, f.force_N.col(1).segment(run.first, len).maxCoeff() / body_weight_N);
    }
    if (frames == 0) continue;
    char head[200];
    std::snprintf(head, sizeof head, "%s foot: carries up to %.2f body weights while its sole stands %.0f-%.0f mm above the floor (%.3f m), frames ",
                  side_name(side), load_hi, 1000 * gap_lo, 1000 * gap_hi, ground_level_m);
    const std::string b = head + where + seconds(frames) +
                          ": on a box, a step or a stair? kin2grf's contact is with one level floor; the load is taken where the foot is, "
                          "its COP on the raised sole, and the GRM's lever for the fore-aft force is the floor's height (--ground-level "
                          "sets the floor)";
    out.emplace_back(b);
  }
  const auto unsupported = [&](Eigen::Index i) {
    return vertical_sum_N[i] > kSupportedFraction * body_weight_N && !in_contact(0, i) && !in_contact(1, i);
  };
  for (const IndexRun& run : runs_where(n, unsupported)) {
    if (run.last - run.first + 1 < shortest) continue;
    const Eigen::Index len = run.last - run.first + 1;
    double sole_lo = std::numeric_limits<double>::infinity();
    for (const FootResult& f : feet)
      if (f.gap_m.size() == n) sole_lo = std::min(sole_lo, f.gap_m.segment(run.first, len).minCoeff());
    const double ask_lo = vertical_sum_N.segment(run.first, len).minCoeff() / body_weight_N;
    const double ask_hi = vertical_sum_N.segment(run.first, len).maxCoeff() / body_weight_N;
    char sole[80] = "";
    if (std::isfinite(sole_lo)) std::snprintf(sole, sizeof sole, " (the lower sole at least %.0f mm above it)", 1000 * sole_lo);
    char b[560];
    std::snprintf(b, sizeof b,
                  "frames %s%s: the body's kinematics ask %.2f-%.2f body weights of the ground, yet neither foot is in contact with the "
                  "floor at %.3f m%s: something else carries the body there (a box, a step, a chair, a handrail?) or the floor "
                  "is elsewhere (--ground-level); the ground reaction is zero there and the residual holds that load",
                  span(run).c_str(), seconds(len).c_str(), ask_lo, ask_hi, ground_level_m, sole);
    out.emplace_back(b);
  }
  return out;
}

FrameTotals frame_totals(const ModelMotion& motion, const std::array<FootResult, 2>& feet, double ground_level_m,
                         const Eigen::Vector2d& grm_reference_m, Eigen::Index i) {
  FrameTotals t;
  const Model& model = *motion.model;
  const double g = model.gravity_mps2;
  MotionFrame m;
  motion.frame(i, m);
  Eigen::Vector3d kin = Eigen::Vector3d::Zero();  // sum m(a+g), sum of moments about the origin
  std::array<Eigen::Vector2d, kSegmentCount> seg_force;
  for (int s = 0; s < kSegmentCount; ++s) {
    const Body& b = model.bodies[s];
    const Eigen::Vector2d pos = m.q.segment<2>(coord::com_x(s));
    const Eigen::Vector2d F = b.mass_kg * Eigen::Vector2d(m.qdd(coord::com_x(s)), m.qdd(coord::com_x(s) + 1) + g);
    seg_force[static_cast<std::size_t>(s)] = F;
    kin += Eigen::Vector3d(F.x(), F.y(), sagittal_moment(pos.x(), pos.y(), F.x(), F.y()) + b.inertia_kgm2 * m.qdd(coord::theta(s)));
  }
  Eigen::Vector3d ext = Eigen::Vector3d::Zero();
  for (int side = 0; side < 2; ++side) {
    const auto& f = feet[static_cast<std::size_t>(side)];
    if (!f.contact[static_cast<std::size_t>(i)]) continue;
    const double x = f.cop_x_m[i], y = ground_level_m;
    const double fx = f.force_N(i, 0), fy = f.force_N(i, 1);
    t.grm_Nm += sagittal_moment(x - grm_reference_m.x(), y - grm_reference_m.y(), fx, fy);
    ext += Eigen::Vector3d(fx, fy, sagittal_moment(x, y, fx, fy));
  }
  t.residual = kin - ext;
  t.kinematic_total = kin;
  for (int j = 0; j < kJointCount; ++j) {
    const int side = j / 4, depth = j % 4;
    Eigen::Vector2d F = Eigen::Vector2d::Zero();
    for (int k = depth; k < 4; ++k) F += seg_force[static_cast<std::size_t>(segment(side, static_cast<LegSegment>(k)))];
    if (depth <= 2 && feet[static_cast<std::size_t>(side)].contact[static_cast<std::size_t>(i)])
      F -= feet[static_cast<std::size_t>(side)].force_N.row(i).transpose();
    t.joint_force_N[static_cast<std::size_t>(2 * j)] = F.x();
    t.joint_force_N[static_cast<std::size_t>(2 * j + 1)] = F.y();
  }
  return t;
}

FrameTotals frame_totals(const EstimateResult& r, Eigen::Index i) {
  return frame_totals(r.motion, r.feet, r.ground_level_m(), r.grm_reference_m, i);
}

namespace {

/// The stance floor (EstimateOptions::min_kinematic_cycles): the dynamics' kinematic cut-off
/// raised to that many cycles over the first solve's median stance, when that is above the
/// noise-lowered one; none otherwise.
std::optional<double> stance_floor_hz(const EstimateOptions& o, const KinematicsStage& kin, const RawSolve& first,
                                      double rate_hz, std::string& message) {
  if (kin.unfiltered.size() == 0) return std::nullopt;
  const auto stance = median_stance_s(foot_contact_states(first, first.lambda.rows()), rate_hz);
  if (!stance) return std::nullopt;
  const double floor_hz = std::min(o.kinematic_cutoff_hz, o.min_kinematic_cycles / *stance);
  if (!(floor_hz > kin.kinematic_cutoff_hz)) return std::nullopt;
  char b[240];
  std::snprintf(b, sizeof b,
                "kinematic cut-off for the dynamics raised to %.2f Hz: %g cycles over the median stance of %.3f s (the COP "
                "function's foot angle keeps %.2f Hz)",
                floor_hz, o.min_kinematic_cycles, *stance, kin.position_cutoff_hz);
  message = b;
  return floor_hz;
}

/// The result, assembled once from the stages' outputs (each moved in).
EstimateResult assemble_result(const std::string& marker_set, double mass_kg, SagittalStage& sag, ModelStage& mod, KinematicsStage& kin,
                               DynamicsPass& dyn, FeetStage& feet, TotalsStage& totals, const std::vector<int>& iterations,
                               const EstimateOptions& o) {
  EstimateResult r;
  r.marker_set = marker_set;
  r.mass_kg = mass_kg;
  r.frame = std::move(sag.frame);
  r.kinematic_cutoff_hz = kin.kinematic_cutoff_hz;
  r.position_cutoff_hz = kin.position_cutoff_hz;
  r.post_cutoff_hz = feet.post_cutoff_hz;
  r.calibration = std::move(dyn.plan.calibration);
  r.time_s = sag.landmarks.time_s;
  r.first_index = sag.first_index;
  r.first_frame_number = sag.first_frame_number;
  r.feet = std::move(feet.feet);
  r.grm_Nm = std::move(totals.grm_Nm);
  r.joint_torque_Nm = std::move(feet.joint_torque_Nm);
  r.joint_force_N = std::move(totals.joint_force_N);
  r.residual = std::move(totals.residual);
  r.iterations = iterations;
  r.foot_lateral_m = std::move(sag.foot_lateral_m);
  r.motion = std::move(kin.motion);
  r.grm_reference_m = o.grm_reference_m;
  r.landmarks = std::move(sag.landmarks);
  r.kinematic_total = std::move(totals.kinematic_total);
  for (Messages* m : {&sag.messages, &mod.messages, &kin.messages, &dyn.plan.messages, &feet.messages}) append(r.messages, std::move(*m));
  return r;
}

/// estimate(); `release` (the trial itself, when the caller gave it up) loses its marker samples
/// once the landmarks are made. The stages in order, each taking what it reads and returning
/// what it makes; the result is assembled at the end.
EstimateResult estimate_impl(const Trial& trial, Trial* release, const Trial* static_trial, const MarkerSet& set,
                             const EstimateOptions& given) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  check_options(given);
  const double mass_kg = resolve_mass(trial, given);
  SagittalStage sag = sagittal_stage(trial, release, static_trial, set, given);
  ModelStage mod = model_stage(given, sag.landmarks, mass_kg);
  // From here the options are this subject's (the sagittal stage and the model read none of the
  // settings its size changes).
  const EstimateOptions o = options_for_subject(given, *mod.model, sag.landmarks.rate_hz, mod.messages);
  // The frontal split's whole-body balance (its COM's lateral place and lateral inertial force),
  // made once the model's masses are known; the landmarks' sums and (the sagittal model) the
  // lateral axes go then, before the kinematics (a long trial's peak memory is there).
  std::optional<FrontalBalance> frontal;
  if (frontal_split_on(o)) {
    frontal = frontal_balance(o, sag, *mod.model);
    sag.com_sums_m = {};
    if (!o.lateral_force()) {
      sag.lateral_axis = Eigen::MatrixX3d();
      sag.upper_body_lab_m = {};
    }
  }
  KinematicsStage kin = kinematics_stage(o, mod.model, sag.landmarks);
  if (running_torso_stage(o, mod, kin.motion, sag)) kin = kinematics_stage(o, mod.model, sag.landmarks, &kin);
  const double hip_speed_mps = sag.frame.treadmill ? 0.0 : progression_speed(sag.landmarks);
  const FootHeights heights = foot_heights(o, sag.landmarks);
  if (!o.keep_all_series) sag.landmarks.p = {};  // the hip's speed and the feet's heights were the last use of them
  // The solve's progress over both passes when a second may follow: the first reports the first
  // half, the second the rest (or the first completes it), so a progress line never restarts.
  const bool two_pass_progress = kin.unfiltered.size() > 0 && o.progress;
  const auto pass_progress = [&](long pass) -> std::function<void(long, long)> {
    if (!two_pass_progress) return o.progress;
    return [&o, pass](long done, long n) { o.progress(pass * n + done, 2 * n); };
  };
  double seconds_kinematics = std::chrono::duration<double>(clock::now() - t0).count();
  const auto pass = [&](ModelMotion& motion, long index) {
    DynamicsPass p = dynamics_pass(o, *mod.model, mod.soles, sag.frame.treadmill, hip_speed_mps, sag.knee_on_bone, kin.kinematic_cutoff_hz, motion,
                                   pass_progress(index), trial.path,
                                   sag.first_frame_number);
    seconds_kinematics += p.seconds_kinematics;
    return p;
  };
  DynamicsPass dyn = pass(kin.motion, 0);
  double seconds_dynamics = dyn.seconds_dynamics;
  std::string raised;
  if (const auto floor_hz = stance_floor_hz(o, kin, dyn.raw, kin.motion.rate_hz, raised)) {
    // The second pass: the same stages on the coordinates filtered at the raised cut-off; the
    // first pass's contact plan and solve are dropped (their messages with them).
    const auto tk = clock::now();
    const double rate_hz = kin.motion.rate_hz;
    Eigen::VectorXd time_s = std::move(kin.motion.time_s);
    kin.motion = ModelMotion();
    dyn = DynamicsPass();
    kin.motion = motion_from_coordinates(mod.model, std::move(kin.unfiltered), rate_hz, std::move(time_s), *floor_hz, kin.position_cutoff_hz,
                                         o.kinematic_edges, o.kinematic_edge_span_periods);
    kin.kinematic_cutoff_hz = *floor_hz;
    kin.messages.push_back(std::move(raised));
    seconds_kinematics += std::chrono::duration<double>(clock::now() - tk).count();
    dyn = pass(kin.motion, 1);
    seconds_dynamics += dyn.seconds_dynamics;
  } else if (two_pass_progress) {
    o.progress(2 * kin.motion.frames(), 2 * kin.motion.frames());  // one pass was enough: done
  }
  kin.unfiltered = Eigen::MatrixXd();
  append(dyn.plan.messages, touchdown_stage(o, *mod.model, dyn.plan, kin.motion, heights, dyn.raw));
  const std::vector<int> iterations = std::move(dyn.raw.iterations);
  const int cycled_frames = dyn.raw.cycled_frames, capped_frames = dyn.raw.capped_frames;
  const double ground_level_m = dyn.plan.calibration.contact.ground_level_m;
  FeetStage feet = feet_stage(o, std::move(dyn.raw), kin.motion, kin.kinematic_cutoff_hz, sag.first_frame_number, ground_level_m,
                              frontal ? &*frontal : nullptr);
  frontal.reset();
  append(feet.messages, support_notes(feet.feet, dyn.plan.vertical_sum_N, mass_kg * mod.model->gravity_mps2, kin.motion.rate_hz,
                                      ground_level_m, sag.first_frame_number));
  dyn.plan.vertical_sum_N = Eigen::VectorXd();  // its last reader
  if (o.lateral_force()) {
    const double cutoff = lateral_cutoff(o, kin.kinematic_cutoff_hz);
    const double lateral_lag_s = o.lateral_torso_lag && sag.trunk_measured ? dyn.torso_lag_added_s : 0.0;
    mediolateral_stage(kin.motion, sag, cutoff, kin.kinematic_cutoff_hz, o.lateral_own_leg_inertia, lateral_lag_s, dyn.plan.near_flight,
                       anthropometric_table(o.anthropometry),
                       feet.feet, kin.messages);
    lateral_cop_stage(sag.foot_line, o.toe_medial_slope, feet.feet);
  }
  // The 3D model's legs: validate drives their kinematics again with the plates, so the result
  // keeps them (keep_all_series); otherwise they are made a block at a time (about 1.2 kB a frame
  // held for a block, not for the trial) once the feet's wrenches are known.
  const auto release_lab = [&sag] {
    sag.landmark_lab_m = {};
    sag.lateral_axis = Eigen::MatrixX3d();
  };
  std::optional<LegMotion3D> legs;
  std::optional<JointCentreOffsets> offsets;
  const std::vector<bool> bilateral = o.lateral_force() && o.lateral_least_squares
                                          ? bilateral_frames(feet.feet, kin.motion.rate_hz, dyn.plan.near_flight)
                                          : std::vector<bool>();
  const bool split_by_least_squares = std::find(bilateral.begin(), bilateral.end(), true) != bilateral.end();
  if (o.model == ModelKind::ThreeD || split_by_least_squares) {
    offsets = joint_centre_offsets(set, trial, *mod.model, sag.hip_half_width_m, kin.messages);
    if (o.keep_all_series)
      legs = leg_motion_3d(*mod.model, sag.landmark_lab_m, sag.lateral_axis, sag.frame.up, kin.motion.rate_hz, kin.kinematic_cutoff_hz, *offsets);
  }
  if (!offsets || legs) release_lab();  // the blocks below are the only other reader
  TotalsStage totals = totals_stage(o, kin.motion, feet.feet, ground_level_m);

  EstimateResult r = assemble_result(set.name, mass_kg, sag, mod, kin, dyn, feet, totals, iterations, o);
  if (offsets) {
    // The legs' 3D moments for the feet's wrenches; with a bilateral stance twice (its frames'
    // lateral forces zero, then 1 N a foot), the least squares's split and its moments from the
    // two by linearity (least_squares_lateral_split).
    const auto moments_for = [&](const std::array<FootWrench3D, 2>& w, bool last) {
      if (legs) return joint_moments_3d(*legs, w);
      if (!last)
        return joint_moments_3d_in_blocks(*mod.model, sag.landmark_lab_m, sag.lateral_axis, r.frame.up, kin.motion.rate_hz,
                                          kin.kinematic_cutoff_hz, *offsets, w);
      JointMoments3D m = joint_moments_3d_in_blocks(*mod.model, std::move(sag.landmark_lab_m), sag.lateral_axis, r.frame.up,
                                                    kin.motion.rate_hz, kin.kinematic_cutoff_hz, *offsets, w);
      release_lab();
      return m;
    };
    JointMoments3D moments;
    if (split_by_least_squares) {
      std::array<Eigen::VectorXd, 2> lateral{r.feet[0].force_lateral_N, r.feet[1].force_lateral_N};
      const auto with_lateral = [&](double force_N) {
        for (std::size_t k = 0; k < 2; ++k)
          for (std::size_t i = 0; i < bilateral.size(); ++i)
            if (bilateral[i]) r.feet[k].force_lateral_N[static_cast<Eigen::Index>(i)] = force_N;
        return estimated_wrenches(r);
      };
      const JointMoments3D zero = moments_for(with_lateral(0.0), false);
      const JointMoments3D unit = moments_for(with_lateral(1.0), true);
      moments = least_squares_lateral_split(zero, unit, bilateral, lateral);
      for (std::size_t k = 0; k < 2; ++k) r.feet[k].force_lateral_N = std::move(lateral[k]);
      const auto frames = std::count(bilateral.begin(), bilateral.end(), true);
      char b[200];
      std::snprintf(b, sizeof b, "lateral force: %ld frames of a landing's bilateral stance (both feet down, near a flight phase) split "
                    "by the least squares with the legs' 3D joint moments", static_cast<long>(frames));
      r.messages.push_back(b);
    } else {
      moments = moments_for(estimated_wrenches(r), true);
    }
    if (o.model == ModelKind::ThreeD) r.legs_3d = Legs3D{legs ? std::move(*legs) : LegMotion3D(), std::move(moments)};
  }
  r.cycled_frames = cycled_frames;
  r.capped_frames = capped_frames;
  r.seconds_kinematics = seconds_kinematics;
  r.seconds_dynamics = seconds_dynamics;
  return r;
}

}  // namespace

namespace {
/// Every error of an estimate names the trial's file: the model and the frame finders know only
/// numbers ("segment torso length 5.5 m is not plausible" did not say which file).
template <class Run>
EstimateResult naming_the_trial(const std::string& path, Run&& run) {
  try {
    return run();
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (path.empty() || what.rfind(path, 0) == 0) throw;
    throw InputError(path + ": " + what);
  }
}
}  // namespace

EstimateResult estimate(const Trial& trial, const Trial* static_trial, const MarkerSet& set, const EstimateOptions& o) {
  return naming_the_trial(trial.path, [&] { return estimate_impl(trial, nullptr, static_trial, set, o); });
}

EstimateResult estimate(Trial&& trial, const Trial* static_trial, const MarkerSet& set, const EstimateOptions& o) {
  const std::string path = trial.path;
  return naming_the_trial(path, [&] { return estimate_impl(trial, &trial, static_trial, set, o); });
}

Eigen::VectorXd cop_lateral_on_foot_line(const Eigen::MatrixX4d& line, const Eigen::VectorXd& cop_x_m, double toe_medial_slope, int side) {
  const Eigen::Index n = cop_x_m.size();
  if (line.rows() != n) throw InputError("the COP's lateral line and the COP differ in frames");
  Eigen::VectorXd out = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(cop_x_m[i])) continue;
    const double span = line(i, 2) - line(i, 0);
    const double u = std::abs(span) > 1e-6 ? (cop_x_m[i] - line(i, 0)) / span : 0.5, t = std::clamp(u, 0.0, 1.0);
    out[i] = line(i, 1) + t * (line(i, 3) - line(i, 1));
    // Ahead of the forefoot end by (u - 1)|span|: medial is -lateral for the right foot.
    if (u > 1) out[i] -= (side == 0 ? 1.0 : -1.0) * toe_medial_slope * (u - 1) * std::abs(span);
  }
  return out;
}

const char* model_kind_name(ModelKind kind) { return kind == ModelKind::ThreeD ? "3d" : "sagittal"; }

ModelKind model_kind(const std::string& name) {
  if (name == "sagittal") return ModelKind::Sagittal;
  if (name == "3d") return ModelKind::ThreeD;
  throw InputError("model '" + name + "' is not known: sagittal or 3d");
}

std::array<FootWrench3D, 2> estimated_wrenches(const EstimateResult& r) {
  std::array<FootWrench3D, 2> out;
  const Eigen::Index n = r.time_s.size();
  for (int side = 0; side < 2; ++side) {
    Eigen::MatrixX3d force(n, 3), cop(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      const LabFootFrame f = lab_foot_frame(r, side, i);
      force.row(i) = f.force_N.transpose();
      cop.row(i) = f.cop_m.transpose();
    }
    out[static_cast<std::size_t>(side)] = foot_wrench(force, cop, Eigen::VectorXd::Zero(n), r.frame.up);
  }
  return out;
}

LabFootFrame lab_foot_frame(const EstimateResult& r, int side, Eigen::Index i) {
  const auto& f = r.feet[static_cast<std::size_t>(side)];
  const Eigen::Index k = r.first_index + i;  // the trial frame (a turning frame's heading)
  LabFootFrame out;
  out.force_N = f.force_N(i, 0) * r.frame.forward_at(k) + f.force_N(i, 1) * r.frame.up;
  if (f.force_lateral_N.size() > i) out.force_N += f.force_lateral_N[i] * r.frame.lateral_at(k);
  if (std::isfinite(f.cop_x_m[i]))
    out.cop_m = r.frame.to_lab(f.cop_x_m[i], r.ground_level_m(),
                               f.cop_lateral_m.size() > i ? f.cop_lateral_m[i] : r.foot_lateral_m[static_cast<std::size_t>(side)][i], k);
  else
    out.cop_m.setConstant(std::numeric_limits<double>::quiet_NaN());
  return out;
}

std::array<ForcePlate, 2> trial_foot_plates(const EstimateResult& r, Eigen::Index trial_frames, const Eigen::Matrix3d& R) {
  const auto lab = as_lab_plates(r);
  const Eigen::Index N = trial_frames, n = r.time_s.size();
  std::array<ForcePlate, 2> out;
  for (std::size_t s = 0; s < 2; ++s) {
    ForcePlate& f = out[s];
    f.force_N = Eigen::MatrixX3d::Zero(N, 3);
    f.cop_m = Eigen::MatrixX3d::Constant(N, 3, std::numeric_limits<double>::quiet_NaN());
    f.free_moment_Nm = Eigen::MatrixX3d::Zero(N, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index k = r.first_index + i;
      if (k < 0 || k >= N || !r.feet[s].contact[static_cast<std::size_t>(i)] || !lab[s].cop_m.row(i).allFinite()) continue;
      f.force_N.row(k) = (R * lab[s].force_N.row(i).transpose()).transpose();
      f.cop_m.row(k) = (R * lab[s].cop_m.row(i).transpose()).transpose();
    }
  }
  return out;
}

std::array<ForcePlate, 2> as_lab_plates(const EstimateResult& r) {
  std::array<ForcePlate, 2> out;
  const Eigen::Index n = r.time_s.size();
  for (int side = 0; side < 2; ++side) {
    ForcePlate& p = out[static_cast<std::size_t>(side)];
    p.name = side_name(side);
    p.side_hint = side ? Side::Left : Side::Right;
    p.force_N.resize(n, 3);
    p.cop_m.resize(n, 3);
    p.free_moment_Nm = Eigen::MatrixX3d::Zero(n, 3);
    p.moment_centre_Nm = Eigen::MatrixX3d::Constant(n, 3, std::numeric_limits<double>::quiet_NaN());
    for (Eigen::Index i = 0; i < n; ++i) {
      const LabFootFrame f = lab_foot_frame(r, side, i);
      p.force_N.row(i) = f.force_N.transpose();
      p.cop_m.row(i) = f.cop_m.transpose();
    }
  }
  return out;
}

}  // namespace kin2grf
