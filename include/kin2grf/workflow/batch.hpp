// kin2grf batches: every trial of a trial list, estimated (and validated where it has plates),
// on all cores, past failing trials, into one summary table.
//
// Each trial is independent: a worker thread takes the next trial of the list, loads it, runs
// estimate_trial() and, when the trial (or its --plates file) has force plates, validate(). A
// trial's error ends that trial only; its message goes into its row. Rows come back in the
// list's order whatever the order they finish in, so a batch's table does not depend on --jobs.
#pragma once

#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kin2grf/validation/validate.hpp"
#include "kin2grf/workflow/trial_list.hpp"

namespace kin2grf {

struct BatchRow {
  std::string activity, lab, name, trial;
  bool ok = false;
  std::string error;           ///< why the trial failed (ok == false)
  long frames = 0;             ///< frames processed
  double duration_s = 0;       ///< of the processed window
  double seconds = 0;          ///< wall time of the trial (load, estimate, validate, outputs)
  double mass_kg = 0;
  std::string marker_set;
  bool validated = false;      ///< it had plates and was compared with them
  /// Means over the validated stances (per foot) of the rRMSE, %; NaN when not validated.
  int stances = 0;
  double vertical = std::numeric_limits<double>::quiet_NaN(), anterior = vertical, cop = vertical, moment = vertical;
  double total_vertical = vertical, total_grm = vertical;  ///< whole-body comparison, %
  double cop_mm = vertical;  ///< the COP's RMSE along progression, mm (MeanMetrics::cop_rmse_mm)
  /// With the lateral force (--mediolateral, --model 3d; NaN otherwise): the per-foot lateral
  /// force's mean rRMSE (%) and the lateral COP's mean RMSE (mm); with --model 3d the knee
  /// adduction moment's mean rRMSE (%), estimate-driven against plate-driven.
  double lateral = vertical, cop_lateral_mm = vertical, knee_adduction = vertical;
  std::vector<std::string> messages;  ///< the estimate's notes and the readers' warnings
  std::vector<std::string> outputs;   ///< files written (BatchOptions::out_dir)
};

struct BatchOptions {
  int jobs = 1;                  ///< worker threads (>= 1)
  std::string out_dir;           ///< when set: NAME.csv, NAME_grf.mot and NAME.json per trial
  bool c3d = false;              ///< with out_dir: NAME.c3d too (output/c3d_export.hpp)
  ValidationOptions validation;
  /// Called after each trial with (trials done, trials in all, that trial's row), from the
  /// thread that ran it, one call at a time. The core prints nothing itself.
  std::function<void(std::size_t, std::size_t, const BatchRow&)> progress;
};

/// validate on one trial, as the CLI and Python run it: the trial and the measured forces (the
/// trial's own plates, or those of `plates_file`) read with the zero-offset rule ("none", "zero",
/// "unloaded"), estimate_trial(), validate(). `settings` records the run (settings_json plus the
/// plates file, threshold and zero offset). InputError when the threshold is not a force above 0 N
/// or there is nothing to validate against.
struct ValidationRun {
  EstimateResult estimate;
  ValidationResult validation;
  nlohmann::json settings;
  std::string plates_path;  ///< the file the measured forces came from
};
ValidationRun validate_trial(const Settings& settings, const std::string& plates_file, const ValidationOptions& validation,
                             const std::string& zero_offset, std::function<void(long, long)> progress = {});

/// `--sync` as the user gives it: "none" (report the marker-plate offset only), "auto" (compare
/// after shifting the plates by it) or a shift in seconds (+: the plates led the markers);
/// InputError naming the value otherwise.
void parse_sync(const std::string& text, ValidationOptions& validation);
/// `--timing` as the user gives it: "auto", "crossing" or "ramp" (ValidationOptions::Timing);
/// InputError naming the value otherwise.
void parse_timing(const std::string& text, ValidationOptions& validation);
/// Its name in the settings JSON and the text ("auto", "crossing", "ramp").
const char* timing_name(ValidationOptions::Timing timing);

/// The files a trial of the batch writes into `out_dir`: NAME.csv, NAME_grf.mot (OpenSim's frame), NAME.json,
/// NAME_markers.trc and NAME_external_loads.xml (the OpenSim set, as `estimate --opensim` writes it),
/// NAME_stances.csv (as `estimate --stances`), NAME_stance_curves.csv (as `estimate --stance-curves`), and with
/// `c3d` NAME.c3d (as `estimate --c3d` writes it).
std::vector<std::string> batch_trial_outputs(const TrialListEntry& entry, const std::string& out_dir, bool c3d = false);
/// One trial: never throws for the trial's own faults (they are the row's error).
BatchRow run_batch_entry(const TrialListEntry& entry, const BatchOptions& options = {});
/// Every trial, rows in the list's order.
std::vector<BatchRow> run_batch(const std::vector<TrialListEntry>& entries, const BatchOptions& options = {});

/// The batch CSV's columns, in order (the Python DataFrame takes the same order).
const std::vector<std::string>& batch_csv_columns();
/// The summary table: CSV (one header line, one line per trial; empty cells for NaN) and JSON
/// (an array of objects with the same fields, null for NaN).
std::string batch_csv(const std::vector<BatchRow>& rows);
/// For a person: one line a trial (status, frames, seconds, mean rRMSE %, the error's first line).
std::string format_batch_table(const std::vector<BatchRow>& rows);
nlohmann::json batch_json(const std::vector<BatchRow>& rows);
nlohmann::json batch_row_json(const BatchRow& row);

}  // namespace kin2grf
