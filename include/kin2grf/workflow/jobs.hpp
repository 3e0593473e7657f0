// kin2grf jobs: what each command of the command line does, from its arguments to its outputs
// (load, resolve the settings, estimate, validate, write, report), in the library so that the
// command line is only its flags. Each writes what it shows on `out` and its notes on `log`.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "kin2grf/validation/validate.hpp"
#include "kin2grf/workflow/settings.hpp"

namespace CLI {
class App;
}

namespace kin2grf {

/// estimate: the settings (the library's names) and where the outputs go.
struct EstimateJob : Settings {
  std::string opensim_dir;
  std::vector<std::string> opensim_bodies;
  std::string out_mot, out_csv, out_json, out_events, out_stances, out_stance_curves, out_report, out_c3d;
  bool lab_frame = false;
};

struct ValidateJob {
  EstimateJob est;
  std::string plates, out_json, report, stance_curves, zero_offset = "unloaded";
  ValidationOptions options;
};

struct StudyJob {
  std::string kind, trial_list, out_json, report, cross_validate;
  std::string criterion = "plate-stance";  ///< --criterion (parse_criterion)
  std::vector<std::string> trials;
  EstimateJob est;
  std::string plates;
};

struct FitCopJob {
  std::string trial_list, activity = "walking", out;
  /// The frames fitted: the plate above this fraction of body weight. validate's COP threshold
  /// (ValidationOptions::cop_min_force_fraction): the function is fitted on the frames its COP is
  /// judged on (0.2 until session 46, which left the heel strike's and push-off's ends to
  /// extrapolation: held out 6.44 -> 6.23 % walking COP, docs/METHOD-NOTES.md).
  double min_force = ValidationOptions{}.cop_min_force_fraction;
  bool leave_one_out = false, fit_angles = false, fit_com = false;
  /// What the fitted fractions count in (CopLength): "heel-mt" (the built-in walking function's)
  /// or "sole" (the paper's).
  std::string length = "heel-mt";
};

struct BatchJob {
  std::string trial_list, out_csv, out_json, out_dir;
  int jobs = 0;  ///< 0: every core
  bool c3d = false;  ///< --c3d: NAME.c3d per trial into out_dir too
};

/// Registers estimate's settings and, with `outputs`, its output options on `app`.
void add_estimate_options(CLI::App* app, EstimateJob& job, bool outputs = true);

/// info: a recording described (text, or JSON with `json`); with `write_mapping`, the mapping made
/// from its labels written there as a mapping file to edit (a "FILL IN" marker for what no label gives).
int info_job(const std::string& file, bool json, double threshold_N, const std::string& zero_offset, const std::string& up_axis,
             std::ostream& out, const std::string& write_mapping = {});
/// estimate: one trial's GRF, COP, GRM and joint torques into the asked outputs.
int estimate_job(const EstimateJob& job, std::ostream& out, std::ostream& log);
/// validate: estimate, then compare with the trial's plates (or --plates).
int validate_job(const ValidateJob& job, std::ostream& out, std::ostream& log);
/// study: a parameter study over trials with plates, optionally cross-validated by lab.
int study_job(const StudyJob& job, std::ostream& out, std::ostream& log);
/// fit-cop: foot model 2's COP function fitted to a trial list's plate COPs.
int fit_cop_job(const FitCopJob& job, std::ostream& out);
/// batch: every trial of a list, on all cores, past failures, into one summary table (1 when
/// any failed).
int batch_job(const BatchJob& job, std::ostream& out, std::ostream& log);
/// make-example: the bundled synthetic walk and squat written into `dir`.
int make_example_job(const std::string& dir, double seconds, double rate_hz, double analog_rate_hz, double noise_mm, std::ostream& out);

}  // namespace kin2grf
