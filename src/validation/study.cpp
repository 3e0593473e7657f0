#include "kin2grf/validation/study.hpp"

#include "kin2grf/kinematics/filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <tuple>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/io/marker_labels.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/option_table.hpp"

namespace kin2grf {
namespace {

struct Setting {
  std::string label;
  double value;
  std::function<void(EstimateOptions&)> apply;
  double marker_noise_m = 0.0;  ///< the `noise` study: Gaussian noise added to every marker coordinate
  bool is_default = false;      ///< leaves kin2grf's default options as they are
  bool without_trunk = false;   ///< the `trunk-ablation` study: the trial's trunk and arm markers unused
  double marker_rate_hz = 0.0;  ///< the `marker-rate` study: markers decimated to about this rate (0: as recorded)
  bool from_labels = false;     ///< the `marker-labels` study: the set made from the file's labels, not the trial's preset
  double cut_margin_s = -1.0;   ///< the `trial-cut` study: markers cut to the plates' loaded span and this much around it (< 0: as recorded)
  /// The `marker-gaps` study: these landmarks' markers (LegLandmark) lost for gap_s at the middle
  /// of every plate's loaded run (gap_s 0: as recorded).
  LegLandmark gap_landmark = kHeel;
  double gap_s = 0.0;
  /// The `toe-ablation` study: each hallux made of a marker replaced by virtual toes of this share
  /// of the ankle-MT length (0: as recorded).
  double virtual_toes = 0.0;
  /// The `subject-scale` study: the trial's subject made dynamically similar at this length scale
  /// (dynamically_scaled in trial.hpp; 1: as recorded).
  double body_scale = 1.0;
  /// The `plate-export` study: every plate's forces and moments through a zero-lag low-pass at this
  /// cut-off (Hz; 0: as recorded), as a GRF file exported after filtering has them, and the
  /// stances timed this way.
  double plate_export_hz = 0.0;
  ValidationOptions::Timing timing = ValidationOptions::Timing::Auto;
  /// The `marker-placement` study: each foot's heel or MT markers (placement_landmark) placed this
  /// far along the foot (m, + towards the toes; 0: as recorded), in the trial and its static trial.
  LegLandmark placement_landmark = kMt;
  double placement_shift_m = 0.0;
};

/// Marks the settings that leave the fields `get` reads at kin2grf's defaults (the added marker
/// noise is the study's condition, not a setting: min-kinematic-cycles is studied under noise).
template <class Get>
void mark_default(std::vector<Setting>& settings, Get get) {
  const EstimateOptions defaults;
  for (Setting& s : settings) {
    EstimateOptions o;
    s.apply(o);
    s.is_default = get(o) == get(defaults);
  }
}

/// The post-filter's settings (the `cutoff` and `post-cutoff-cycles` studies' defaults).
std::tuple<double, double> post_filter_setting(const EstimateOptions& o) { return {o.post_cutoff_cycles, o.post_cutoff_hz}; }

/// The `noise` study's realizations per level (seeds 1..8), pooled: one realization of 2 mm noise
/// moved subject01's vertical rRMSE by anything from +0.1 to +2.5 points with the seed, so a
/// single draw measures the seed as much as the method.
constexpr int kNoiseRealizations = 8;

/// Settings over a list of values, labelled by `format` applied to scale x the value (`zero`: the
/// label of 0 when given).
template <class Apply>
std::vector<Setting> value_settings(const std::vector<double>& values, const char* format, double scale, const char* zero,
                                    Apply apply) {
  std::vector<Setting> s;
  char b[48];
  for (double v : values) {
    if (v == 0 && zero) std::snprintf(b, sizeof b, "%s", zero);
    else std::snprintf(b, sizeof b, format, scale * v);
    s.push_back({b, v, [apply, v](EstimateOptions& o) { apply(o, v); }});
  }
  return s;
}

/// A study from its setting's row (option_table.hpp): the row's grid, labels and condition.
std::vector<Setting> grid_settings(const NumericOption& row) {
  auto* field = row.field;
  auto s = value_settings(row.grid, row.label_format, row.label_scale, row.zero_label,
                          [field](EstimateOptions& o, double v) { field(o) = v; });
  for (Setting& c : s) c.marker_noise_m = row.study_marker_noise_m;
  mark_default(s, [field](EstimateOptions o) { return field(o); });
  return s;
}

std::vector<Setting> r_settings() {
  std::vector<Setting> s;
  char b[32];
  for (int e = 2; e <= 12; ++e) {
    const double r = std::pow(10.0, 0.5 * e);
    std::snprintf(b, sizeof b, "%.3g", r);
    s.push_back({b, r, [r](EstimateOptions& o) { o.solver.r_N_per_m = r; }});
  }
  mark_default(s, [](const EstimateOptions& o) { return o.solver.r_N_per_m; });
  return s;
}

std::vector<Setting> cutoff_settings() {
  auto s = value_settings({4.0, 6.0, 8.0, 10.0, 12.0, 15.0, 20.0}, "%.0f Hz", 1.0, nullptr,
                          [](EstimateOptions& o, double f) { o.post_cutoff_cycles = 0, o.post_cutoff_hz = f; });
  mark_default(s, post_filter_setting);
  return s;
}

/// The post-filter per stance (EstimateOptions::post_cutoff_cycles) against the paper's fixed 12 Hz.
std::vector<Setting> post_cutoff_cycles_settings() {
  std::vector<Setting> s{{"fixed 12 Hz", 0, [](EstimateOptions& o) { o.post_cutoff_cycles = 0, o.post_cutoff_hz = 12; }}};
  for (Setting& c : value_settings({3.0, 3.5, 4.0, 5.0, 6.0, 8.0}, "%.1f cycles", 1.0, nullptr,
                                   [](EstimateOptions& o, double v) { o.post_cutoff_cycles = v; }))
    s.push_back(std::move(c));
  mark_default(s, post_filter_setting);
  return s;
}

std::vector<Setting> kinematic_cutoff_settings() {
  auto s = value_settings({4.0, 5.0, 6.0, 8.0, 10.0, 12.0}, "%.0f Hz", 1.0, nullptr,
                          [](EstimateOptions& o, double f) { o.kinematic_cutoff_hz = f; });
  mark_default(s, [](const EstimateOptions& o) { return o.kinematic_cutoff_hz; });
  return s;
}

std::vector<Setting> speed_gate_settings() {
  auto s = value_settings({0.0, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0}, "%.2f m/s", 1.0, "off", [](EstimateOptions& o, double v) {
    o.contact.speed_gate.ratio = 0, o.contact.speed_gate.fixed_mps = v;
  });
  mark_default(s, [](const EstimateOptions& o) { return std::tuple(o.contact.speed_gate.ratio, o.contact.speed_gate.fixed_mps); });
  return s;
}

/// The gate relative to the progression speed, at the default floor, against the fixed 1.5 m/s.
/// The floor is its own study (speed-gate-floor, a row of option_table): crossed with it, a
/// held-out lab whose trials cannot tell the floors apart (every walk and run is faster than
/// them) had the tie broken by the grid's order, not kept at the default.
std::vector<Setting> speed_gate_ratio_settings() {
  std::vector<Setting> s;
  char b[48];
  s.push_back({"fixed 1.50 m/s", 0, [](EstimateOptions& o) { o.contact.speed_gate.ratio = 0, o.contact.speed_gate.fixed_mps = 1.5; }});
  for (double k : {0.5, 0.7, 1.0, 1.5, 2.0, 3.0}) {
    std::snprintf(b, sizeof b, "%.1f x speed", k);
    s.push_back({b, k, [k](EstimateOptions& o) { o.contact.speed_gate.ratio = k; }});
  }
  mark_default(s, [](const EstimateOptions& o) { return std::tuple(o.contact.speed_gate.ratio, o.contact.speed_gate.fixed_mps); });
  return s;
}

/// What the estimate owes to the trunk and arm markers: every trial as recorded, and with the
/// model torso above the pelvis instead (without_trunk_markers); `mediolateral`: with the
/// mediolateral force, the trunk being most of the mass whose lateral acceleration it is.
std::vector<Setting> trunk_ablation_settings(bool mediolateral) {
  auto apply = [mediolateral](EstimateOptions& o) { o.mediolateral = mediolateral || o.mediolateral; };
  return {{"intact", 0, apply, 0.0, true}, {"trunk markers removed", 1, apply, 0.0, false, true}};
}

/// Robustness to what real capture does: 0, 1, 2, 3 mm of Gaussian noise on every marker
/// coordinate, kNoiseRealizations seeded draws per level (the same draws for every run), their
/// stances pooled; the estimate otherwise unchanged.
std::vector<Setting> noise_settings() {
  std::vector<Setting> s;
  char b[32];
  for (double mm : {0.0, 1.0, 2.0, 3.0}) {
    std::snprintf(b, sizeof b, "%.0f mm noise", mm);
    s.push_back({b, mm, [](EstimateOptions&) {}, mm / 1000.0});
  }
  return s;
}

/// A robustness condition's rows: the trial as recorded (the default row, labelled with
/// `recorded_value`), then one row per value, labelled by `format` and given its condition by `mark`.
template <class Mark>
std::vector<Setting> condition_settings(double recorded_value, const std::vector<double>& values, const char* format, Mark mark) {
  std::vector<Setting> s{{"as recorded", recorded_value, [](EstimateOptions&) {}, 0.0, true}};
  for (double v : values) {
    char b[48];
    std::snprintf(b, sizeof b, format, v);
    Setting c{b, v, [](EstimateOptions&) {}};
    mark(c, v);
    s.push_back(std::move(c));
  }
  return s;
}

/// Robustness to the capture rate: every trial's markers as recorded and decimated to about 100,
/// 60 and 50 Hz (every k-th frame, k the whole factor nearest the rate; a trial already at or
/// under a rate keeps its frames), the plates as recorded. Clinical systems capture at 50-120 Hz,
/// the development trials at 60-250 Hz, so a rule that counted frames where it means seconds would
/// show here. `validate` averages the plates over each marker frame, so at a lower rate the
/// plates' impact transient is smoothed in the reference too.
std::vector<Setting> marker_rate_settings() {
  return condition_settings(0.0, {100.0, 60.0, 50.0}, "about %.0f Hz", [](Setting& c, double hz) { c.marker_rate_hz = hz; });
}

/// Robustness to a marker set no preset knows: every trial with its preset (or mapping file) and
/// with the mapping made from its own labels (io/marker_labels.hpp, the static trial's labels
/// included), as a held-out lab with an unknown set gets it. A trial whose labels do not give every
/// landmark fails that row, naming them.
std::vector<Setting> marker_labels_settings() {
  std::vector<Setting> s{{"preset", 0, [](EstimateOptions&) {}, 0.0, true}, {"labels", 1, [](EstimateOptions&) {}}};
  s[1].from_labels = true;
  return s;
}

/// Robustness to a trial cut short (a user's frame range, a capture stopped early): every trial's
/// markers as recorded and cut to its plates' loaded span (any plate's vertical force above 20 N)
/// with 1.0, 0.5, 0.3 and 0.2 s around it. Whatever the method measures from the trial itself
/// (the ground, the foot-flat reference, the progression speed, the filters' edges) then has less
/// of it; a trial whose plates are loaded throughout (a treadmill) keeps its frames.
std::vector<Setting> trial_cut_settings() {
  return condition_settings(-1.0, {1.0, 0.5, 0.3, 0.2}, "plates' span +-%.1f s", [](Setting& c, double m) { c.cut_margin_s = m; });
}

/// Each plate's runs of load (first and last sample's times, s), its load read on its axis of
/// largest force (the vertical: a body weight against shear forces of a fifth of it; the axis is
/// not the file's to say, a GRF .mot is Y up, a C3D mostly Z up, and a drifting shear channel must
/// not count as load) above 20 N. The plate studies' reading of where the plates are loaded.
std::vector<std::pair<double, double>> plate_loaded_runs_s(const ForcePlateRecording& plates) {
  std::vector<std::pair<double, double>> out;
  for (const ForcePlate& p : plates.plates) {
    const Eigen::Index n = std::min(plates.samples(), p.force_N.rows());
    if (n == 0) continue;
    Eigen::Index up = 0;
    p.force_N.topRows(n).cwiseAbs().colwise().maxCoeff().maxCoeff(&up);
    for (const IndexRun& r : runs_where(n, [&](Eigen::Index k) { return std::abs(p.force_N(k, up)) > 20.0; }))
      out.emplace_back(plates.time_s[r.first], plates.time_s[r.last]);
  }
  return out;
}

/// The trial_cut_settings crop: the marker rows within `margin_s` of the plates' loaded span
/// (plate_loaded_runs_s).
MarkerTrajectories cut_to_plates(const MarkerTrajectories& m, const ForcePlateRecording& plates, double margin_s) {
  double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
  for (const auto& [first, last] : plate_loaded_runs_s(plates)) t0 = std::min(t0, first), t1 = std::max(t1, last);
  Eigen::Index a = 0, b = m.frames() - 1;
  if (std::isfinite(t0)) {
    while (a < b && m.time_s[a] < t0 - margin_s) ++a;
    while (b > a && m.time_s[b] > t1 + margin_s) --b;
  }
  return cropped(m, a, b - a + 1);
}

/// What validate's timing makes of a plate filtered before export (validate's step 7,
/// ValidationOptions::Timing): every trial's plates as recorded, and exported through a 6 and a 10
/// Hz zero-lag low-pass (the cut-offs OpenSim's example GRF files and gait pipelines use), the
/// stances timed by the threshold's crossings and as validate does by default. The estimate is the
/// same in every row: what moves is the reference its onsets and offsets are compared with. The
/// plates' COP stays as recorded.
std::vector<Setting> plate_export_settings() {
  std::vector<Setting> s{{"as recorded", 0, [](EstimateOptions&) {}, 0.0, true}};
  for (const double hz : {6.0, 10.0})
    for (const auto timing : {ValidationOptions::Timing::Crossing, ValidationOptions::Timing::Auto}) {
      char b[64];
      std::snprintf(b, sizeof b, "%.0f Hz export, %s", hz, timing == ValidationOptions::Timing::Crossing ? "crossings" : "auto");
      Setting c{b, hz, [](EstimateOptions&) {}};
      c.plate_export_hz = hz;
      c.timing = timing;
      s.push_back(std::move(c));
    }
  return s;
}

/// plate_export_settings' export: each plate's force, moment and free moment columns (those
/// finite throughout) through butterworth_filtfilt at `cutoff_hz`.
ForcePlateRecording exported_plates(ForcePlateRecording rec, double cutoff_hz) {
  for (ForcePlate& p : rec.plates)
    for (Eigen::MatrixX3d* m : {&p.force_N, &p.moment_centre_Nm, &p.free_moment_Nm})
      for (Eigen::Index c = 0; c < m->cols(); ++c)
        if (m->rows() > 0 && m->col(c).allFinite()) m->col(c) = butterworth_filtfilt(Eigen::VectorXd(m->col(c)), rec.rate_hz, cutoff_hz);
  return rec;
}

/// What the COP owes to a toe marker (a lab whose set has none): every trial as recorded, and with
/// each hallux landmark made of a marker replaced by the presets' virtual toes (kVirtualToeShare of
/// the ankle-MT length). Trials whose sets have virtual toes already are the same in both rows.
/// A third row removes the trunk and arm markers too (without_trunk_markers); a fourth adds the MT
/// markers placed 15 mm back and 2 mm of marker noise (kNoiseRealizations draws).
std::vector<Setting> toe_ablation_settings() {
  std::vector<Setting> s{{"as recorded", 0, [](EstimateOptions&) {}, 0.0, true}};
  Setting c{"toe markers removed", 1, [](EstimateOptions&) {}};
  c.virtual_toes = kVirtualToeShare;
  s.push_back(c);
  // The sets the held-out labs use most (lower-body Plug-in Gait, Helen-Hayes): no trunk, arm or
  // toe markers. Both ablations at once, since their costs need not add up.
  Setting lower{"lower body, virtual toes", 2, [](EstimateOptions&) {}};
  lower.virtual_toes = kVirtualToeShare;
  lower.without_trunk = true;
  // A clinical lab's capture of that set, all at once: Plug-in Gait's and Helen-Hayes' TOE marker
  // stands over the second MT head on the midfoot side of the toes' break, so about a marker's
  // diameter behind where these labs put their MT markers, and markers as noisy as the noise
  // study's. Each costs a point or less alone; this row measures whether they add up.
  Setting clinical = lower;
  clinical.label = "lower body, MT 15 mm back, 2 mm noise";
  clinical.value = 3;
  s.push_back(std::move(lower));
  clinical.placement_landmark = kMt;
  clinical.placement_shift_m = -0.015;
  clinical.marker_noise_m = 0.002;
  s.push_back(std::move(clinical));
  return s;
}

/// Robustness to the subject's size: every trial as recorded and its subject made dynamically
/// similar at 0.6, 0.8 and 1.2 times its size (Froude similarity: lengths times L, times times
/// sqrt(L), the mass and so the plates' forces times L^3; dynamically_scaled in trial.hpp), the
/// validation's own lengths, forces and speeds scaled alike. The true ground reactions in body
/// weights are the same gait's, so a method all of whose rules scale with the subject scores the
/// same in every row; what changes is owed to a rule in metres, newtons, m/s or hertz that does
/// not (0.6: a child of about 1.05 m, faster in cadence by 1.29; 1.2: a tall adult). The markers'
/// own noise scales with them here, where a real child's markers would be as noisy as an adult's.
std::vector<Setting> subject_scale_settings() {
  return condition_settings(1.0, {0.6, 0.8, 1.2}, "subject x %.1f", [](Setting& c, double L) { c.body_scale = L; });
}

/// The validation's lengths, forces and speeds for a subject dynamically scaled by L (the
/// subject-scale study), so that only the estimate's own rules can change the figures.
ValidationOptions scaled_validation(double L) {
  ValidationOptions v;
  const double force = L * L * L;
  v.threshold_N *= force;
  v.max_assign_distance_m *= L;
  v.max_cop_beyond_foot_m *= L;
  v.ground_contact_height_m *= L;
  v.edge_margin_m *= L;
  v.still_speed_mps *= std::sqrt(L);
  return v;
}

/// Robustness to markers lost for a while (occluded by the other foot over a plate, a marker
/// fallen off): the heel markers, then the MT markers, of both feet lost for 0.2 s at the middle
/// of every plate's loaded run, with the rigid fill off (the gap ends the processed window, as
/// before session 37) and on (LandmarkOptions::rigid_fill). A trial whose window keeps no plate
/// stance counts none in that row (the row's stance count says how many were kept).
std::vector<Setting> marker_gaps_settings() {
  std::vector<Setting> s{{"as recorded", 0, [](EstimateOptions&) {}, 0.0, true}};
  for (const LegLandmark which : {kHeel, kMt})
    for (const bool fill : {false, true}) {
      Setting c{std::string(which == kHeel ? "heels" : "MT heads") + " lost 0.2 s, rigid fill " + (fill ? "on" : "off"),
                static_cast<double>(s.size()), [fill](EstimateOptions& o) { o.landmarks.rigid_fill = fill; }};
      c.gap_landmark = which, c.gap_s = 0.2;
      s.push_back(std::move(c));
    }
  return s;
}

/// Robustness to where a lab puts the foot's markers: the heel markers, then the MT markers, of
/// both feet placed kPlacementShiftM further back and further forward along the foot (the line
/// from the heel markers to the MT markers) in every frame of the trial and of its static trial.
/// Model 2 places the COP in lengths measured between these markers (the heel point A, the MT
/// head B), so their placement is the foot's geometry to it; a rule that leans on one of them
/// shows it here. 15 mm is about a marker's diameter: a palpation of the calcaneus or of a
/// metatarsal head a little off, or a lab's habit (Plug-in Gait's TOE "on the mid-foot side" of
/// the 2nd MT head or on it).
constexpr double kPlacementShiftM = 0.015;
std::vector<Setting> marker_placement_settings() {
  std::vector<Setting> s{{"as recorded", 0, [](EstimateOptions&) {}, 0.0, true}};
  for (const LegLandmark which : {kHeel, kMt})
    for (const double shift : {-kPlacementShiftM, kPlacementShiftM}) {
      char b[64];
      std::snprintf(b, sizeof b, "%s %.0f mm %s", which == kHeel ? "heels" : "MT heads", 1000 * kPlacementShiftM,
                    shift < 0 ? "back" : "forward");
      Setting c{b, static_cast<double>(s.size()), [](EstimateOptions&) {}};
      c.placement_landmark = which, c.placement_shift_m = shift;
      s.push_back(std::move(c));
    }
  return s;
}

}  // namespace

/// A rule of several markers (a mean) moves by the same vector; the direction is taken from the
/// positions before the move.
void shift_markers_along_foot(MarkerTrajectories& m, const MarkerSet& set, LegLandmark which, double shift_m) {
  for (int side = 0; side < 2; ++side) {
    const auto& heel = set.rules[static_cast<std::size_t>(landmark(side, kHeel))].markers;
    const auto& mt = set.rules[static_cast<std::size_t>(landmark(side, kMt))].markers;
    const auto& moved = set.rules[static_cast<std::size_t>(landmark(side, which))].markers;
    auto indices = [&](const std::vector<std::string>& names) {
      std::vector<int> k;
      for (const std::string& name : names)
        if (const int i = m.find(name); i >= 0) k.push_back(i);
      return k;
    };
    const std::vector<int> h = indices(heel), t = indices(mt), mv = indices(moved);
    if (h.empty() || t.empty()) continue;
    auto mean = [&](const std::vector<int>& k, Eigen::Index i) {
      Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
      for (int j : k) sum += m.positions_m[static_cast<std::size_t>(j)].row(i);
      return Eigen::RowVector3d(sum / static_cast<double>(k.size()));
    };
    for (Eigen::Index i = 0; i < m.frames(); ++i) {
      const Eigen::RowVector3d u = mean(t, i) - mean(h, i);
      const double len = u.norm();
      if (!std::isfinite(len) || len <= 0) continue;
      const Eigen::RowVector3d d = shift_m / len * u;
      for (int j : mv) m.positions_m[static_cast<std::size_t>(j)].row(i) += d;
    }
  }
}

namespace {

/// marker_gaps_settings' gaps: `names` lost (NaN) within gap_s / 2 of the middle of each of the
/// plates' loaded runs (plate_loaded_runs_s) that lasts a stance's kMinStanceS at least (shorter:
/// a noisy channel's crossings, not a stance).
constexpr double kMinStanceS = 0.1;
void lose_markers_at_plate_stances(MarkerTrajectories& m, const ForcePlateRecording& plates, const std::vector<std::string>& names,
                                   double gap_s) {
  for (const auto& [first, last] : plate_loaded_runs_s(plates)) {
    if (last - first < kMinStanceS) continue;
    const double mid = 0.5 * (first + last);
    for (const std::string& name : names) {
      const int idx = m.find(name);
      if (idx < 0) continue;
      auto& P = m.positions_m[static_cast<std::size_t>(idx)];
      for (Eigen::Index i = 0; i < P.rows(); ++i)
        if (std::abs(m.time_s[i] - mid) < 0.5 * gap_s) P.row(i).setConstant(std::numeric_limits<double>::quiet_NaN());
    }
  }
}

std::vector<Setting> torso_length_settings() {
  std::vector<Setting> s{{"fixed (the paper)", 0, [](EstimateOptions& o) { o.torso_length = TorsoLength::Fixed; }},
                         {"measured", 1, [](EstimateOptions& o) { o.torso_length = TorsoLength::Measured; }}};
  mark_default(s, [](const EstimateOptions& o) { return o.torso_length; });
  return s;
}

std::vector<Setting> kinematic_edges_settings() {
  std::vector<Setting> s{{"odd reflection (the paper)", 0, [](EstimateOptions& o) { o.kinematic_edges = FilterEdge::OddReflection; }},
                         {"curvature", 1, [](EstimateOptions& o) { o.kinematic_edges = FilterEdge::Curvature; }}};
  mark_default(s, [](const EstimateOptions& o) { return o.kinematic_edges; });
  return s;
}

std::vector<Setting> foot_model_settings() {
  std::vector<Setting> s{{"three-point (model 1)", 1, [](EstimateOptions& o) { o.contact.foot_model = FootModel::ThreePoint; }},
                         {"cop (model 2)", 2, [](EstimateOptions& o) { o.contact.foot_model = FootModel::Cop; }}};
  mark_default(s, [](const EstimateOptions& o) { return o.contact.foot_model; });
  return s;
}

/// The studies that are not one numeric setting's grid, in the command line's order; the
/// numeric settings' own studies (numeric_options() rows with a grid) are listed by study_kinds().
struct StudyKind {
  const char* name;
  std::vector<Setting> (*settings)();
};
const std::vector<StudyKind>& special_studies() {
  static const std::vector<StudyKind> kinds{
      {"r", r_settings},
      {"cutoff", cutoff_settings},
      {"post-cutoff-cycles", post_cutoff_cycles_settings},
      {"kinematic-cutoff", kinematic_cutoff_settings},
      {"speed-gate", speed_gate_settings},
      {"speed-gate-ratio", speed_gate_ratio_settings},
      {"trunk-ablation", [] { return trunk_ablation_settings(false); }},
      {"mediolateral-ablation", [] { return trunk_ablation_settings(true); }},
      {"noise", noise_settings},
      {"marker-rate", marker_rate_settings},
      {"marker-labels", marker_labels_settings},
      {"trial-cut", trial_cut_settings},
      {"marker-gaps", marker_gaps_settings},
      {"toe-ablation", toe_ablation_settings},
      {"marker-placement", marker_placement_settings},
      {"plate-export", plate_export_settings},
      {"subject-scale", subject_scale_settings},
      {"torso-length", torso_length_settings},
      {"kinematic-edges", kinematic_edges_settings},
      {"foot-model", foot_model_settings},
  };
  return kinds;
}

std::vector<Setting> settings_for(const std::string& kind) {
  for (const StudyKind& k : special_studies())
    if (kind == k.name) return k.settings();
  if (const NumericOption* row = find_numeric_option(kind.c_str()); row && !row->grid.empty()) return grid_settings(*row);
  std::string kinds;
  for (const auto& k : study_kinds()) kinds += (kinds.empty() ? "" : ", ") + k;
  throw InputError("unknown study '" + kind + "' (" + kinds + ")");
}

/// Pool the stances of one activity ("all": every trial) over the trials that ran.
StudyCell pool(const std::vector<StudyTrialResult>& trials, const std::string& activity) {
  StudyCell c;
  c.activity = activity;
  std::vector<StanceValidation> stances;
  double sum = 0;
  for (const auto& t : trials) {
    if ((activity != "all" && t.activity != activity) || t.failed) continue;
    ++c.trials;
    stances.insert(stances.end(), t.stances.begin(), t.stances.end());
    if (std::isfinite(t.total_grm)) sum += t.total_grm, ++c.total_trials;
  }
  c.per_foot = mean_rrmse(stances);
  c.total_grm = c.total_trials ? sum / c.total_trials : std::numeric_limits<double>::quiet_NaN();
  return c;
}

}  // namespace

const std::vector<std::string>& study_kinds() {
  static const std::vector<std::string> kinds = [] {
    std::vector<std::string> k;
    for (const StudyKind& s : special_studies()) k.emplace_back(s.name);
    for (const NumericOption& row : numeric_options())
      if (!row.grid.empty()) k.emplace_back(row.flag);
    return k;
  }();
  return kinds;
}

namespace {

/// One trial at one setting.
StudyTrialResult run_setting(const StudyTrial& t, const StudyTrialData& d, const Setting& s, std::string& failure) {
  StudyTrialResult tr{t.name, t.activity, t.lab_or_name(), {}, std::numeric_limits<double>::quiet_NaN(), false};
  EstimateOptions o = t.options;
  s.apply(o);
  try {
    const int draws = s.marker_noise_m > 0 ? kNoiseRealizations : 1;
    double grm_sum = 0;
    int grm_n = 0;
    // The marker set (the trial's, its trunk ablated, or made from its labels) and the capture
    // rate are the trial's, the same for every draw of noise.
    std::optional<MarkerSet> ablated;
    if (s.without_trunk) {
      std::string why;
      ablated = without_trunk_markers(*d.marker_set, why);
      if (!ablated) throw InputError(why);
    }
    if (s.from_labels) {
      const LabelMapping lm = map_marker_labels(d.trial->markers, d.static_trial ? &d.static_trial->markers : nullptr);
      if (!lm.mapping) {
        std::string missing;
        for (const auto& x : lm.missing) missing += (missing.empty() ? "" : "; ") + x;
        throw InputError(t.name + ": its labels give no mapping: " + missing);
      }
      ablated = parse_marker_set(*lm.mapping, t.name + " (its labels)");
    }
    if (s.virtual_toes > 0) {
      MarkerSet toeless = ablated ? *ablated : *d.marker_set;
      for (int side = 0; side < 2; ++side) {
        LandmarkRule& r = toeless.rules[static_cast<std::size_t>(landmark(side, kHallux))];
        if (r.kind == RuleKind::VirtualHallux) continue;
        r = LandmarkRule{};
        r.kind = RuleKind::VirtualHallux;
        r.value = s.virtual_toes;
      }
      ablated = std::move(toeless);
    }
    const int factor = s.marker_rate_hz > 0 ? decimation_factor(d.trial->markers.rate_hz, s.marker_rate_hz) : 1;
    const bool scaled = s.body_scale != 1.0;
    const bool placed = s.placement_shift_m != 0.0;
    const bool changed = s.marker_noise_m > 0 || factor > 1 || s.cut_margin_s >= 0 || s.gap_s > 0 || scaled || placed;
    // A dynamically similar subject: its static trial, plates, mass and floor scaled with it.
    std::optional<Trial> scaled_static;
    std::optional<ForcePlateRecording> scaled_plates;
    ValidationOptions vo;
    if (scaled) {
      const double L = s.body_scale;
      if (d.static_trial) scaled_static = dynamically_scaled(*d.static_trial, L);
      scaled_plates = dynamically_scaled(*d.plates, L);
      if (o.mass_kg) *o.mass_kg *= L * L * L;
      if (o.ground_level_m) *o.ground_level_m *= L;
      o.allow_unusual_mass = true;  // a 47.5 kg subject at 0.6 weighs 10 kg
      vo = scaled_validation(L);
    }
    if (s.plate_export_hz > 0) scaled_plates = exported_plates(*d.plates, s.plate_export_hz);
    vo.timing = s.timing;
    if (placed && d.static_trial) {
      // The markers stand where the lab put them in the static trial too.
      if (!scaled_static) scaled_static = *d.static_trial;
      shift_markers_along_foot(scaled_static->markers, ablated ? *ablated : *d.marker_set, s.placement_landmark, s.placement_shift_m);
    }
    const Trial* static_trial = scaled_static ? &*scaled_static : d.static_trial;
    const ForcePlateRecording& plates = scaled_plates ? *scaled_plates : *d.plates;
    for (int seed = 1; seed <= draws; ++seed) {
      // The trial as recorded, or a copy cut short or with the setting's noise or capture rate.
      Trial working;
      if (changed) {
        working = scaled ? dynamically_scaled(*d.trial, s.body_scale) : *d.trial;
        if (s.cut_margin_s >= 0) working.markers = cut_to_plates(working.markers, *d.plates, s.cut_margin_s);
        if (s.gap_s > 0) {
          const MarkerSet& set = ablated ? *ablated : *d.marker_set;
          std::vector<std::string> names;
          for (int side = 0; side < 2; ++side)
            for (const std::string& name : set.rules[static_cast<std::size_t>(landmark(side, s.gap_landmark))].markers) names.push_back(name);
          lose_markers_at_plate_stances(working.markers, *d.plates, names, s.gap_s);
        }
        if (placed) shift_markers_along_foot(working.markers, ablated ? *ablated : *d.marker_set, s.placement_landmark, s.placement_shift_m);
        if (factor > 1) working.markers = decimated(std::move(working.markers), factor);
        if (s.marker_noise_m > 0) add_marker_noise(working.markers, s.marker_noise_m, static_cast<unsigned>(seed));
      }
      const EstimateResult e = estimate(changed ? working : *d.trial, static_trial, ablated ? *ablated : *d.marker_set, o);
      const ValidationResult v = validate(e, plates, vo);
      tr.stances.insert(tr.stances.end(), v.stances.begin(), v.stances.end());
      if (v.total && v.total->metrics.moment) grm_sum += v.total->metrics.moment->rrmse_percent, ++grm_n;
    }
    if (grm_n > 0) tr.total_grm = grm_sum / grm_n;
  } catch (const InputError& err) {
    tr.failed = true;
    tr.stances.clear();
    failure = t.name + " at " + s.label + ": " + err.what();
  }
  return tr;
}

}  // namespace

StudyResult run_study(const std::string& kind, const std::vector<StudyTrial>& trials) {
  StudyResult res;
  res.kind = kind;
  std::vector<std::string> activities;
  for (const auto& t : trials)
    if (std::find(activities.begin(), activities.end(), t.activity) == activities.end()) activities.push_back(t.activity);
  if (activities.size() > 1) activities.push_back("all");
  const std::vector<Setting> settings = settings_for(kind);
  // Trial by trial, every setting on each: a trial is loaded once and let go before the next
  // (a study of many long trials holds one at a time). A trial that cannot be loaded ends the
  // study, naming its file; one that fails at a setting is that setting's failure.
  res.per_trial.assign(settings.size(), {});
  std::vector<std::vector<std::string>> failures(settings.size());
  for (const auto& t : trials) {
    const StudyTrialData d = t.data();
    for (std::size_t k = 0; k < settings.size(); ++k) {
      std::string failure;
      res.per_trial[k].push_back(run_setting(t, d, settings[k], failure));
      if (!failure.empty()) failures[k].push_back(std::move(failure));
    }
  }
  for (std::size_t k = 0; k < settings.size(); ++k) {
    StudyRow row;
    row.label = settings[k].label;
    row.value = settings[k].value;
    row.is_default = settings[k].is_default;
    for (const auto& a : activities) row.cells.push_back(pool(res.per_trial[k], a));
    res.rows.push_back(std::move(row));
    res.failures.insert(res.failures.end(), failures[k].begin(), failures[k].end());
  }
  return res;
}

CrossValidation::Vertical parse_criterion(const std::string& text) {
  for (const auto v : {CrossValidation::Vertical::PlateStance, CrossValidation::Vertical::LoadedSpan})
    if (text == criterion_name(v)) return v;
  throw InputError("--criterion " + text + ": give plate-stance or loaded-span");
}

const char* criterion_name(CrossValidation::Vertical vertical) {
  return vertical == CrossValidation::Vertical::LoadedSpan ? "loaded-span" : "plate-stance";
}

const char* criterion_terms(CrossValidation::Vertical vertical) {
  return vertical == CrossValidation::Vertical::LoadedSpan ? "vertical over the loaded span + anterior + COP" : "vertical + anterior + COP";
}

CrossValidation cross_validate(const StudyResult& s, CrossValidation::Vertical vertical) {
  if (s.per_trial.empty() || s.per_trial.front().empty()) throw InputError("cross-validation: the study has no trials");
  const auto& first = s.per_trial.front();
  std::vector<std::string> labs, activities;
  for (const auto& t : first) {
    if (std::find(labs.begin(), labs.end(), t.lab) == labs.end()) labs.push_back(t.lab);
    if (std::find(activities.begin(), activities.end(), t.activity) == activities.end()) activities.push_back(t.activity);
  }
  if (labs.size() < 2) throw InputError("cross-validation: the trials come from one lab; give each trial its lab (trial list: activity|lab|name|TRIAL)");
  if (activities.size() > 1) activities.push_back("all");
  // The criterion over the trials of `trials` that `use` accepts (criterion: those of setting r);
  // NaN when a trial failed (a setting that breaks a trial is never chosen) or none has a stance.
  auto criterion_of = [&](const std::vector<StudyTrialResult>& trials, const std::function<bool(const StudyTrialResult&)>& use) {
    // Each lab weighs the same, whatever its number of stances (a 30 s treadmill run has 80).
    double score = 0;
    int nlabs = 0;
    for (const auto& lab : labs) {
      std::vector<StanceValidation> st;
      for (const auto& t : trials)
        if (t.lab == lab && use(t)) {
          if (t.failed) return std::numeric_limits<double>::quiet_NaN();
          st.insert(st.end(), t.stances.begin(), t.stances.end());
        }
      if (st.empty()) continue;
      const MeanMetrics m = mean_rrmse(st);
      score += ((vertical == CrossValidation::Vertical::LoadedSpan ? m.vertical_loaded_span : m.vertical) + m.anterior + m.cop) / 3.0, ++nlabs;
    }
    return nlabs ? score / nlabs : std::numeric_limits<double>::quiet_NaN();
  };
  auto criterion = [&](std::size_t r, const std::function<bool(const StudyTrialResult&)>& use) { return criterion_of(s.per_trial[r], use); };
  // The lowest criterion; a tie keeps kin2grf's default (a default changes only when the figure
  // improves: labs on which the setting changes nothing, e.g. the split distance on trials where
  // the feet are never side by side, carry no evidence against it), else the first (lowest) setting.
  auto choose = [&](const std::function<bool(const StudyTrialResult&)>& use) {
    std::size_t best = 0;
    double best_score = std::numeric_limits<double>::infinity();
    std::vector<double> score(s.per_trial.size());
    for (std::size_t r = 0; r < s.per_trial.size(); ++r) {
      score[r] = criterion(r, use);
      if (score[r] < best_score - 1e-9) best_score = score[r], best = r;  // NaN never wins
    }
    for (std::size_t r = 0; r < s.per_trial.size(); ++r)
      if (s.rows[r].is_default && score[r] <= best_score + 1e-9) return r;
    return best;
  };
  CrossValidation cv;
  cv.vertical = vertical;
  for (std::size_t r = 0; r < s.per_trial.size(); ++r)
    cv.criterion.emplace_back(s.rows[r].label, criterion(r, [](const StudyTrialResult&) { return true; }));
  const std::size_t all = choose([](const StudyTrialResult&) { return true; });
  cv.in_sample_choice = s.rows[all].label;
  // Each trial's held-out result: its lab's choice made on the other labs.
  std::vector<StudyTrialResult> held;
  for (const auto& lab : labs) {
    const std::size_t r = choose([&](const StudyTrialResult& t) { return t.lab != lab; });
    cv.lab_choice.emplace_back(lab, s.rows[r].label);
    for (const auto& t : s.per_trial[r])
      if (t.lab == lab) held.push_back(t);
  }
  // The figure a default changes by: each lab at the choice made without it, against the default.
  cv.held_out_criterion = criterion_of(held, [](const StudyTrialResult&) { return true; });
  for (std::size_t r = 0; r < s.rows.size() && r < cv.criterion.size(); ++r)
    if (s.rows[r].is_default) cv.default_criterion = cv.criterion[r].second;
  for (const auto& a : activities) {
    CrossValidation::Cell c;
    c.activity = a;
    const StudyCell in = pool(s.per_trial[all], a);
    const StudyCell out = pool(held, a);
    c.in_sample = in.per_foot, c.in_sample_total_grm = in.total_grm;
    c.held_out = out.per_foot, c.held_out_total_grm = out.total_grm;
    c.worst_vertical = -1;
    for (const auto& t : held) {
      if (a != "all" && t.activity != a) continue;
      if (t.stances.empty()) continue;
      const double v = mean_rrmse(t.stances).vertical;
      if (v > c.worst_vertical) c.worst_vertical = v, c.worst_trial = t.name;
    }
    cv.cells.push_back(c);
  }
  return cv;
}

std::string format_cross_validation(const StudyResult& s, const CrossValidation& cv) {
  std::ostringstream os;
  char b[256];
  os << "\nleave-one-lab-out (" << s.kind << "): chosen on all trials: " << cv.in_sample_choice << "\n";
  for (const auto& [lab, choice] : cv.lab_choice) os << "  without " << lab << ": " << choice << "\n";
  os << "criterion on all trials (mean over labs of (" << criterion_terms(cv.vertical) << ") / 3, %):";
  for (std::size_t r = 0; r < cv.criterion.size(); ++r) {  // one entry per row of the study, in its order
    const auto& [label, c] = cv.criterion[r];
    std::snprintf(b, sizeof b, " %s%s %.2f;", label.c_str(), r < s.rows.size() && s.rows[r].is_default ? " (default)" : "", c);
    os << b;
  }
  os << "\n";
  if (std::isfinite(cv.held_out_criterion)) {
    std::snprintf(b, sizeof b, "held-out criterion (each lab at the choice made without it): %.3f %%", cv.held_out_criterion);
    os << b;
    if (std::isfinite(cv.default_criterion)) {
      std::snprintf(b, sizeof b, "; kin2grf's default on every lab: %.3f %%", cv.default_criterion);
      os << b;
    }
    os << "\n";
  }
  std::snprintf(b, sizeof b, "%-14s %-10s %9s %9s %9s %10s %10s %9s   %s\n", "activity", "", "vertical", "anterior", "COP", "total GRM",
                "|onset| ms", "span", "worst trial (vertical)");
  os << b;
  auto tot = [](double x) {
    char t[32];
    std::snprintf(t, sizeof t, std::isfinite(x) ? "%.1f" : "-", x);
    return std::string(t);
  };
  for (const auto& c : cv.cells) {
    std::snprintf(b, sizeof b, "%-14s %-10s %9.1f %9.1f %9.1f %10s %10s %9s\n", c.activity.c_str(), "in-sample", c.in_sample.vertical,
                  c.in_sample.anterior, c.in_sample.cop, tot(c.in_sample_total_grm).c_str(), tot(c.in_sample.onset_abs_ms).c_str(),
                  tot(c.in_sample.vertical_loaded_span).c_str());
    os << b;
    std::snprintf(b, sizeof b, "%-14s %-10s %9.1f %9.1f %9.1f %10s %10s %9s   %s %.1f\n", "", "held-out", c.held_out.vertical,
                  c.held_out.anterior, c.held_out.cop, tot(c.held_out_total_grm).c_str(), tot(c.held_out.onset_abs_ms).c_str(),
                  tot(c.held_out.vertical_loaded_span).c_str(), c.worst_trial.c_str(), c.worst_vertical);
    os << b;
  }
  return os.str();
}

nlohmann::json cross_validation_json(const CrossValidation& cv) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  auto metrics = [&](const MeanMetrics& m, double grm) {
    return nlohmann::json{{"stances", m.n},   {"vertical", num(m.vertical)}, {"anterior", num(m.anterior)},
                          {"cop", num(m.cop)}, {"total_grm", num(grm)},      {"onset_abs_ms", num(m.onset_abs_ms)},
                          {"vertical_loaded_span", num(m.vertical_loaded_span)}};
  };
  nlohmann::json j;
  j["criterion"] = std::string("mean over labs of the lab's mean per-stance (") + criterion_terms(cv.vertical) +
                   ") / 3 rRMSE, all activities pooled";
  j["in_sample_choice"] = cv.in_sample_choice;
  for (const auto& [label, c] : cv.criterion) j["criterion_all_trials"][label] = num(c);
  j["criterion_held_out"] = num(cv.held_out_criterion);
  j["criterion_default"] = num(cv.default_criterion);
  for (const auto& [lab, choice] : cv.lab_choice) j["choice_without_lab"][lab] = choice;
  for (const auto& c : cv.cells)
    j["activities"][c.activity] = {{"in_sample", metrics(c.in_sample, c.in_sample_total_grm)},
                                   {"held_out", metrics(c.held_out, c.held_out_total_grm)},
                                   {"worst_trial", {{"name", c.worst_trial}, {"vertical", num(c.worst_vertical)}}}};
  return j;
}

nlohmann::json study_json(const StudyResult& s) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["study"] = s.kind;
  j["rows"] = nlohmann::json::array();
  for (const auto& r : s.rows) {
    nlohmann::json row = {{"setting", r.label}, {"value", r.value}, {"default", r.is_default}};
    for (const auto& c : r.cells)
      row["activities"][c.activity] = {{"trials", c.trials},
                                       {"stances", c.per_foot.n},
                                       {"onset_abs_ms", num(c.per_foot.onset_abs_ms)},
                                       {"rrmse_percent",
                                        {{"vertical", num(c.per_foot.vertical)},
                                         {"vertical_loaded_span", num(c.per_foot.vertical_loaded_span)},
                                         {"anterior", num(c.per_foot.anterior)},
                                         {"cop", num(c.per_foot.cop)},
                                         {"moment", num(c.per_foot.moment)},
                                         {"total_grm", num(c.total_grm)}}}};
    j["rows"].push_back(row);
  }
  j["failures"] = s.failures;
  return j;
}

std::string format_study_table(const StudyResult& s) {
  std::ostringstream os;
  char b[256];
  os << "kin2grf study " << s.kind << ": mean rRMSE % over the plate stances (per foot) and over the trials (total GRM)\n";
  if (s.rows.empty()) return os.str();
  // The settings' column as wide as its longest label (at least 24), so the figures stay in columns.
  int width = 24;
  for (const auto& r : s.rows) width = std::max(width, static_cast<int>(std::min<std::size_t>(r.label.size(), 100)));
  for (std::size_t a = 0; a < s.rows.front().cells.size(); ++a) {
    const auto& c0 = s.rows.front().cells[a];
    std::snprintf(b, sizeof b, "\n%s (%d trials, %d stances)\n%-*s %9s %9s %9s %9s %10s %12s\n", c0.activity.c_str(), c0.trials,
                  c0.per_foot.n, width, "setting", "vertical", "anterior", "COP", "moment", "total GRM", "|onset| ms");
    os << b;
    for (const auto& r : s.rows) {
      const auto& c = r.cells[a];
      std::snprintf(b, sizeof b, "%-*s %9.1f %9.1f %9.1f %9.1f", width, r.label.c_str(), c.per_foot.vertical, c.per_foot.anterior,
                    c.per_foot.cop, c.per_foot.moment);
      os << b;
      // No trial with a total window (validate says why): a dash, not "nan".
      if (std::isfinite(c.total_grm)) std::snprintf(b, sizeof b, " %10.1f", c.total_grm);
      else std::snprintf(b, sizeof b, " %10s", "-");
      os << b;
      // The mean |onset| over the stances that have one (validate's timing).
      if (std::isfinite(c.per_foot.onset_abs_ms)) std::snprintf(b, sizeof b, " %12.0f", c.per_foot.onset_abs_ms);
      else std::snprintf(b, sizeof b, " %12s", "-");
      os << b;
      // With --mediolateral: its rRMSE and RMSE in % body weight, and the lateral COP's RMSE.
      if (std::isfinite(c.per_foot.lateral_rmse_percent_bw)) {
        std::snprintf(b, sizeof b, "   mediolateral %.1f %% (%.1f %% BW), lateral COP %.0f mm", c.per_foot.lateral,
                      c.per_foot.lateral_rmse_percent_bw, c.per_foot.cop_lateral_rmse_mm);
        os << b;
      }
      os << "\n";
    }
  }
  for (const auto& f : s.failures) os << "failed: " << f << "\n";
  return os.str();
}

}  // namespace kin2grf
