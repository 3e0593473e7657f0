// kin2grf command line: a thin front end that wires the library's steps together and prints.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <thread>

#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/summary.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/output/opensim_export.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/cop_fit.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/workflow/batch.hpp"
#include "kin2grf/workflow/process.hpp"
#include "kin2grf/workflow/progress.hpp"
#include "kin2grf/workflow/settings.hpp"
#include "kin2grf/workflow/trial_list.hpp"
#include "kin2grf/io/json.hpp"

namespace {

int run_info(const std::string& file, bool json, double threshold, const std::string& zero, const std::string& up_axis) {
  const auto s = kin2grf::describe_file(file, threshold, kin2grf::load_options(zero), kin2grf::parse_axis(up_axis));
  if (json) std::cout << kin2grf::json_text(s);
  else std::cout << kin2grf::format_summary(s);
  return 0;
}

/// estimate's arguments: the settings (the library's names) and where the outputs go.
struct EstimateArgs : kin2grf::Settings {
  std::string opensim_dir;
  std::vector<std::string> opensim_bodies;
  std::string out_mot, out_csv, out_json, out_events, out_report;
  bool lab_frame = false;
};

void add_estimate_options(CLI::App* c, EstimateArgs& a, bool outputs = true) {
  kin2grf::add_settings_options(c, a);
  if (!outputs) return;
  c->add_option("-o,--output", a.out_mot,
                "GRF .mot output in OpenSim's convention (X forward, Y up, every frame of the trial), as --opensim writes it");
  c->add_flag("--lab-frame", a.lab_frame, "-o in the input's lab frame (its up axis) over the processed window instead");
  c->add_option("--csv", a.out_csv, "Per-frame CSV output (sagittal frame)");
  c->add_option("--json", a.out_json, "JSON summary output");
  c->add_option("--events", a.out_events, "Gait events (foot strike, foot off per side, from the estimated contact) as CSV");
  c->add_option("--report", a.out_report, "Self-contained HTML report with plots (no plates needed)");
  c->add_option("--opensim", a.opensim_dir,
                "Write FOLDER/TRIAL_grf.mot (whole trial), TRIAL_markers.trc and TRIAL_external_loads.xml in OpenSim's frame "
                "(Y up, X forward), ready for the ID tool");
  c->add_option("--opensim-bodies", a.opensim_bodies, "Bodies the right and left forces are applied to (default calcn_r calcn_l)")
      ->expected(2);
}

/// The estimate's notes and its speed, on stderr.
void print_messages(const kin2grf::EstimateResult& r) {
  for (const auto& m : r.messages) std::cerr << "kin2grf: " << m << "\n";
  std::cerr << "kin2grf: " << r.time_s.size() << " frames, mass " << r.mass_kg << " kg, "
            << static_cast<long>(static_cast<double>(r.time_s.size()) / std::max(1e-9, r.seconds_kinematics + r.seconds_dynamics))
            << " frames/s\n";
}

/// No output replaces an input of the run, nor another output of it.
void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs,
                   const std::vector<std::string>& names = {}) {
  kin2grf::ensure_distinct_outputs(outputs, names);
  kin2grf::ensure_no_output_is_an_input(outputs, inputs);
}

int run_estimate(const EstimateArgs& a) {
  {
    std::vector<std::string> out = {a.out_mot, a.out_csv, a.out_json, a.out_events, a.out_report},
                             names = {"-o", "--csv", "--json", "--events", "--report"};
    if (!a.opensim_dir.empty()) {
      const auto f = kin2grf::opensim_export_paths(a.opensim_dir, std::filesystem::path(a.trial).stem().string());
      out.insert(out.end(), {f.grf_mot, f.markers_trc, f.external_loads_xml});
      names.insert(names.end(), 3, "--opensim");
    }
    check_outputs(out, kin2grf::input_files(a), names);
  }
  {
    // From 8 MB of file on, the trial's series alone outgrow the heap's 32 MB of huge pages.
    std::error_code ec;
    if (std::filesystem::file_size(a.trial, ec) >= (std::uintmax_t{8} << 20) && !ec) kin2grf::tune_allocator_for_a_long_run();
  }
  auto files = kin2grf::load_trial_and_static(a, kin2grf::estimate_load_options());
  const kin2grf::Trial& trial = files.trial;
  auto options = kin2grf::to_options(a);
  options.progress = kin2grf::solve_progress(stderr);
  // The outputs need neither what validation reads nor, unless the OpenSim export writes them,
  // the markers: a long trial's memory.
  options.keep_all_series = !a.out_report.empty();  // the report plots the GRM
  const Eigen::VectorXd trial_time_s = trial.markers.time_s;  // -o's rows: every frame of the trial
  const auto r = a.opensim_dir.empty() ? kin2grf::estimate_trial(a, options, std::move(files.trial), files.static_trial)
                                       : kin2grf::estimate_trial(a, options, trial, files.static_trial);
  print_messages(r);
  const std::string settings_line = kin2grf::settings_json(a, options).dump();
  if (!a.out_mot.empty()) {
    if (a.lab_frame) kin2grf::write_grf_mot(a.out_mot, r, settings_line);
    else kin2grf::write_opensim_grf_mot(a.out_mot, std::filesystem::path(a.trial).stem().string(), trial_time_s, r, settings_line);
  }
  if (!a.out_csv.empty()) kin2grf::write_results_csv(a.out_csv, r);
  if (!a.out_json.empty() || !a.out_report.empty()) {
    const auto summary = kin2grf::results_summary(r, kin2grf::settings_json(a, options));
    if (!a.out_json.empty()) kin2grf::write_file_text(a.out_json, kin2grf::json_text(summary));
    if (!a.out_report.empty()) kin2grf::write_file_text(a.out_report, kin2grf::estimate_report_html(a.trial, r, summary));
  }
  if (!a.out_events.empty()) kin2grf::write_file_text(a.out_events, kin2grf::gait_events_csv(r));
  std::cout << kin2grf::format_results_text(r);
  for (const auto& [file, what] : {std::pair{a.out_mot, a.lab_frame ? "GRF, lab frame" : "GRF, OpenSim's frame"}, {a.out_csv, "per-frame CSV"}, {a.out_json, "JSON summary"},
                                   {a.out_events, "gait events CSV"}, {a.out_report, "HTML report"}})
    if (!file.empty()) std::cout << "wrote " << file << " (" << what << ")\n";
  if (!a.opensim_dir.empty()) {
    kin2grf::OpenSimExportOptions eo;
    if (a.opensim_bodies.size() == 2) eo.right_body = a.opensim_bodies[0], eo.left_body = a.opensim_bodies[1];
    eo.settings = settings_line;
    const auto f = kin2grf::write_opensim_export(a.opensim_dir, std::filesystem::path(a.trial).stem().string(), trial, r, eo);
    std::cout << "wrote " << f.grf_mot << ", " << f.markers_trc << " and " << f.external_loads_xml
              << " (OpenSim: Y up, X forward; sagittal model: no mediolateral force or free moment)\n";
  }
  if (a.out_mot.empty() && a.out_csv.empty() && a.out_json.empty() && a.out_events.empty() && a.out_report.empty() && a.opensim_dir.empty())
    std::cout << "(-o GRF.mot, --csv FILE and --json FILE write the per-frame results and the full summary)\n";
  return 0;
}

struct ValidateArgs {
  EstimateArgs est;
  std::string plates, out_json, report, zero_offset = "unloaded";
  kin2grf::ValidationOptions options;
};

int run_validate(const ValidateArgs& a) {
  auto in = kin2grf::input_files(a.est);
  in.push_back(a.plates);
  check_outputs({a.out_json, a.report}, in, {"--json", "--report"});
  const auto run = kin2grf::validate_trial(a.est, a.plates, a.options, a.zero_offset, kin2grf::solve_progress(stderr));
  print_messages(run.estimate);
  std::cout << kin2grf::format_validation_table(a.est.trial, run.validation);
  const auto j = kin2grf::validation_json(a.est.trial, run.estimate, run.validation, run.settings);
  if (!a.out_json.empty()) kin2grf::write_file_text(a.out_json, kin2grf::json_text(j));
  if (!a.report.empty()) kin2grf::write_file_text(a.report, kin2grf::validation_report_html(a.est.trial, run.estimate, run.validation, j));
  return 0;
}

struct StudyArgs {
  std::string kind, trial_list, out_json, report, cross_validate;
  std::vector<std::string> trials;
  EstimateArgs est;
  std::string plates;
};

int run_study(const StudyArgs& a) {
  check_outputs({a.out_json, a.report}, {a.trial_list}, {"--json", "--report"});
  auto inputs = a.trial_list.empty() ? std::vector<kin2grf::TrialListEntry>{} : kin2grf::read_trial_list(a.trial_list);
  for (auto& e : kin2grf::trial_list_of_files(a.trials, a.est, a.plates)) inputs.push_back(std::move(e));
  if (inputs.empty()) throw kin2grf::InputError("study: give TRIAL files or --trial-list FILE");
  check_outputs({a.out_json, a.report}, kin2grf::list_input_files(inputs));
  const auto st = kin2grf::study_trials(inputs);
  std::cerr << "kin2grf: study " << a.kind << " on " << st.size() << " trials\n";
  const auto res = kin2grf::run_study(a.kind, st);
  std::cout << kin2grf::format_study_table(res);
  auto j = kin2grf::study_json(res);
  if (!a.cross_validate.empty()) {
    const auto cv = kin2grf::cross_validate(res);
    std::cout << kin2grf::format_cross_validation(res, cv);
    j["cross_validation"] = kin2grf::cross_validation_json(cv);
  }
  if (!a.out_json.empty()) kin2grf::write_file_text(a.out_json, kin2grf::json_text(j));
  if (!a.report.empty()) kin2grf::write_file_text(a.report, kin2grf::study_report_html(res));
  return 0;
}

struct FitCopArgs {
  std::string trial_list, activity = "walking", out;
  double min_force = 0.2;
  bool leave_one_out = false, fit_angles = false;
};

/// fit-cop: the COP function of foot model 2 fitted to the plate COPs of a trial list's stances.
int run_fit_cop(const FitCopArgs& a) {
  check_outputs({a.out}, {a.trial_list});
  std::vector<kin2grf::TrialListEntry> inputs;
  for (auto& in : kin2grf::read_trial_list(a.trial_list))
    if (a.activity.empty() || in.activity == a.activity) inputs.push_back(in);
  if (inputs.empty()) throw kin2grf::InputError(a.trial_list + ": no trial of activity '" + a.activity + "'");
  check_outputs({a.out}, kin2grf::list_input_files(inputs));
  const auto trials = kin2grf::study_trials(inputs);
  // Start (and, without --fit-angles, keep) the paper's event angles.
  const kin2grf::CopFunction start = kin2grf::CopFunction::paper();
  const auto res = kin2grf::fit_cop_on_trials(trials, start, a.min_force, a.fit_angles, a.leave_one_out);
  kin2grf::CopFitProvenance prov;
  prov.command = "kin2grf fit-cop --trial-list " + a.trial_list + " --activity " + a.activity + (a.fit_angles ? " --fit-angles" : "") +
                 (a.leave_one_out ? " --leave-one-out" : "");
  prov.activity = a.activity;
  prov.min_force_fraction = a.min_force;
  prov.fit_angles = a.fit_angles;
  std::cout << kin2grf::format_cop_fit(res, trials, start, prov);
  const nlohmann::json j = kin2grf::cop_fit_json(res, trials, start, prov);
  if (!a.out.empty()) kin2grf::write_file_text(a.out, kin2grf::json_text(j));
  return 0;
}

struct BatchArgs {
  std::string trial_list, out_csv, out_json, out_dir;
  int jobs = 0;  ///< 0: every core
};

/// batch: every trial of a list, on all cores, past failures, into one summary table.
int run_batch(const BatchArgs& a) {
  check_outputs({a.out_csv, a.out_json}, {a.trial_list}, {"--csv", "--json"});
  const auto entries = kin2grf::read_trial_list(a.trial_list);
  {
    // The summaries replace no trial's input and no trial's own output (--out-dir).
    std::vector<std::string> out = {a.out_csv, a.out_json}, names = {"--csv", "--json"};
    if (!a.out_dir.empty())
      for (const auto& e : entries)
        for (auto& f : kin2grf::batch_trial_outputs(e, a.out_dir)) out.push_back(std::move(f)), names.push_back("--out-dir");
    check_outputs(out, kin2grf::list_input_files(entries), names);
  }
  kin2grf::BatchOptions o;
  o.jobs = a.jobs > 0 ? a.jobs : static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  o.out_dir = a.out_dir, o.progress = kin2grf::batch_progress(stderr);
  const auto start = std::chrono::steady_clock::now();
  kin2grf::allow_allocator_arenas(o.jobs);
  std::cerr << "kin2grf: batch of " << entries.size() << " trials on " << o.jobs << " threads\n";
  const auto rows = kin2grf::run_batch(entries, o);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << kin2grf::format_batch_table(rows);
  const auto failed = std::count_if(rows.begin(), rows.end(), [](const kin2grf::BatchRow& r) { return !r.ok; });
  std::printf("%zu trials, %ld failed, %.1f s on %d threads\n", rows.size(), static_cast<long>(failed), wall, o.jobs);
  if (!a.out_csv.empty()) kin2grf::write_file_text(a.out_csv, kin2grf::batch_csv(rows));
  if (!a.out_json.empty()) {
    auto j = kin2grf::batch_json(rows);
    j["trial_list"] = a.trial_list, j["jobs"] = o.jobs, j["wall_seconds"] = wall;
    kin2grf::write_file_text(a.out_json, kin2grf::json_text(j));
  }
  return failed == 0 ? 0 : 1;
}

/// The bundled examples (write_examples): a walk over two plates and a squat.
int run_make_example(const std::string& dir, double seconds, double rate_hz, double analog_rate_hz, double noise_mm) {
  for (const auto& line : kin2grf::write_examples(dir, seconds, rate_hz, analog_rate_hz, noise_mm / 1000.0))
    std::cout << "wrote " << line << "\n";
  return 0;
}

/// "Did you mean ...?" for a misspelt subcommand (the first word) or long option of the chosen
/// subcommand, on standard error after CLI11's own message.
void suggest_spelling(CLI::App& app, int argc, char** argv, const std::vector<std::string>& commands) {
  if (argc < 2) return;
  const std::string first = argv[1];
  if (first.empty() || first[0] == '-') return;
  if (std::find(commands.begin(), commands.end(), first) == commands.end()) {
    if (const auto near = kin2grf::closest_match(first, commands); !near.empty())
      std::cerr << "kin2grf: unknown command '" << first << "'; did you mean '" << near << "'?\n";
    return;
  }
  const CLI::App* sub = nullptr;
  for (const CLI::App* c : app.get_subcommands([](const CLI::App*) { return true; }))
    if (c->get_name() == first) sub = c;
  if (!sub) return;
  std::vector<std::string> names;
  for (const CLI::Option* o : sub->get_options())
    for (const auto& l : o->get_lnames()) names.push_back("--" + l);
  for (int i = 2; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.rfind("--", 0) != 0) continue;
    const std::string flag = word.substr(0, word.find('='));
    if (std::find(names.begin(), names.end(), flag) != names.end()) continue;
    if (const auto near = kin2grf::closest_match(flag, names); !near.empty())
      std::cerr << "kin2grf: unknown option '" << flag << "'; did you mean " << near << "?\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  kin2grf::tune_allocator_for_a_short_run();
  CLI::App app{"kin2grf: ground reaction forces, centre of pressure and joint torques from "
               "motion-capture markers alone (no force plates)"};
  app.set_version_flag("--version", std::string("kin2grf ") + KIN2GRF_VERSION);
  app.require_subcommand(1);
  // Only the subcommand asked for is built (building all of them was a twentieth of a short
  // run); with no known subcommand first, all are, for the overview and the error.
  const std::vector<std::string> commands = {"info", "estimate", "validate", "study", "fit-cop", "batch", "make-example"};
  const bool one = argc > 1 && std::find(commands.begin(), commands.end(), argv[1]) != commands.end();
  auto wanted = [&](const char* name) { return !one || name == std::string(argv[1]); };
  CLI::App *info = nullptr, *estimate = nullptr, *validate = nullptr, *study = nullptr, *fit_cop = nullptr, *batch = nullptr,
           *make_example = nullptr;

  std::string info_file, info_zero = "none", info_up_axis;
  bool info_json = false;
  double info_threshold = 20.0;
  if (wanted("info")) {
    info = app.add_subcommand("info", "Describe a recording (C3D, TRC, MOT/STO) before processing it");
    info->add_option("FILE", info_file, "The recording")->required();
    info->add_flag("--json", info_json, "Write the description as JSON (schema in docs/FORMATS.md)");
    info->add_option("--zero-offset", info_zero,
                     "C3D plate offsets: none, zero (FORCE_PLATFORM:ZERO frames) or unloaded (median of unloaded samples)")
        ->check(CLI::IsMember({"none", "zero", "unloaded"}))->capture_default_str();
    info->add_option("--up-axis", info_up_axis, "The lab up axis (X, Y or Z); default: the data's (plates' normal, markers' spread)");
    info->add_option("--load-threshold", info_threshold, "Vertical force (N) above which a plate counts as loaded")
        ->capture_default_str();
  }

  EstimateArgs est;
  if (wanted("estimate")) {
    estimate = app.add_subcommand("estimate", "Estimate GRF, COP, GRM and joint torques from markers");
    add_estimate_options(estimate, est);
  }

  ValidateArgs val;
  if (wanted("validate")) {
    validate = app.add_subcommand("validate", "Estimate, then compare with the trial's force plates (paper's Eqs. 11-12)");
    add_estimate_options(validate, val.est, false);
    validate->add_option("--plates", val.plates, "Measured forces from this file (GRF .mot/.sto or C3D) instead of the trial's plates");
    validate->add_option("--json", val.out_json, "Validation results as JSON (schema in docs/FORMATS.md)");
    validate->add_option("--report", val.report, "Self-contained HTML report with plots");
    validate->add_option("--threshold", val.options.threshold_N, "Stance: measured vertical force above this, N")->capture_default_str();
    validate->add_option("--zero-offset", val.zero_offset, "C3D plate offsets: none, zero or unloaded")
        ->check(CLI::IsMember({"none", "zero", "unloaded"}))->capture_default_str();
    validate->add_option_function<std::string>(
        "--sync", [&val](const std::string& t) { kin2grf::parse_sync(t, val.options); },
        "Marker-plate time offset: none (compare as recorded; the offset is reported), auto (compare after shifting the plates "
        "by the estimated offset) or SECONDS (shift the plates by this; + when the plates led)");
  }

  StudyArgs study_args;
  if (wanted("study")) {
    std::string kinds;
    for (const auto& k : kin2grf::study_kinds()) kinds += (kinds.empty() ? "" : " | ") + k;
    study = app.add_subcommand("study", "The paper's parameter studies and kin2grf's, on trials with plates: " + kinds);
    study->add_option("KIND", study_args.kind, "Which study")->required()->check(CLI::IsMember(kin2grf::study_kinds()));
    study->add_option("TRIAL", study_args.trials, "Trials with plates (the options below apply to all of them)");
    study->add_option("--trial-list", study_args.trial_list,
                      "File of lines 'activity|lab|name|TRIAL [options]', each trial with its own options");
    study->add_option("--cross-validate", study_args.cross_validate,
                      "Also choose the setting leave-one-lab-out and print in-sample against held-out figures")
        ->check(CLI::IsMember({"lab"}));
    study->add_option("--plates", study_args.plates, "Measured forces for the TRIAL arguments (GRF .mot)");
    study->add_option("--json", study_args.out_json, "Study results as JSON");
    study->add_option("--report", study_args.report, "HTML report with the rRMSE-against-setting plots");
    // Estimate options for the TRIAL arguments (without outputs; TRIAL is positional above).
    auto& e = study_args.est;
    study->add_option("--static", e.static_trial, "Static trial");
    study->add_option("--markers", e.markers, "Marker-set preset or mapping file");
    study->add_option("--mass", e.mass, "Body mass, kg");
    study->add_flag("--paper", e.paper, "The paper's configuration");
  }

  FitCopArgs fit_args;
  if (wanted("fit-cop")) {
    fit_cop = app.add_subcommand("fit-cop", "Fit foot model 2's COP function to the plate COPs of trials with plates");
    fit_cop->add_option("--trial-list", fit_args.trial_list, "File of lines 'activity|lab|name|TRIAL [options]'")->required();
    fit_cop->add_option("--activity", fit_args.activity, "Use the trials of this activity ('' = all)")->capture_default_str();
    fit_cop->add_option("--min-force", fit_args.min_force, "Frames where the plate carries at least this fraction of body weight")
        ->capture_default_str();
    fit_cop->add_flag("--fit-angles", fit_args.fit_angles, "Fit the event angles too (default: the paper's, fixed)");
    fit_cop->add_flag("--leave-one-out", fit_args.leave_one_out,
                      "Also report each trial's COP error with a fit on the other labs' trials (leave one lab out)");
    fit_cop->add_option("-o,--output", fit_args.out, "Write the fitted function and its provenance (JSON)");
  }

  BatchArgs batch_args;
  if (wanted("batch")) {
    batch = app.add_subcommand("batch", "Estimate (and validate, where plates exist) every trial of a trial list, on all cores");
    batch->add_option("LIST", batch_args.trial_list, "File of lines 'activity|lab|name|TRIAL [options] [--plates F]'")->required();
    batch->add_option("-j,--jobs", batch_args.jobs, "Worker threads (default: every core)")->check(CLI::Range(0, 1024));
    batch->add_option("--csv", batch_args.out_csv, "Summary table, one line per trial (CSV)");
    batch->add_option("--json", batch_args.out_json, "Summary table as JSON, with each trial's messages");
    batch->add_option("--out-dir", batch_args.out_dir, "Write NAME.csv, NAME_grf.mot and NAME.json per trial into this folder");
  }

  std::string example_dir = "example";
  double example_seconds = 3.0, example_rate = 100.0, example_analog_rate = 0.0, example_noise_mm = 0.0;
  if (wanted("make-example")) {
    make_example = app.add_subcommand("make-example", "Write the synthetic example trial (C3D with plates, TRC, GRF .mot)");
    make_example->add_option("--out-dir", example_dir, "Output folder")->capture_default_str();
    make_example->add_option("--seconds", example_seconds, "Duration, s")->capture_default_str();
    make_example->add_option("--rate", example_rate, "Marker rate, Hz (50-2000)")->capture_default_str();
    make_example->add_option("--analog-rate", example_analog_rate,
                             "The walk's plates' rate, Hz: a whole multiple of the marker rate (default: the marker rate)");
    make_example->add_option("--marker-noise", example_noise_mm,
                             "Gaussian noise on the walk's marker coordinates, SD in mm (0-10; seeded)")->capture_default_str();
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2 (README, "Exit status"), with a
    // suggestion for a misspelt subcommand or option.
    if (app.exit(e) == 0) return 0;
    suggest_spelling(app, argc, argv, commands);
    return 2;
  }
  // A run's outputs are placed together at its end, or not at all; a signal removes their
  // temporary files. A closed standard output (`| head -1`) is not a reason to die half way.
  kin2grf::install_output_cleanup_on_signals();
  std::signal(SIGPIPE, SIG_IGN);
  try {
    kin2grf::OutputTransaction outputs(/*whole_run=*/true);
    int rc = 0;
    auto chosen = [](const CLI::App* c) { return c && c->parsed(); };
    if (chosen(info)) rc = run_info(info_file, info_json, info_threshold, info_zero, info_up_axis);
    else if (chosen(estimate)) rc = run_estimate(est);
    else if (chosen(validate)) rc = run_validate(val);
    else if (chosen(study)) rc = run_study(study_args);
    else if (chosen(fit_cop)) rc = run_fit_cop(fit_args);
    else if (chosen(batch)) rc = run_batch(batch_args);
    else if (chosen(make_example)) rc = run_make_example(example_dir, example_seconds, example_rate, example_analog_rate, example_noise_mm);
    outputs.commit();
    // Standard output full or failing: what it was to show is lost, so the run failed. A reader
    // that stopped reading (a closed pipe) asked for no more.
    std::cout.flush();
    if ((!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) && errno != EPIPE)
      throw kin2grf::InputError(std::string("cannot write to standard output (") + std::strerror(errno) + ")");
    return rc;
  } catch (const kin2grf::InputError& e) {
    std::cerr << "kin2grf: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "kin2grf: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
