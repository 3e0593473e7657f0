// kin2grf settings: what a user chooses for one trial, by the names of the command line, and the
// one translation of them into the library's option structs. The CLI, the trial list of
// `study`/`batch`/`fit-cop` and the Python module all go through here, so that a setting has
// one name, one default and one meaning everywhere.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "kin2grf/io/load.hpp"
#include "kin2grf/pipeline.hpp"

namespace CLI {
class App;
}

namespace kin2grf {

/// One trial's settings as the user gives them (flag names without the dashes; strings where the
/// command line takes a word). Numerical defaults come from EstimateOptions/SolverOptions.
struct Settings {
  std::string trial, static_trial, markers;
  std::optional<double> mass;
  bool force_mass = false, mediolateral = false;
  std::string model = "sagittal";  ///< --model: sagittal or 3d (ModelKind)
  std::string lateral_split = "own-leg", upper_body = "segments", lateral_lag = "torso", lateral_bilateral = "least-squares";
  std::string foot_model = "cop", norm = "torque-scaled", anthropometry = EstimateOptions{}.anthropometry, up_axis,
              cop_function, running_cop = "builtin", torso_length = "measured",
              kinematic_cutoff_rule = "noise";
  /// --kinematic-edges: odd or curvature (EstimateOptions::kinematic_edges)
  std::string kinematic_edges = filter_edge_name(EstimateOptions{}.kinematic_edges);
  /// --rigid-fill: on or off (LandmarkOptions::rigid_fill)
  std::string rigid_fill = "on";
  double r = SolverOptions{}.r_N_per_m, kinematic_cutoff = EstimateOptions{}.kinematic_cutoff_hz,
         post_cutoff_cycles = EstimateOptions{}.post_cutoff_cycles, speed_gate = SpeedGateRule{}.fixed_mps;
  /// The numeric settings that are one option field each (option_table.hpp's rows: flag, range,
  /// --paper value, JSON key), held in their own fields with the library's defaults.
  EstimateOptions numeric;
  bool paper = false, r_given = false, anthropometry_given = false;
  std::optional<double> ground_level;
  std::optional<double> post_cutoff;  ///< given: the post-filter at this fixed cut-off, Hz
  bool post_cutoff_cycles_given = false;
  std::vector<double> grm_reference;
  int max_gap = 10;
  /// --frames FIRST:LAST: the file's frames processed (its own frame numbers, inclusive; an end
  /// left empty is open); empty: every frame.
  std::string frames;
};

/// Registers TRIAL and every setting as options of `app` (the command line's and the trial
/// list's parser; the Python module's keyword arguments are these names with '_' for '-').
void add_settings_options(CLI::App* app, Settings& s);

/// Parses `--name value ...` words (a trial-list line, Python keyword arguments) into `s`, after
/// TRIAL. InputError naming `where` and the option on a bad one.
void parse_settings(const std::vector<std::string>& words, Settings& s, const std::string& where);

/// The resolved options: what --paper and the defaults make of the settings (reads COP function
/// files). Ranges are checked by estimate() (check_options).
EstimateOptions to_options(const Settings& s);

/// The settings a run used, from the resolved options: recorded in every JSON output.
nlohmann::json settings_json(const Settings& s, const EstimateOptions& o);

/// C3D plate offsets by name: "none", "zero" (FORCE_PLATFORM:ZERO) or "unloaded".
LoadOptions load_options(const std::string& zero_offset);
/// "X", "Y", "Z" (either case) or "" (none); InputError otherwise.
std::optional<Axis> parse_axis(const std::string& text);

/// The marker set: `s.markers` (a preset name, a mapping file, or "labels"), else recognised from
/// the trial's markers, else made from its labels (io/marker_labels.hpp; `static_trial`'s labels
/// give the joints whose markers are on it only). `why` says how; `custom` holds a mapping file's
/// or the labels' set.
const MarkerSet& resolve_marker_set(const Settings& s, const Trial& trial, MarkerSet& custom, std::string* why = nullptr,
                                    const Trial* static_trial = nullptr);

/// The files a run with these settings reads (no output may be one of them).
std::vector<std::string> input_files(const Settings& s);

/// The settings' trial and static trial (none when the settings name none).
struct TrialAndStatic {
  Trial trial;
  std::optional<Trial> static_trial;
};

/// Reads the trial (with `load`) and the static trial at the same time, one on each of two
/// threads when thread_count() allows; an error is the trial's first, as when read in turn.
TrialAndStatic load_trial_and_static(const Settings& s, const LoadOptions& load = {});

/// --frames: the trial's markers cut to the file's frames FIRST:LAST (apply to the motion trial, not
/// to the static; the plates are left whole, validate compares the estimate's frames); InputError
/// naming the file, the range and the recording's frames when it is malformed or outside them.
void apply_frame_range(Trial& t, const std::string& range);

/// How `estimate` reads its trial: C3D plates without their samples (C3dReadOptions::
/// plate_samples), since the estimate takes nothing of the plates but the lab's up axis.
LoadOptions estimate_load_options();

/// Resolves the marker set and runs estimate() on `trial` (with its static trial `st`) with
/// `options` (to_options(s), resolved once by the caller, who also records them); the marker
/// set's recognition goes into the result's messages.
EstimateResult estimate_trial(const Settings& s, EstimateOptions options, const Trial& trial, const std::optional<Trial>& st);
/// The same, giving up the trial: its marker samples are released once the landmarks are made
/// (estimate(Trial&&), the memory of long trials).
EstimateResult estimate_trial(const Settings& s, EstimateOptions options, Trial&& trial, const std::optional<Trial>& st);

}  // namespace kin2grf
