// kin2grf validation: the paper's parameter studies (Sect. 4) on any trials with plates.
//
// A study runs estimate + validate on every trial for each value of one setting and reports the
// mean per-stance rRMSE (vertical, anterior, COP, moment about the plate centre), the mean
// total-GRM rRMSE and the mean |onset|, per activity. Kinds:
//   r             activation parameter r of Eq. 8, 10^1 .. 10^6 N/m (paper: Fig. 7 discussion)
//   ground-shift  the ground moved by -1 cm, 0, +1 cm (paper: robustness to the ground level)
//   cutoff        the post-filter cut-off (paper: 12 Hz)
//   kinematic-cutoff  the marker/coordinate low-pass cut-off (paper: 6 Hz)
//   speed-gate    kin2grf's contact speed gate, off .. 3 m/s (not in the paper)
//   speed-gate-ratio  the gate as a multiple of the progression speed (1 .. 3, floor 0.5 or 0.75 m/s)
//                 against the fixed 1.5 m/s
//   noise         0-3 mm of Gaussian noise on every marker coordinate, 8 seeded draws per level
//                 pooled (robustness)
//   marker-gaps   the heel or the MT markers lost for 0.2 s at every plate stance, the rigid fill
//                 off and on (robustness to occlusions)
//   toe-ablation  each toe marker replaced by virtual toes (a lab whose set has none), then with the
//                 trunk and arm markers removed too (a lower-body clinical set: Plug-in Gait lower
//                 body, Helen-Hayes), then that set's MT markers 15 mm back with 2 mm of marker
//                 noise, 8 draws (a clinical lab's capture)
//   marker-placement  the heel or the MT markers placed 15 mm further back or forward along the
//                 foot (robustness to where a lab puts them: model 2's COP is placed in lengths
//                 between them)
//   plate-export  the plates through a 6 and a 10 Hz zero-lag low-pass, as a filtered GRF export,
//                 timed by the threshold's crossings and by validate's default (its timing, not the
//                 estimate, is what moves)
//   split-distance  kin2grf's side-by-side feet distance, off .. 0.2 m (not in the paper)
//   torso-length  the torso's hip-shoulder length fixed (the paper) or measured per frame
//   kinematic-edges  the kinematics' filter past the window's ends: the odd reflection (the ends'
//                 acceleration read as zero) or the ends' own curvature
//   foot-model    model 1 (three points) against model 2 (moving COP) (paper: Fig. 6)
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kin2grf/trial.hpp"
#include "kin2grf/markers/landmarks.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/validation/validate.hpp"

namespace kin2grf {

/// One trial of a study, loaded, with its own options (mass etc.).
/// A study trial's data, held while it is used: the trial, its static trial and plates, its
/// marker set. Pointers into data the caller keeps, or into `held` (a trial loaded for the use).
struct StudyTrialData {
  const Trial* trial = nullptr;
  const Trial* static_trial = nullptr;
  const ForcePlateRecording* plates = nullptr;
  const MarkerSet* marker_set = nullptr;
  std::shared_ptr<const void> held;  ///< what the pointers point into, when loaded for this use
};

struct StudyTrial {
  std::string name, activity;
  std::string lab;  ///< the recording's lab (or data source): the unit of leave-one-lab-out
  /// The lab, or the trial's own name when none is given (each trial then its own lab).
  [[nodiscard]] const std::string& lab_or_name() const { return lab.empty() ? name : lab; }
  const Trial* trial = nullptr;
  const Trial* static_trial = nullptr;
  const ForcePlateRecording* plates = nullptr;
  const MarkerSet* marker_set = nullptr;
  EstimateOptions options;
  /// When set, the trial is loaded by this each time it is used and let go after, so that a study
  /// of many trials holds one at a time (the pointers above are then unused); InputError naming
  /// the file when it cannot be read or has no plates.
  std::function<StudyTrialData()> load;
  /// The data: load() when set, else the pointers.
  [[nodiscard]] StudyTrialData data() const { return load ? load() : StudyTrialData{trial, static_trial, plates, marker_set, nullptr}; }
};

struct StudyCell {
  std::string activity;
  int trials = 0;
  MeanMetrics per_foot;
  double total_grm = 0.0;  ///< mean over trials with a total window; NaN if none
  int total_trials = 0;
};

struct StudyRow {
  std::string label;  ///< the setting's value as text
  double value = 0.0;
  bool is_default = false;       ///< the setting leaves kin2grf's default options as they are
  std::vector<StudyCell> cells;  ///< per activity, then "all"
};

/// One trial's result at one setting (mean per-stance rRMSE over the trial's plate stances).
struct StudyTrialResult {
  std::string name, activity, lab;
  std::vector<StanceValidation> stances;
  double total_grm = std::numeric_limits<double>::quiet_NaN();
  bool failed = false;
};

/// Leave-one-lab-out choice of the setting (cross_validate()). The criterion a setting is chosen
/// by: per lab, the mean over its stances of (vertical + anterior + COP) / 3 rRMSE; then the mean
/// over the labs, so that each lab weighs the same and all activities are pooled (one default
/// serves every activity, as kin2grf's defaults do). A tie keeps kin2grf's default setting (a
/// default changes only when the figure improves), else the first (lowest) setting.
struct CrossValidation {
  /// The vertical rRMSE the criterion takes: over the plate's stance (the paper's; the default),
  /// or over the loaded span (StanceValidation::vertical_loaded_span: a foot loaded before its
  /// plate's onset or after its offset is counted against the plate's reading there).
  enum class Vertical { PlateStance, LoadedSpan } vertical = Vertical::PlateStance;
  std::string in_sample_choice;                   ///< the setting chosen on every trial
  std::vector<std::pair<std::string, double>> criterion;  ///< per setting, on every trial
  std::vector<std::pair<std::string, std::string>> lab_choice;  ///< held lab -> setting chosen without it
  /// The criterion with each lab at the choice made without it (the figure a default changes by),
  /// and the default setting's on every trial (NaN when no row is the default).
  double held_out_criterion = std::numeric_limits<double>::quiet_NaN();
  double default_criterion = std::numeric_limits<double>::quiet_NaN();
  /// Per activity, then "all": in-sample (every trial at the in-sample choice) and held-out (each
  /// lab's trials at the choice made without that lab), and the worst trial's vertical rRMSE.
  struct Cell {
    std::string activity;
    MeanMetrics in_sample, held_out;
    double in_sample_total_grm = 0, held_out_total_grm = 0;
    std::string worst_trial;  ///< held-out: the trial with the highest mean vertical rRMSE
    double worst_vertical = 0;
  };
  std::vector<Cell> cells;
};

struct StudyResult {
  std::string kind;
  std::vector<StudyRow> rows;
  std::vector<std::vector<StudyTrialResult>> per_trial;  ///< [row][trial]
  std::vector<std::string> failures;  ///< trial + value + error, for runs that threw InputError
};

/// The study kinds run_study takes, in the order the command line lists them.
const std::vector<std::string>& study_kinds();

/// The kinds above; throws InputError for another.
StudyResult run_study(const std::string& kind, const std::vector<StudyTrial>& trials);

/// The marker-placement study's condition: on each foot, the markers of `which`'s rule in `set`
/// (kHeel or kMt) moved by shift_m (+ towards the toes) along the unit vector from the mean of the
/// heel rule's markers to the mean of the MT rule's, frame by frame (frames where either is unseen
/// are left as they are). As if the lab had put them that far along the foot.
void shift_markers_along_foot(MarkerTrajectories& m, const MarkerSet& set, LegLandmark which, double shift_m);

/// Leave-one-lab-out: for each lab, the setting with the lowest criterion on the other labs'
/// trials, scored on that lab's. Needs trials from at least 2 labs (InputError otherwise).
CrossValidation cross_validate(const StudyResult& s, CrossValidation::Vertical vertical = CrossValidation::Vertical::PlateStance);
/// `--criterion` as the user gives it: "plate-stance" or "loaded-span"; InputError otherwise.
CrossValidation::Vertical parse_criterion(const std::string& text);
/// The criterion's name as `--criterion` takes it (and the study JSON's cross_validation_by_criterion keys).
const char* criterion_name(CrossValidation::Vertical vertical);
/// The criterion's three terms as the tables say them: "vertical + anterior + COP", or with the
/// vertical over the loaded span.
const char* criterion_terms(CrossValidation::Vertical vertical);
std::string format_cross_validation(const StudyResult& s, const CrossValidation& cv);
nlohmann::json cross_validation_json(const CrossValidation& cv);

nlohmann::json study_json(const StudyResult& s);
std::string format_study_table(const StudyResult& s);

}  // namespace kin2grf
