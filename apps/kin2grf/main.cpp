// kin2grf command line: the flags of each command; what a command does is the library's
// (workflow/jobs.hpp).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/workflow/batch.hpp"
#include "kin2grf/workflow/jobs.hpp"
#include "kin2grf/workflow/process.hpp"

namespace {

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

  std::string info_file, info_zero = "none", info_up_axis, info_mapping;
  bool info_json = false;
  double info_threshold = 20.0;
  if (wanted("info")) {
    info = app.add_subcommand("info", "Describe a recording (C3D, TRC, MOT/STO) before processing it");
    info->add_option("FILE", info_file, "The recording")->required();
    info->add_flag("--json", info_json, "Write the description as JSON (schema in docs/FORMATS.md)");
    info->add_option("--write-mapping", info_mapping,
                     "Write the mapping made from the file's marker labels as a mapping file to edit (docs/MARKERSETS.md; "
                     "a \"FILL IN\" marker names each landmark no label gives)");
    info->add_option("--zero-offset", info_zero,
                     "C3D plate offsets: none, zero (FORCE_PLATFORM:ZERO frames) or unloaded (median of unloaded samples)")
        ->check(CLI::IsMember({"none", "zero", "unloaded"}))->capture_default_str();
    info->add_option("--up-axis", info_up_axis, "The lab up axis (X, Y or Z); default: the data's (plates' normal, markers' spread)");
    info->add_option("--load-threshold", info_threshold, "Vertical force (N) above which a plate counts as loaded")
        ->capture_default_str();
  }

  kin2grf::EstimateJob est;
  if (wanted("estimate")) {
    estimate = app.add_subcommand("estimate", "Estimate GRF, COP, GRM and joint torques from markers");
    kin2grf::add_estimate_options(estimate, est);
  }

  kin2grf::ValidateJob val;
  if (wanted("validate")) {
    validate = app.add_subcommand("validate", "Estimate, then compare with the trial's force plates (paper's Eqs. 11-12)");
    kin2grf::add_estimate_options(validate, val.est, false);
    validate->add_option("--plates", val.plates, "Measured forces from this file (GRF .mot/.sto or C3D) instead of the trial's plates");
    validate->add_option("--json", val.out_json, "Validation results as JSON (schema in docs/FORMATS.md)");
    validate->add_option("--report", val.report, "Self-contained HTML report with plots");
    validate->add_option("--stance-curves", val.stance_curves,
                         "Each scored plate stance time-normalised (0 to 100 %, 101 rows), the estimate's and the plate's forces "
                         "in body weights and COPs side by side, as CSV (docs/FORMATS.md)");
    validate->add_option("--threshold", val.options.threshold_N, "Stance: measured vertical force above this, N")->capture_default_str();
    validate->add_option("--zero-offset", val.zero_offset, "C3D plate offsets: none, zero or unloaded")
        ->check(CLI::IsMember({"none", "zero", "unloaded"}))->capture_default_str();
    validate->add_option_function<std::string>(
        "--sync", [&val](const std::string& t) { kin2grf::parse_sync(t, val.options); },
        "Marker-plate time offset: none (compare as recorded; the offset is reported), auto (compare after shifting the plates "
        "by the estimated offset) or SECONDS (shift the plates by this; + when the plates led)");
    validate->add_option_function<std::string>(
        "--timing", [&val](const std::string& t) { kin2grf::parse_timing(t, val.options); },
        "How onsets and offsets are timed: crossing (the threshold's crossings of the estimate and the plates), ramp (the loading "
        "and unloading ramps' zero intercepts, 20-80 % of the peak, of both) or auto (the default: the loading ramp for the onsets "
        "on a plate low-pass filtered before export, told from its rise or its noise, whose crossings the filter moved; the "
        "crossings for every other onset and every offset)")
        ->check(CLI::IsMember({"auto", "crossing", "ramp"}));
  }

  kin2grf::StudyJob study_args;
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
    study->add_option("--criterion", study_args.criterion,
                      "The vertical force the leave-one-lab-out criterion takes: over each plate's stance (plate-stance, the "
                      "default), or over the loaded span, which counts a foot loaded before its plate's onset or after its offset "
                      "(loaded-span)")
        ->check(CLI::IsMember({"plate-stance", "loaded-span"}))
        ->capture_default_str();
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

  kin2grf::FitCopJob fit_args;
  if (wanted("fit-cop")) {
    fit_cop = app.add_subcommand("fit-cop", "Fit foot model 2's COP function to the plate COPs of trials with plates");
    fit_cop->add_option("--trial-list", fit_args.trial_list, "File of lines 'activity|lab|name|TRIAL [options]'")->required();
    fit_cop->add_option("--activity", fit_args.activity, "Use the trials of this activity ('' = all)")->capture_default_str();
    fit_cop->add_option("--min-force", fit_args.min_force,
                        "Frames where the plate carries at least this fraction of body weight (validate's COP threshold)")
        ->capture_default_str();
    fit_cop->add_flag("--fit-angles", fit_args.fit_angles, "Fit the event angles too (default: the paper's, fixed)");
    fit_cop->add_flag("--fit-com", fit_args.fit_com,
                      "Fit the COP's gain on the body's centre of mass ahead of the heel too (com_gain; default: 0, the paper's function of the angle alone)");
    fit_cop->add_option("--length", fit_args.length,
                        "What the fitted positions count in: heel-mt (the heel to the 2nd metatarsal head, the built-in walking "
                        "function's) or sole (the sole's heel-to-toe length, the paper's)")
        ->check(CLI::IsMember({"heel-mt", "sole"}))
        ->capture_default_str();
    fit_cop->add_flag("--leave-one-out", fit_args.leave_one_out,
                      "Also report each trial's COP error with a fit on the other labs' trials (leave one lab out)");
    fit_cop->add_option("-o,--output", fit_args.out, "Write the fitted function and its provenance (JSON)");
  }

  kin2grf::BatchJob batch_args;
  if (wanted("batch")) {
    batch = app.add_subcommand("batch", "Estimate (and validate, where plates exist) every trial of a trial list, on all cores");
    batch->add_option("LIST", batch_args.trial_list, "File of lines 'activity|lab|name|TRIAL [options] [--plates F]'")->required();
    batch->add_option("-j,--jobs", batch_args.jobs, "Worker threads (default: every core)")->check(CLI::Range(0, 1024));
    batch->add_option("--csv", batch_args.out_csv, "Summary table, one line per trial (CSV)");
    batch->add_option("--json", batch_args.out_json, "Summary table as JSON, with each trial's messages");
    CLI::Option* out_dir =
        batch->add_option("--out-dir", batch_args.out_dir, "Write NAME.csv, NAME_grf.mot and NAME.json per trial into this folder");
    batch->add_flag("--c3d", batch_args.c3d, "With --out-dir: NAME.c3d per trial too (as estimate --c3d: the markers with the estimated GRF as force platforms)")
        ->needs(out_dir);
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
    auto& out = std::cout;
    auto& log = std::cerr;
    if (chosen(info)) rc = kin2grf::info_job(info_file, info_json, info_threshold, info_zero, info_up_axis, out, info_mapping);
    else if (chosen(estimate)) rc = kin2grf::estimate_job(est, out, log);
    else if (chosen(validate)) rc = kin2grf::validate_job(val, out, log);
    else if (chosen(study)) rc = kin2grf::study_job(study_args, out, log);
    else if (chosen(fit_cop)) rc = kin2grf::fit_cop_job(fit_args, out);
    else if (chosen(batch)) rc = kin2grf::batch_job(batch_args, out, log);
    else if (chosen(make_example))
      rc = kin2grf::make_example_job(example_dir, example_seconds, example_rate, example_analog_rate, example_noise_mm, out);
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
