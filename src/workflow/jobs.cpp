#include "kin2grf/workflow/jobs.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "kin2grf/error.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/io/json.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/marker_labels.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/summary.hpp"
#include "kin2grf/output/c3d_export.hpp"
#include "kin2grf/output/opensim_export.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/cop_fit.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/workflow/batch.hpp"
#include "kin2grf/workflow/process.hpp"
#include "kin2grf/workflow/progress.hpp"
#include "kin2grf/workflow/trial_list.hpp"

namespace kin2grf {

namespace {
/// The estimate's notes and its speed, on `log`.
void print_messages(const EstimateResult& r, std::ostream& log) {
  for (const auto& m : r.messages) log << "kin2grf: " << m << "\n";
  log << "kin2grf: " << r.time_s.size() << " frames, mass " << r.mass_kg << " kg, "
            << static_cast<long>(static_cast<double>(r.time_s.size()) / std::max(1e-9, r.seconds_kinematics + r.seconds_dynamics))
            << " frames/s\n";
}

/// No output replaces an input of the run, nor another output of it.
void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs,
                   const std::vector<std::string>& names = {}) {
  ensure_distinct_outputs(outputs, names);
  ensure_no_output_is_an_input(outputs, inputs);
}
}  // namespace

int info_job(const std::string& file, bool json, double threshold, const std::string& zero, const std::string& up_axis, std::ostream& out,
             const std::string& write_mapping) {
  if (!write_mapping.empty()) check_outputs({write_mapping}, {file}, {"--write-mapping"});
  Trial t;
  const auto s = describe_file(file, threshold, load_options(zero), parse_axis(up_axis), write_mapping.empty() ? nullptr : &t);
  if (json) out << json_text(s);
  else out << format_summary(s);
  // The mapping made from the labels, whatever the preset: a mapping file to start from.
  if (!write_mapping.empty()) write_file_text(write_mapping, map_marker_labels(t.markers).draft.dump(1) + "\n");
  return 0;
}


void add_estimate_options(CLI::App* c, EstimateJob& a, bool outputs) {
  add_settings_options(c, a);
  if (!outputs) return;
  c->add_option("-o,--output", a.out_mot,
                "GRF .mot output in OpenSim's convention (X forward, Y up, every frame of the trial), as --opensim writes it");
  c->add_flag("--lab-frame", a.lab_frame, "-o in the input's lab frame (its up axis) over the processed window instead");
  c->add_option("--csv", a.out_csv, "Per-frame CSV output (sagittal frame)");
  c->add_option("--json", a.out_json, "JSON summary output");
  c->add_option("--events", a.out_events, "Gait events (foot strike, foot off per side, from the estimated contact) as CSV");
  c->add_option("--stances", a.out_stances,
                "Each stance's ground reaction parameters as CSV, one row per stance: the vertical peaks and valley, the braking and "
                "propulsive peaks and impulses, the loading rate, in N and body weights (docs/FORMATS.md)");
  c->add_option("--stance-curves", a.out_stance_curves,
                "Each complete stance time-normalised, 0 to 100 % of the stance (101 rows a stance), as CSV: the foot's force in body "
                "weights, the COP's progression, the hip, knee and ankle torques (N m/kg) and powers (W/kg); with --model 3d the knee adduction "
                "moment and every joint's 3D moment in each plane (docs/FORMATS.md)");
  c->add_option("--report", a.out_report, "Self-contained HTML report with plots (no plates needed)");
  c->add_option("--opensim", a.opensim_dir,
                "Write FOLDER/TRIAL_grf.mot (whole trial), TRIAL_markers.trc and TRIAL_external_loads.xml in OpenSim's frame "
                "(Y up, X forward), ready for the ID tool");
  c->add_option("--opensim-bodies", a.opensim_bodies, "Bodies the right and left forces are applied to (default calcn_r calcn_l)")
      ->expected(2);
  c->add_option("--c3d", a.out_c3d,
                "Write the trial's markers with the estimated GRF as two force platforms (TYPE 2: 1 the right foot, 2 the left) "
                "and its gait events, Z up, for Nexus, Visual3D, Mokka or ezc3d (docs/FORMATS.md)");
}

int estimate_job(const EstimateJob& a, std::ostream& out, std::ostream& log) {
  {
    std::vector<std::string> files = {a.out_mot, a.out_csv, a.out_json, a.out_events, a.out_stances, a.out_stance_curves, a.out_report, a.out_c3d},
                             names = {"-o", "--csv", "--json", "--events", "--stances", "--stance-curves", "--report", "--c3d"};
    if (!a.opensim_dir.empty()) {
      const auto f = opensim_export_paths(a.opensim_dir, std::filesystem::path(a.trial).stem().string());
      files.insert(files.end(), {f.grf_mot, f.markers_trc, f.external_loads_xml});
      names.insert(names.end(), 3, "--opensim");
    }
    check_outputs(files, input_files(a), names);
  }
  {
    // From 8 MB of file on, the trial's series alone outgrow the heap's 32 MB of huge pages.
    std::error_code ec;
    if (std::filesystem::file_size(a.trial, ec) >= (std::uintmax_t{8} << 20) && !ec) tune_allocator_for_a_long_run();
  }
  auto files = load_trial_and_static(a, estimate_load_options());
  const Trial& trial = files.trial;
  auto options = to_options(a);
  options.progress = solve_progress(stderr);
  // The outputs need neither what validation reads nor, unless the OpenSim or the C3D export writes
  // them, the markers: a long trial's memory.
  options.keep_all_series = !a.out_report.empty();  // the report plots the GRM
  const Eigen::VectorXd trial_time_s = trial.markers.time_s;  // -o's rows: every frame of the trial
  const bool keep_markers = !a.opensim_dir.empty() || !a.out_c3d.empty();  // the exports write them
  const auto r = keep_markers ? estimate_trial(a, options, trial, files.static_trial)
                              : estimate_trial(a, options, std::move(files.trial), files.static_trial);
  print_messages(r, log);
  const std::string settings_line = settings_json(a, options).dump();
  if (!a.out_mot.empty()) {
    if (a.lab_frame) write_grf_mot(a.out_mot, r, settings_line);
    else write_opensim_grf_mot(a.out_mot, std::filesystem::path(a.trial).stem().string(), trial_time_s, r, settings_line);
  }
  if (!a.out_csv.empty()) write_results_csv(a.out_csv, r);
  if (!a.out_json.empty() || !a.out_report.empty()) {
    const auto summary = results_summary(r, settings_json(a, options));
    if (!a.out_json.empty()) write_file_text(a.out_json, json_text(summary));
    if (!a.out_report.empty()) write_file_text(a.out_report, estimate_report_html(a.trial, r, summary));
  }
  if (!a.out_events.empty()) write_file_text(a.out_events, gait_events_csv(r));
  if (!a.out_stances.empty()) write_file_text(a.out_stances, stance_parameters_csv(r));
  if (!a.out_stance_curves.empty()) write_stance_curves_csv(a.out_stance_curves, r);
  if (!a.out_c3d.empty())
    for (const auto& m : write_c3d_export(a.out_c3d, trial, r)) log << "kin2grf: " << m << "\n";
  out << format_results_text(r);
  for (const auto& [file, what] : {std::pair{a.out_mot, a.lab_frame ? "GRF, lab frame" : "GRF, OpenSim's frame"}, {a.out_csv, "per-frame CSV"}, {a.out_json, "JSON summary"},
                                   {a.out_events, "gait events CSV"}, {a.out_stances, "stance parameters CSV"},
                                   {a.out_stance_curves, "time-normalised stances CSV"}, {a.out_report, "HTML report"},
                                   {a.out_c3d, "C3D: the markers with the estimated GRF as force platforms 1 (right) and 2 (left)"}})
    if (!file.empty()) out << "wrote " << file << " (" << what << ")\n";
  if (!a.opensim_dir.empty()) {
    OpenSimExportOptions eo;
    if (a.opensim_bodies.size() == 2) eo.right_body = a.opensim_bodies[0], eo.left_body = a.opensim_bodies[1];
    eo.settings = settings_line;
    const auto f = write_opensim_export(a.opensim_dir, std::filesystem::path(a.trial).stem().string(), trial, r, eo);
    out << "wrote " << f.grf_mot << ", " << f.markers_trc << " and " << f.external_loads_xml << " (OpenSim: Y up, X forward; "
        << (a.mediolateral ? "with the mediolateral force; no free moment)\n" : "sagittal model: no mediolateral force or free moment)\n");
  }
  if (a.out_mot.empty() && a.out_csv.empty() && a.out_json.empty() && a.out_events.empty() && a.out_stances.empty() && a.out_stance_curves.empty() && a.out_report.empty() &&
      a.opensim_dir.empty() &&
      a.out_c3d.empty())
    out << "(-o GRF.mot, --csv FILE and --json FILE write the per-frame results and the full summary)\n";
  return 0;
}


int validate_job(const ValidateJob& a, std::ostream& out, std::ostream& log) {
  auto in = input_files(a.est);
  in.push_back(a.plates);
  check_outputs({a.out_json, a.report, a.stance_curves}, in, {"--json", "--report", "--stance-curves"});
  const auto run = validate_trial(a.est, a.plates, a.options, a.zero_offset, solve_progress(stderr));
  print_messages(run.estimate, log);
  out << format_validation_table(a.est.trial, run.validation);
  const auto j = validation_json(a.est.trial, run.estimate, run.validation, run.settings);
  if (!a.out_json.empty()) write_file_text(a.out_json, json_text(j));
  if (!a.report.empty()) write_file_text(a.report, validation_report_html(a.est.trial, run.estimate, run.validation, j));
  if (!a.stance_curves.empty()) write_file_text(a.stance_curves, validation_stance_curves_csv(run.estimate, run.validation));
  return 0;
}


int study_job(const StudyJob& a, std::ostream& out, std::ostream& log) {
  check_outputs({a.out_json, a.report}, {a.trial_list}, {"--json", "--report"});
  auto inputs = a.trial_list.empty() ? std::vector<TrialListEntry>{} : read_trial_list(a.trial_list);
  for (auto& e : trial_list_of_files(a.trials, a.est, a.plates)) inputs.push_back(std::move(e));
  if (inputs.empty()) throw InputError("study: give TRIAL files or --trial-list FILE");
  check_outputs({a.out_json, a.report}, list_input_files(inputs));
  const auto st = study_trials(inputs);
  log << "kin2grf: study " << a.kind << " on " << st.size() << " trials\n";
  const auto res = kin2grf::run_study(a.kind, st);
  out << format_study_table(res);
  auto j = study_json(res);
  if (!a.cross_validate.empty()) {
    const auto cv = cross_validate(res, parse_criterion(a.criterion));
    out << format_cross_validation(res, cv);
    j["cross_validation"] = cross_validation_json(cv);
    // Both criteria in the JSON, whichever was asked for (VALIDATION.md reports them side by side).
    for (const auto vertical : {CrossValidation::Vertical::PlateStance, CrossValidation::Vertical::LoadedSpan})
      j["cross_validation_by_criterion"][criterion_name(vertical)] =
          vertical == cv.vertical ? j["cross_validation"] : cross_validation_json(cross_validate(res, vertical));
  }
  if (!a.out_json.empty()) write_file_text(a.out_json, json_text(j));
  if (!a.report.empty()) write_file_text(a.report, study_report_html(res));
  return 0;
}


/// fit-cop: the COP function of foot model 2 fitted to the plate COPs of a trial list's stances.
int fit_cop_job(const FitCopJob& a, std::ostream& out) {
  check_outputs({a.out}, {a.trial_list});
  std::vector<TrialListEntry> inputs;
  for (auto& in : read_trial_list(a.trial_list))
    if (a.activity.empty() || in.activity == a.activity) inputs.push_back(in);
  if (inputs.empty()) throw InputError(a.trial_list + ": no trial of activity '" + a.activity + "'");
  check_outputs({a.out}, list_input_files(inputs));
  const auto trials = study_trials(inputs);
  // Start (and, without --fit-angles, keep) the paper's event angles.
  CopFunction start = CopFunction::paper();
  const std::optional<CopLength> length = parse_cop_length(a.length);
  if (!length) throw InputError("fit-cop: --length must be heel-mt or sole, not '" + a.length + "'");
  start.length = *length;
  const auto res = fit_cop_on_trials(trials, start, a.min_force, a.fit_angles, a.leave_one_out, a.fit_com);
  CopFitProvenance prov;
  char min_force[32];
  std::snprintf(min_force, sizeof min_force, "%g", a.min_force);
  prov.command = "kin2grf fit-cop --trial-list " + a.trial_list + " --activity " + a.activity + (a.fit_angles ? " --fit-angles" : "") +
                 (a.fit_com ? " --fit-com" : "") + " --length " + a.length + " --min-force " + min_force + (a.leave_one_out ? " --leave-one-out" : "");
  prov.activity = a.activity;
  prov.min_force_fraction = a.min_force;
  prov.fit_angles = a.fit_angles;
  out << format_cop_fit(res, trials, start, prov);
  const nlohmann::json j = cop_fit_json(res, trials, start, prov);
  if (!a.out.empty()) write_file_text(a.out, json_text(j));
  return 0;
}


/// batch: every trial of a list, on all cores, past failures, into one summary table.
int batch_job(const BatchJob& a, std::ostream& out, std::ostream& log) {
  check_outputs({a.out_csv, a.out_json}, {a.trial_list}, {"--csv", "--json"});
  const auto entries = read_trial_list(a.trial_list);
  {
    // The summaries replace no trial's input and no trial's own output (--out-dir).
    std::vector<std::string> files = {a.out_csv, a.out_json}, names = {"--csv", "--json"};
    if (!a.out_dir.empty())
      for (const auto& e : entries)
        for (auto& f : batch_trial_outputs(e, a.out_dir, a.c3d)) files.push_back(std::move(f)), names.push_back("--out-dir");
    check_outputs(files, list_input_files(entries), names);
  }
  BatchOptions o;
  o.jobs = a.jobs > 0 ? a.jobs : static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  o.out_dir = a.out_dir, o.c3d = a.c3d, o.progress = batch_progress(stderr);
  const auto start = std::chrono::steady_clock::now();
  allow_allocator_arenas(o.jobs);
  log << "kin2grf: batch of " << entries.size() << " trials on " << o.jobs << " threads\n";
  const auto rows = kin2grf::run_batch(entries, o);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out << format_batch_table(rows);
  const auto failed = std::count_if(rows.begin(), rows.end(), [](const BatchRow& r) { return !r.ok; });
  char line[160];
  std::snprintf(line, sizeof line, "%zu trials, %ld failed, %.1f s on %d threads\n", rows.size(), static_cast<long>(failed), wall, o.jobs);
  out << line;
  if (!a.out_csv.empty()) write_file_text(a.out_csv, batch_csv(rows));
  if (!a.out_json.empty()) {
    auto j = batch_json(rows);
    j["trial_list"] = a.trial_list, j["jobs"] = o.jobs, j["wall_seconds"] = wall;
    write_file_text(a.out_json, json_text(j));
  }
  return failed == 0 ? 0 : 1;
}

/// The bundled examples (write_examples): a walk over two plates and a squat.
int make_example_job(const std::string& dir, double seconds, double rate_hz, double analog_rate_hz, double noise_mm, std::ostream& out) {
  for (const auto& line : write_examples(dir, seconds, rate_hz, analog_rate_hz, noise_mm / 1000.0))
    out << "wrote " << line << "\n";
  return 0;
}

}  // namespace kin2grf
