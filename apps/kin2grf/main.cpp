// kin2grf command line: a thin front end that wires the library's steps together and prints.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "kin2grf/error.hpp"
#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/summary.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/output/opensim_export.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/cop_fit.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"

namespace {

constexpr long kProgressFrames = 20000;  ///< inputs at least this long report progress

kin2grf::LoadOptions load_options(const std::string& zero) {
  kin2grf::LoadOptions lo;
  if (zero == "zero") lo.c3d.zero_offset = kin2grf::ZeroOffset::ZeroParameter;
  if (zero == "unloaded") lo.c3d.zero_offset = kin2grf::ZeroOffset::Unloaded;
  return lo;
}

std::optional<kin2grf::Axis> parse_axis(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
  if (c < 'X' || c > 'Z' || text.size() != 1) throw kin2grf::InputError("--up-axis must be X, Y or Z");
  return static_cast<kin2grf::Axis>(c - 'X');
}

int run_info(const std::string& file, bool json, double threshold, const std::string& zero, const std::string& up_axis) {
  if (!(std::isfinite(threshold) && threshold > 0)) throw kin2grf::InputError("--load-threshold must be a force above 0 N");
  kin2grf::Trial t = kin2grf::load_trial(file, load_options(zero));
  if (const auto up = parse_axis(up_axis)) {  // the user's word over the data's
    t.markers.up_axis = *up;
    if (t.plates) t.plates->up_axis = *up;
  }
  const auto s = kin2grf::trial_summary(t, threshold);
  if (json) std::cout << kin2grf::json_text(s);
  else std::cout << kin2grf::format_summary(s);
  return 0;
}

const char* torso_length_name(kin2grf::TorsoLength t) { return t == kin2grf::TorsoLength::Fixed ? "fixed" : "measured"; }

struct EstimateArgs {
  std::string opensim_dir;
  std::vector<std::string> opensim_bodies;
  std::string trial, static_trial, markers, out_mot, out_csv, out_json, foot_model = "cop", norm = "torque-scaled",
      anthropometry = kin2grf::EstimateOptions{}.anthropometry, up_axis, cop_function, running_cop = "builtin",
      torso_length = torso_length_name(kin2grf::EstimateOptions{}.torso_length);
  // Numerical defaults come from the library's option structs (one source for CLI and API).
  std::optional<double> mass;
  bool force_mass = false;
  double r = kin2grf::SolverOptions{}.r_N_per_m, kin_cutoff = kin2grf::EstimateOptions{}.kinematic_cutoff_hz,
         post_cutoff = kin2grf::EstimateOptions{}.post_cutoff_hz, ground_shift = 0,
         speed_gate = kin2grf::SolverOptions{}.speed_gate_mps, split_distance = kin2grf::SolverOptions{}.min_split_distance_m,
         speed_gate_ratio = kin2grf::SolverOptions{}.speed_gate_ratio, speed_gate_floor = kin2grf::SolverOptions{}.speed_gate_floor_mps;
  bool paper = false, r_given = false, anthropometry_given = false;
  std::optional<double> ground_level;
  std::vector<double> grm_reference;
  int max_gap = 10;
};

void add_estimate_options(CLI::App* c, EstimateArgs& a, bool outputs = true) {
  c->add_option("TRIAL", a.trial, "Motion trial (C3D or TRC)")->required();
  c->add_option("--static", a.static_trial, "Static calibration trial (for virtual knee/ankle landmarks)");
  c->add_option("--markers", a.markers, "Marker-set preset name or mapping file (JSON); default: recognised");
  c->add_option("--mass", a.mass, "Body mass, kg (default: the C3D's PROCESSING:Bodymass or SUBJECT(S):WEIGHT); 20-300");
  c->add_flag("--force-mass", a.force_mass, "Accept a body mass outside 20-300 kg");
  c->add_option("--foot-model", a.foot_model, "cop (paper's model 2) or three-point (model 1)")
      ->check(CLI::IsMember({"cop", "three-point"}))->capture_default_str();
  c->add_option_function<double>(
       "--r", [&a](double v) { a.r = v, a.r_given = true; },
       "Activation parameter r, N/m (Eq. 8); default 1000 (from `kin2grf study r`), 10000 with --paper");
  c->add_option("--kinematic-cutoff", a.kin_cutoff, "Kinematics low-pass cut-off, Hz")->capture_default_str();
  c->add_option("--post-cutoff", a.post_cutoff, "Multiplier post-filter cut-off, Hz")->capture_default_str();
  c->add_option("--ground-level", a.ground_level, "Floor height in the lab's up axis, m (default: estimated)");
  c->add_option("--grm-reference", a.grm_reference,
                 "GRM reference point in the sagittal frame: along progression and up from the lab origin, m (default 0 0)")
      ->expected(2);
  c->add_option("--ground-shift", a.ground_shift, "Shift the ground by this much, m (robustness study)")->capture_default_str();
  c->add_option_function<double>(
       "--speed-gate", [&a](double v) { a.speed_gate = v, a.speed_gate_ratio = 0; },
       "A fixed speed gate: contact allowed only below this sole speed, m/s (0 = off, the paper); replaces --speed-gate-ratio")
      ->check(CLI::Range(0.0, 20.0));
  c->add_option("--speed-gate-ratio", a.speed_gate_ratio,
                "The speed gate as this multiple of the progression speed (hip or belt), at least --speed-gate-floor; "
                "0 = the fixed --speed-gate")
      ->check(CLI::Range(0.0, 20.0))->capture_default_str();
  c->add_option("--speed-gate-floor", a.speed_gate_floor, "Lowest speed gate with --speed-gate-ratio, m/s")
      ->check(CLI::Range(0.0, 20.0))->capture_default_str();
  c->add_option("--split-distance", a.split_distance,
                "Feet closer than this along progression share the load by the minimum norm, m (0 = off, the paper)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  c->add_option("--torso-length", a.torso_length,
                "measured (the hip-shoulder distance of each frame, filtered) or fixed (its median, the paper's rigid HAT)")
      ->check(CLI::IsMember({"measured", "fixed"}))->capture_default_str();
  c->add_option("--norm", a.norm, "Multiplier norm: paper (pseudo-inverse) or torque-scaled")
      ->check(CLI::IsMember({"paper", "torque-scaled"}))->capture_default_str();
  c->add_option_function<std::string>(
       "--anthropometry", [&a](const std::string& v) { a.anthropometry = v, a.anthropometry_given = true; },
       "winter or de-leva; default de-leva, winter with --paper")
      ->check(CLI::IsMember({"winter", "de-leva"}));
  c->add_option("--cop-function", a.cop_function,
                "Foot model 2's COP function from this JSON (see kin2grf fit-cop); used on every frame unless --running-cop FILE");
  c->add_option("--running-cop", a.running_cop,
                "COP function near flight phases (running): builtin (kin2grf's running fit), off, or a JSON file")
      ->capture_default_str();
  c->add_option("--up-axis", a.up_axis, "Override the lab up axis (X, Y or Z)");
  c->add_flag("--paper", a.paper, "The paper's own configuration: plain pseudo-inverse norm, no speed gate, no side-by-side split, fixed torso length");
  c->add_option("--max-gap", a.max_gap, "Longest marker gap filled, frames")->capture_default_str();
  if (!outputs) return;
  c->add_option("-o,--output", a.out_mot, "OpenSim GRF .mot output");
  c->add_option("--csv", a.out_csv, "Per-frame CSV output (sagittal frame)");
  c->add_option("--json", a.out_json, "JSON summary output");
  c->add_option("--opensim", a.opensim_dir,
                "Write FOLDER/TRIAL_grf.mot (whole trial), TRIAL_markers.trc and TRIAL_external_loads.xml in OpenSim's frame "
                "(Y up, X forward), ready for the ID tool");
  c->add_option("--opensim-bodies", a.opensim_bodies, "Bodies the right and left forces are applied to (default calcn_r calcn_l)")
      ->expected(2);
}

kin2grf::EstimateOptions to_options(const EstimateArgs& a) {
  kin2grf::EstimateOptions o;
  o.mass_kg = a.mass;  // any given value, checked by the library (a negative one is refused, not ignored)
  o.allow_unusual_mass = a.force_mass;
  o.anthropometry = (a.paper && !a.anthropometry_given) ? "winter" : a.anthropometry;
  o.kinematic_cutoff_hz = a.kin_cutoff;
  o.post_cutoff_hz = a.post_cutoff;
  o.ground_level_m = a.ground_level;
  o.contact.foot_model = a.foot_model == "cop" ? kin2grf::FootModel::Cop : kin2grf::FootModel::ThreePoint;
  o.contact.ground_shift_m = a.ground_shift;
  if (a.grm_reference.size() == 2) o.grm_reference_m = Eigen::Vector2d(a.grm_reference[0], a.grm_reference[1]);
  if (a.paper) o.contact.cop = kin2grf::CopFunction::paper();
  if (!a.cop_function.empty()) o.contact.cop = kin2grf::read_cop_function(a.cop_function);
  // The running function: kin2grf's own unless the paper's configuration, a user's function for
  // every frame, or "off" is asked for; a file replaces it.
  if (a.running_cop == "off" || (a.running_cop == "builtin" && (a.paper || !a.cop_function.empty()))) o.contact.running_cop.reset();
  else if (a.running_cop != "builtin") o.contact.running_cop = kin2grf::read_cop_function(a.running_cop);
  o.solver.r_N_per_m = (a.paper && !a.r_given) ? 1e4 : a.r;
  o.solver.norm = (a.paper || a.norm == "paper") ? kin2grf::MultiplierNorm::Paper : kin2grf::MultiplierNorm::TorqueScaled;
  o.solver.speed_gate_mps = a.paper ? 0.0 : a.speed_gate;
  o.solver.speed_gate_ratio = a.paper ? 0.0 : a.speed_gate_ratio;
  o.solver.speed_gate_floor_mps = a.speed_gate_floor;
  o.solver.min_split_distance_m = a.paper ? 0.0 : a.split_distance;
  o.torso_length = (a.paper || a.torso_length == "fixed") ? kin2grf::TorsoLength::Fixed : kin2grf::TorsoLength::Measured;
  o.landmarks.max_gap_frames = a.max_gap;
  o.landmarks.up_axis = parse_axis(a.up_axis);
  return o;
}

/// The settings a run used, from the resolved options (what --paper and the defaults made of them).
nlohmann::json settings_json(const EstimateArgs& a, const kin2grf::EstimateOptions& o) {
  const auto& c = o.contact.cop;
  return {{"trial", a.trial},
          {"static", a.static_trial},
          {"paper_configuration", a.paper},
          {"foot_model", a.foot_model},
          {"cop_function", {{"source", !a.cop_function.empty() ? a.cop_function : a.paper ? "paper event angles" : "built-in fit"},
                            {"delta_rad", {c.delta_hs, c.delta_ho, c.delta_mo, c.delta_to}},
                            {"s", {c.s_hs, c.s_ho, c.s_mo, c.s_to}}}},
          {"running_cop_function", o.contact.running_cop ? nlohmann::json{{"source", a.running_cop == "builtin" ? "built-in running fit" : a.running_cop},
                                                                         {"delta_rad", {o.contact.running_cop->delta_hs, o.contact.running_cop->delta_ho, o.contact.running_cop->delta_mo, o.contact.running_cop->delta_to}},
                                                                         {"s", {o.contact.running_cop->s_hs, o.contact.running_cop->s_ho, o.contact.running_cop->s_mo, o.contact.running_cop->s_to}}}
                                                       : nlohmann::json(nullptr)},
          {"r_N_per_m", o.solver.r_N_per_m},
          {"norm", o.solver.norm == kin2grf::MultiplierNorm::Paper ? "paper" : "torque-scaled"},
          {"speed_gate_mps", o.solver.speed_gate_mps},
          {"speed_gate_ratio", o.solver.speed_gate_ratio},
          {"speed_gate_floor_mps", o.solver.speed_gate_floor_mps},
          {"min_split_distance_m", o.solver.min_split_distance_m},
          {"torso_length", torso_length_name(o.torso_length)},
          {"kinematic_cutoff_hz", o.kinematic_cutoff_hz},
          {"post_cutoff_hz", o.post_cutoff_hz},
          {"anthropometry", o.anthropometry},
          {"ground_level_m", o.ground_level_m ? nlohmann::json(*o.ground_level_m) : nlohmann::json("auto")},
          {"ground_shift_m", o.contact.ground_shift_m},
          {"grm_reference_m", {o.grm_reference_m.x(), o.grm_reference_m.y()}},
          {"max_gap_frames", o.landmarks.max_gap_frames}};
}

/// The marker set: --markers (preset name or mapping file), else recognised from the names.
const kin2grf::MarkerSet& resolve_marker_set(const EstimateArgs& a, const kin2grf::Trial& trial, kin2grf::MarkerSet& custom) {
  if (!a.markers.empty()) {
    if (const auto* set = kin2grf::find_marker_set(a.markers)) return *set;
    custom = kin2grf::load_marker_set(a.markers);
    return custom;
  }
  std::string why;
  const auto* set = kin2grf::recognise_marker_set(trial.markers, &why);
  if (!set) {
    std::string names;
    for (const auto& s : kin2grf::builtin_marker_sets()) names += " " + s.name;
    throw kin2grf::InputError(a.trial + ": marker set not recognised (presets:" + names +
                              "). Give --markers FILE.json with a rule for each landmark: shoulder, hip, knee_r, "
                              "ankle_r, heel_r, mt_r, hallux_r and the same _l (see docs/MARKERSETS.md)");
  }
  std::cerr << "kin2grf: marker set recognised: " << set->name << " (" << why << ")\n";
  return *set;
}

kin2grf::EstimateResult run_estimate_core(const EstimateArgs& a, kin2grf::EstimateOptions options, const kin2grf::Trial& trial) {
  std::optional<kin2grf::Trial> st;
  if (!a.static_trial.empty()) st = kin2grf::load_trial(a.static_trial);
  kin2grf::MarkerSet custom;
  const kin2grf::MarkerSet& set = resolve_marker_set(a, trial, custom);
  if (trial.markers.frames() >= kProgressFrames) {
    // Long inputs: progress on stderr, on one line when stderr is a terminal.
    const bool tty = isatty(fileno(stderr)) != 0;
    options.progress = [tty, last = -1](long done, long all) mutable {
      const int pct = static_cast<int>(100 * done / std::max(1L, all));
      if (pct / 10 == last / 10 && pct != 100 && !tty) return;
      if (pct == last) return;
      last = pct;
      std::fprintf(stderr, tty ? "\rkin2grf: contact solve %3d %% (%ld of %ld frames)" : "kin2grf: contact solve %3d %% (%ld of %ld frames)\n",
                   pct, done, all);
      if (tty && pct == 100) std::fputc('\n', stderr);
    };
  }
  std::optional<kin2grf::EstimateResult> res;
  try {
    res = kin2grf::estimate(trial, st ? &*st : nullptr, set, options);
  } catch (const kin2grf::InputError&) {
    // The readers' warnings travel in the result; when there is none, say them before the error.
    for (const auto& w : trial.warnings) std::cerr << "kin2grf: input: " << w << "\n";
    if (st)
      for (const auto& w : st->warnings) std::cerr << "kin2grf: static trial: " << w << "\n";
    throw;
  }
  auto& r = *res;
  for (const auto& m : r.messages) std::cerr << "kin2grf: " << m << "\n";
  std::cerr << "kin2grf: " << r.time_s.size() << " frames, mass " << r.mass_kg << " kg, "
            << static_cast<long>(static_cast<double>(r.time_s.size()) / std::max(1e-9, r.seconds_kinematics + r.seconds_dynamics))
            << " frames/s\n";
  return std::move(*res);
}

/// The files a run reads: no output may be one of them.
std::vector<std::string> inputs_of(const EstimateArgs& a) {
  std::vector<std::string> in = {a.trial, a.static_trial, a.markers, a.cop_function};
  if (a.running_cop != "builtin" && a.running_cop != "off") in.push_back(a.running_cop);
  return in;
}

void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  for (const auto& o : outputs) kin2grf::ensure_not_an_input(o, inputs);
}

/// The three files of --opensim (write_opensim_export's names), or none.
std::vector<std::string> opensim_outputs(const EstimateArgs& a) {
  if (a.opensim_dir.empty()) return {};
  const std::string stem = std::filesystem::path(a.trial).stem().string();
  std::vector<std::string> out;
  for (const char* suffix : {"_grf.mot", "_markers.trc", "_external_loads.xml"})
    out.push_back((std::filesystem::path(a.opensim_dir) / (stem + suffix)).string());
  return out;
}

int run_estimate(const EstimateArgs& a) {
  check_outputs({a.out_mot, a.out_csv, a.out_json}, inputs_of(a));
  check_outputs(opensim_outputs(a), inputs_of(a));
  const kin2grf::Trial trial = kin2grf::load_trial(a.trial);
  const auto options = to_options(a);
  const auto r = run_estimate_core(a, options, trial);
  if (!a.out_mot.empty()) kin2grf::write_grf_mot(a.out_mot, r);
  if (!a.out_csv.empty()) kin2grf::write_file_text(a.out_csv, kin2grf::format_results_csv(r));
  if (!a.out_json.empty()) kin2grf::write_file_text(a.out_json, kin2grf::json_text(kin2grf::results_summary(r, settings_json(a, options))));
  std::cout << kin2grf::format_results_text(r);
  for (const auto& [file, what] : {std::pair{a.out_mot, "OpenSim GRF"}, {a.out_csv, "per-frame CSV"}, {a.out_json, "JSON summary"}})
    if (!file.empty()) std::cout << "wrote " << file << " (" << what << ")\n";
  if (!a.opensim_dir.empty()) {
    kin2grf::OpenSimExportOptions eo;
    if (a.opensim_bodies.size() == 2) eo.right_body = a.opensim_bodies[0], eo.left_body = a.opensim_bodies[1];
    const auto f = kin2grf::write_opensim_export(a.opensim_dir, std::filesystem::path(a.trial).stem().string(), trial, r, eo);
    std::cout << "wrote " << f.grf_mot << ", " << f.markers_trc << " and " << f.external_loads_xml
              << " (OpenSim: Y up, X forward; sagittal model: no mediolateral force or free moment)\n";
  }
  if (a.out_mot.empty() && a.out_csv.empty() && a.out_json.empty() && a.opensim_dir.empty())
    std::cout << "(-o GRF.mot, --csv FILE and --json FILE write the per-frame results and the full summary)\n";
  return 0;
}

struct ValidateArgs {
  EstimateArgs est;
  std::string plates, out_json, report, zero_offset = "unloaded";
  kin2grf::ValidationOptions options;
};

int run_validate(const ValidateArgs& a) {
  {
    auto in = inputs_of(a.est);
    in.push_back(a.plates);
    check_outputs({a.out_json, a.report}, in);
  }
  if (!(std::isfinite(a.options.threshold_N) && a.options.threshold_N > 0))
    throw kin2grf::InputError("--threshold " + std::to_string(a.options.threshold_N) + ": must be a force above 0 N");
  const kin2grf::Trial trial = kin2grf::load_trial(a.est.trial, load_options(a.zero_offset));
  std::optional<kin2grf::Trial> plates_file;
  if (!a.plates.empty()) plates_file = kin2grf::load_trial(a.plates, load_options(a.zero_offset));
  const kin2grf::Trial& source = plates_file ? *plates_file : trial;
  if (!source.plates || source.plates->plates.empty())
    throw kin2grf::InputError(source.path + ": no force plates to validate against" +
                              (plates_file ? std::string() : std::string("; give --plates GRF.mot")));
  const auto options = to_options(a.est);
  const auto r = run_estimate_core(a.est, options, trial);
  const auto v = kin2grf::validate(r, *source.plates, a.options);
  nlohmann::json settings = settings_json(a.est, options);
  settings["plates"] = source.path;
  settings["threshold_N"] = a.options.threshold_N;
  settings["zero_offset"] = a.zero_offset;
  std::cout << kin2grf::format_validation_table(a.est.trial, v);
  const auto j = kin2grf::validation_json(a.est.trial, r, v, settings);
  if (!a.out_json.empty()) kin2grf::write_file_text(a.out_json, kin2grf::json_text(j));
  if (!a.report.empty()) kin2grf::write_file_text(a.report, kin2grf::validation_report_html(a.est.trial, r, v, j));
  return 0;
}

/// `study`: one line of a trial list is "activity|lab|name|TRIAL [estimate options] [--plates FILE]"
/// (the older "activity|name|TRIAL" is read with each trial its own lab).
struct StudyInput {
  std::string activity, lab, name;
  EstimateArgs args;
  std::string plates;
};

std::vector<StudyInput> read_trial_list(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw kin2grf::InputError(path + ": cannot open the trial list");
  std::vector<StudyInput> out;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::size_t start = 0;
    for (std::size_t bar; fields.size() < 3 && (bar = line.find('|', start)) != std::string::npos; start = bar + 1)
      fields.push_back(line.substr(start, bar - start));
    if (fields.size() < 2)
      throw kin2grf::InputError(path + ":" + std::to_string(number) + ": expected activity|lab|name|TRIAL [options]");
    StudyInput si;
    si.activity = fields[0];
    si.lab = fields[1];  // the old 3-field form: the name is the lab
    si.name = fields.back();
    for (const auto& f : fields)
      if (f.empty()) throw kin2grf::InputError(path + ":" + std::to_string(number) + ": an empty field in activity|lab|name");
    CLI::App parser{"trial"};
    add_estimate_options(&parser, si.args, false);
    parser.add_option("--plates", si.plates);
    try {
      parser.parse(line.substr(start), false);
    } catch (const CLI::ParseError& e) {
      throw kin2grf::InputError(path + ":" + std::to_string(number) + ": " + e.what());
    }
    out.push_back(std::move(si));
  }
  if (out.empty()) throw kin2grf::InputError(path + ": no trials in the list");
  return out;
}

struct StudyArgs {
  std::string kind, trial_list, out_json, report, cross_validate;
  std::vector<std::string> trials;
  EstimateArgs est;
  std::string plates;
};

/// Trials of a study or fit, loaded once (the containers are reserved: pointers stay valid).
struct LoadedTrials {
  std::vector<kin2grf::Trial> trials, statics, plates;
  std::vector<kin2grf::MarkerSet> sets;
  std::vector<kin2grf::StudyTrial> study;
};

void load_study_trials(const std::vector<StudyInput>& inputs, LoadedTrials& L) {
  L.trials.reserve(inputs.size()), L.statics.reserve(inputs.size()), L.plates.reserve(inputs.size()), L.sets.reserve(inputs.size());
  for (const auto& in : inputs) {
    L.trials.push_back(kin2grf::load_trial(in.args.trial, load_options("unloaded")));
    kin2grf::StudyTrial x;
    x.name = in.name;
    x.activity = in.activity;
    x.lab = in.lab;
    x.trial = &L.trials.back();
    if (!in.args.static_trial.empty()) {
      L.statics.push_back(kin2grf::load_trial(in.args.static_trial));
      x.static_trial = &L.statics.back();
    }
    const kin2grf::Trial* source = x.trial;
    if (!in.plates.empty()) {
      L.plates.push_back(kin2grf::load_trial(in.plates, load_options("unloaded")));
      source = &L.plates.back();
    }
    if (!source->plates || source->plates->plates.empty())
      throw kin2grf::InputError(source->path + ": no force plates; give --plates");
    x.plates = &*source->plates;
    kin2grf::MarkerSet custom;
    L.sets.push_back(resolve_marker_set(in.args, *x.trial, custom));
    x.marker_set = &L.sets.back();
    x.options = to_options(in.args);
    L.study.push_back(x);
  }
}

int run_study(const StudyArgs& a) {
  {
    std::vector<std::string> in = a.trials;
    in.push_back(a.trial_list);
    check_outputs({a.out_json, a.report}, in);
  }
  std::vector<StudyInput> inputs;
  if (!a.trial_list.empty()) inputs = read_trial_list(a.trial_list);
  for (const auto& t : a.trials) {
    StudyInput si;
    si.activity = "trials";
    si.name = std::filesystem::path(t).filename().string();
    si.lab = si.name;
    si.args = a.est;
    si.args.trial = t;
    si.plates = a.plates;
    inputs.push_back(si);
  }
  if (inputs.empty()) throw kin2grf::InputError("study: give TRIAL files or --trial-list FILE");
  LoadedTrials L;
  load_study_trials(inputs, L);
  const auto& st = L.study;
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
  std::vector<StudyInput> inputs;
  for (auto& in : read_trial_list(a.trial_list))
    if (a.activity.empty() || in.activity == a.activity) inputs.push_back(in);
  if (inputs.empty()) throw kin2grf::InputError(a.trial_list + ": no trial of activity '" + a.activity + "'");
  LoadedTrials L;
  load_study_trials(inputs, L);
  // Start (and, without --fit-angles, keep) the paper's event angles.
  const kin2grf::CopFunction start = kin2grf::CopFunction::paper();
  const auto res = kin2grf::fit_cop_on_trials(L.study, start, a.min_force, a.fit_angles, a.leave_one_out);
  const auto& fit = res.fit;
  nlohmann::json j = kin2grf::cop_function_json(fit.function);
  nlohmann::json prov;
  prov["command"] = "kin2grf fit-cop --trial-list " + a.trial_list + " --activity " + a.activity +
                    (a.fit_angles ? " --fit-angles" : "") + (a.leave_one_out ? " --leave-one-out" : "");
  prov["kin2grf_version"] = KIN2GRF_VERSION;
  prov["trials"] = nlohmann::json::array();
  for (std::size_t k = 0; k < L.study.size(); ++k)
    prov["trials"].push_back({{"name", L.study[k].name}, {"samples", res.samples_per_trial[k]}});
  prov["samples"] = fit.samples;
  prov["event_angles"] = a.fit_angles ? "fitted" : "fixed (the paper's)";
  prov["min_force_fraction_of_body_weight"] = a.min_force;
  prov["rms_fraction_before"] = fit.rms_fraction_before;
  prov["rms_fraction_after"] = fit.rms_fraction;
  prov["start"] = kin2grf::cop_function_json(start);
  std::printf("COP function fitted on %d samples of %zu trials (%s)\n", fit.samples, L.study.size(), a.activity.c_str());
  std::printf("  event angles (rad)   HS %.3f  HO %.3f  MO %.3f  TO %.3f\n", fit.function.delta_hs, fit.function.delta_ho,
              fit.function.delta_mo, fit.function.delta_to);
  std::printf("  positions (fraction) HS %.3f  HO %.3f  MO %.3f  TO %.3f   (start %.3f %.3f %.3f %.3f)\n", fit.function.s_hs,
              fit.function.s_ho, fit.function.s_mo, fit.function.s_to, start.s_hs, start.s_ho, start.s_mo, start.s_to);
  std::printf("  RMS of F(theta) - s: %.3f (start: %.3f)\n", fit.rms_fraction, fit.rms_fraction_before);
  if (a.leave_one_out) {
    std::printf("\nleave-one-lab-out: COP rRMSE %% (mean over the trial's stances; 'other labs': fitted without the trial's lab)\n"
                "%-26s %8s %8s %11s\n", "trial", "start", "all", "other labs");
    nlohmann::json loo = nlohmann::json::array();
    for (const auto& l : res.leave_one_out) {
      std::printf("%-26s %8.1f %8.1f %11.1f\n", l.trial.c_str(), l.start, l.all, l.others);
      loo.push_back({{"trial", l.trial}, {"start", l.start}, {"all", l.all}, {"other_labs", l.others}});
    }
    prov["leave_one_lab_out_cop_rrmse_percent"] = loo;
  }
  j["provenance"] = prov;
  if (!a.out.empty()) kin2grf::write_file_text(a.out, kin2grf::json_text(j));
  return 0;
}

/// The bundled example: a synthetic squat on two force plates whose signals are the model's own
/// ground reactions (written by kin2grf's own C3D, TRC and MOT writers).
int run_make_example(const std::string& dir, double seconds) {
  if (!(std::isfinite(seconds) && seconds >= 1.0 && seconds <= 600.0))
    throw kin2grf::InputError("--seconds " + std::to_string(seconds) + ": must be between 1 and 600");
  std::filesystem::create_directories(dir);
  kin2grf::SyntheticOptions so;
  so.duration_s = seconds;
  kin2grf::Trial t = kin2grf::make_synthetic_trial(so);
  const auto* set = kin2grf::find_marker_set("kin2grf-example");
  kin2grf::EstimateOptions eo;
  const auto r = kin2grf::estimate(t, nullptr, *set, eo);
  t.plates = kin2grf::example_plates(r, t, 0);
  const std::string base = (std::filesystem::path(dir) / "example_squat").string();
  kin2grf::write_c3d(base + ".c3d", t);
  kin2grf::write_trc(base + ".trc", t.markers);
  kin2grf::write_grf_mot(base + "_grf.mot", r);
  std::cout << "wrote " << base << ".c3d, .trc and _grf.mot\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kin2grf: ground reaction forces, centre of pressure and joint torques from "
               "motion-capture markers alone (no force plates)"};
  app.set_version_flag("--version", std::string("kin2grf ") + KIN2GRF_VERSION);
  app.require_subcommand(1);

  std::string info_file;
  bool info_json = false;
  double info_threshold = 20.0;
  auto* info = app.add_subcommand("info", "Describe a recording (C3D, TRC, MOT/STO) before processing it");
  info->add_option("FILE", info_file, "The recording")->required();
  info->add_flag("--json", info_json, "Write the description as JSON (schema in docs/FORMATS.md)");
  std::string info_zero = "none";
  info->add_option("--zero-offset", info_zero,
                   "C3D plate offsets: none, zero (FORCE_PLATFORM:ZERO frames) or unloaded (median of unloaded samples)")
      ->check(CLI::IsMember({"none", "zero", "unloaded"}))->capture_default_str();
  std::string info_up_axis;
  info->add_option("--up-axis", info_up_axis, "The lab up axis (X, Y or Z); default: the data's (plates' normal, markers' spread)");
  info->add_option("--load-threshold", info_threshold, "Vertical force (N) above which a plate counts as loaded")
      ->capture_default_str();

  EstimateArgs est;
  auto* estimate = app.add_subcommand("estimate", "Estimate GRF, COP, GRM and joint torques from markers");
  add_estimate_options(estimate, est);

  ValidateArgs val;
  auto* validate = app.add_subcommand("validate", "Estimate, then compare with the trial's force plates (paper's Eqs. 11-12)");
  add_estimate_options(validate, val.est, false);
  validate->add_option("--plates", val.plates, "Measured forces from this file (GRF .mot/.sto or C3D) instead of the trial's plates");
  validate->add_option("--json", val.out_json, "Validation results as JSON (schema in docs/FORMATS.md)");
  validate->add_option("--report", val.report, "Self-contained HTML report with plots");
  validate->add_option("--threshold", val.options.threshold_N, "Stance: measured vertical force above this, N")->capture_default_str();
  validate->add_option("--zero-offset", val.zero_offset, "C3D plate offsets: none, zero or unloaded")
      ->check(CLI::IsMember({"none", "zero", "unloaded"}))->capture_default_str();

  StudyArgs study_args;
  auto* study = app.add_subcommand("study", "The paper's parameter studies on trials with plates: r, ground-shift, cutoff, "
                                            "kinematic-cutoff, speed-gate, split-distance, torso-length, foot-model");
  study->add_option("KIND", study_args.kind, "r | ground-shift | cutoff | kinematic-cutoff | speed-gate | split-distance | torso-length | foot-model")
      ->required()->check(CLI::IsMember({"r", "ground-shift", "cutoff", "kinematic-cutoff", "speed-gate", "speed-gate-ratio", "noise", "split-distance", "torso-length", "foot-model"}));
  study->add_option("TRIAL", study_args.trials, "Trials with plates (the options below apply to all of them)");
  study->add_option("--trial-list", study_args.trial_list,
                    "File of lines 'activity|lab|name|TRIAL [options]', each trial with its own options");
  study->add_option("--cross-validate", study_args.cross_validate,
                    "Also choose the setting leave-one-lab-out and print in-sample against held-out figures")
      ->check(CLI::IsMember({"lab"}));
  study->add_option("--plates", study_args.plates, "Measured forces for the TRIAL arguments (GRF .mot)");
  study->add_option("--json", study_args.out_json, "Study results as JSON");
  study->add_option("--report", study_args.report, "HTML report with the rRMSE-against-setting plots");
  {
    // Estimate options for the TRIAL arguments (without outputs; TRIAL is positional above).
    auto& e = study_args.est;
    study->add_option("--static", e.static_trial, "Static trial");
    study->add_option("--markers", e.markers, "Marker-set preset or mapping file");
    study->add_option("--mass", e.mass, "Body mass, kg");
    study->add_flag("--paper", e.paper, "The paper's configuration");
  }

  FitCopArgs fit_args;
  auto* fit_cop = app.add_subcommand("fit-cop", "Fit foot model 2's COP function to the plate COPs of trials with plates");
  fit_cop->add_option("--trial-list", fit_args.trial_list, "File of lines 'activity|lab|name|TRIAL [options]'")->required();
  fit_cop->add_option("--activity", fit_args.activity, "Use the trials of this activity ('' = all)")->capture_default_str();
  fit_cop->add_option("--min-force", fit_args.min_force, "Frames where the plate carries at least this fraction of body weight")
      ->capture_default_str();
  fit_cop->add_flag("--fit-angles", fit_args.fit_angles, "Fit the event angles too (default: the paper's, fixed)");
  fit_cop->add_flag("--leave-one-out", fit_args.leave_one_out,
                    "Also report each trial's COP error with a fit on the other labs' trials (leave one lab out)");
  fit_cop->add_option("-o,--output", fit_args.out, "Write the fitted function and its provenance (JSON)");

  std::string example_dir = "example";
  double example_seconds = 3.0;
  auto* make_example = app.add_subcommand("make-example", "Write the synthetic example trial (C3D with plates, TRC, GRF .mot)");
  make_example->add_option("--out-dir", example_dir, "Output folder")->capture_default_str();
  make_example->add_option("--seconds", example_seconds, "Duration, s")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    int rc = 0;
    if (*info) rc = run_info(info_file, info_json, info_threshold, info_zero, info_up_axis);
    else if (*estimate) rc = run_estimate(est);
    else if (*validate) rc = run_validate(val);
    else if (*study) rc = run_study(study_args);
    else if (*fit_cop) rc = run_fit_cop(fit_args);
    else if (*make_example) rc = run_make_example(example_dir, example_seconds);
    // Standard output closed or full: the output is lost, so the run failed.
    std::cout.flush();
    if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout))
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
