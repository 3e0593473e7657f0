// kin2grf command line: a thin front end that wires the library's steps together and prints.
#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <optional>

#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/summary.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/validation/validate.hpp"
#include <filesystem>

namespace {

kin2grf::LoadOptions load_options(const std::string& zero) {
  kin2grf::LoadOptions lo;
  if (zero == "zero") lo.c3d.zero_offset = kin2grf::ZeroOffset::ZeroParameter;
  if (zero == "unloaded") lo.c3d.zero_offset = kin2grf::ZeroOffset::Unloaded;
  return lo;
}

int run_info(const std::string& file, bool json, double threshold, const std::string& zero) {
  const kin2grf::Trial t = kin2grf::load_trial(file, load_options(zero));
  const auto s = kin2grf::trial_summary(t, threshold);
  if (json) std::cout << s.dump(2) << "\n";
  else std::cout << kin2grf::format_summary(s);
  return 0;
}

struct EstimateArgs {
  std::string trial, static_trial, markers, out_mot, out_csv, out_json, foot_model = "cop", norm = "torque-scaled",
      anthropometry = "winter", up_axis;
  double mass = 0, r = 1e4, kin_cutoff = 6, post_cutoff = 12, ground_shift = 0, speed_gate = 2.0;
  bool paper = false;
  std::optional<double> ground_level;
  int max_gap = 10;
};

void add_estimate_options(CLI::App* c, EstimateArgs& a, bool outputs = true) {
  c->add_option("TRIAL", a.trial, "Motion trial (C3D or TRC)")->required();
  c->add_option("--static", a.static_trial, "Static calibration trial (for virtual knee/ankle landmarks)");
  c->add_option("--markers", a.markers, "Marker-set preset name or mapping file (JSON); default: recognised");
  c->add_option("--mass", a.mass, "Body mass, kg (default: PROCESSING:Bodymass of a C3D)");
  c->add_option("--foot-model", a.foot_model, "cop (paper's model 2) or three-point (model 1)")
      ->check(CLI::IsMember({"cop", "three-point"}))->capture_default_str();
  c->add_option("--r", a.r, "Activation parameter r, N/m (Eq. 8)")->capture_default_str();
  c->add_option("--kinematic-cutoff", a.kin_cutoff, "Kinematics low-pass cut-off, Hz")->capture_default_str();
  c->add_option("--post-cutoff", a.post_cutoff, "Multiplier post-filter cut-off, Hz")->capture_default_str();
  c->add_option("--ground-level", a.ground_level, "Floor height in the lab's up axis, m (default: estimated)");
  c->add_option("--ground-shift", a.ground_shift, "Shift the ground by this much, m (robustness study)")->capture_default_str();
  c->add_option("--speed-gate", a.speed_gate, "Contact allowed only below this sole speed, m/s (0 = off, the paper)")
      ->capture_default_str();
  c->add_option("--norm", a.norm, "Multiplier norm: paper (pseudo-inverse) or torque-scaled")
      ->check(CLI::IsMember({"paper", "torque-scaled"}))->capture_default_str();
  c->add_option("--anthropometry", a.anthropometry, "winter or de-leva")->capture_default_str();
  c->add_option("--up-axis", a.up_axis, "Override the lab up axis (X, Y or Z)");
  c->add_flag("--paper", a.paper, "The paper's own configuration: plain pseudo-inverse norm, no speed gate");
  c->add_option("--max-gap", a.max_gap, "Longest marker gap filled, frames")->capture_default_str();
  if (!outputs) return;
  c->add_option("-o,--output", a.out_mot, "OpenSim GRF .mot output");
  c->add_option("--csv", a.out_csv, "Per-frame CSV output (sagittal frame)");
  c->add_option("--json", a.out_json, "JSON summary output");
}

kin2grf::EstimateOptions to_options(const EstimateArgs& a) {
  kin2grf::EstimateOptions o;
  if (a.mass > 0) o.mass_kg = a.mass;
  o.anthropometry = a.anthropometry;
  o.kinematic_cutoff_hz = a.kin_cutoff;
  o.post_cutoff_hz = a.post_cutoff;
  o.ground_level_m = a.ground_level;
  o.contact.foot_model = a.foot_model == "cop" ? kin2grf::FootModel::Cop : kin2grf::FootModel::ThreePoint;
  o.contact.ground_shift_m = a.ground_shift;
  o.solver.r_N_per_m = a.r;
  o.solver.norm = (a.paper || a.norm == "paper") ? kin2grf::MultiplierNorm::Paper : kin2grf::MultiplierNorm::TorqueScaled;
  o.solver.speed_gate_mps = a.paper ? 0.0 : a.speed_gate;
  o.landmarks.max_gap_frames = a.max_gap;
  if (!a.up_axis.empty()) {
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(a.up_axis[0])));
    if (c < 'X' || c > 'Z' || a.up_axis.size() != 1) throw kin2grf::InputError("--up-axis must be X, Y or Z");
    o.landmarks.up_axis = static_cast<kin2grf::Axis>(c - 'X');
  }
  return o;
}

nlohmann::json settings_json(const EstimateArgs& a) {
  return {{"trial", a.trial}, {"static", a.static_trial}, {"foot_model", a.foot_model}, {"r_N_per_m", a.r},
          {"kinematic_cutoff_hz", a.kin_cutoff}, {"post_cutoff_hz", a.post_cutoff}, {"norm", a.paper ? std::string("paper") : a.norm},
          {"speed_gate_mps", a.paper ? 0.0 : a.speed_gate}, {"paper_configuration", a.paper}, {"anthropometry", a.anthropometry}, {"ground_shift_m", a.ground_shift},
          {"ground_level_m", a.ground_level ? nlohmann::json(*a.ground_level) : nlohmann::json("auto")}};
}

/// The marker set: --markers (preset name or mapping file), else recognised from the names.
const kin2grf::MarkerSet& resolve_marker_set(const EstimateArgs& a, const kin2grf::Trial& trial, kin2grf::MarkerSet& custom) {
  if (!a.markers.empty()) {
    if (const auto* set = kin2grf::find_marker_set(a.markers)) return *set;
    custom = kin2grf::load_marker_set(a.markers);
    return custom;
  }
  const auto* set = kin2grf::recognise_marker_set(trial.markers);
  if (!set) {
    std::string names;
    for (const auto& s : kin2grf::builtin_marker_sets()) names += " " + s.name;
    throw kin2grf::InputError(a.trial + ": marker set not recognised (presets:" + names +
                              "). Give --markers FILE.json with a rule for each landmark: shoulder, hip, knee_r, "
                              "ankle_r, heel_r, mt_r, hallux_r and the same _l (see docs/MARKERSETS.md)");
  }
  std::cerr << "kin2grf: marker set recognised: " << set->name << "\n";
  return *set;
}

kin2grf::EstimateResult run_estimate_core(const EstimateArgs& a, const kin2grf::Trial& trial) {
  std::optional<kin2grf::Trial> st;
  if (!a.static_trial.empty()) st = kin2grf::load_trial(a.static_trial);
  kin2grf::MarkerSet custom;
  const kin2grf::MarkerSet& set = resolve_marker_set(a, trial, custom);
  auto r = kin2grf::estimate(trial, st ? &*st : nullptr, set, to_options(a));
  for (const auto& m : r.messages) std::cerr << "kin2grf: " << m << "\n";
  std::cerr << "kin2grf: " << r.time_s.size() << " frames, mass " << r.mass_kg << " kg, "
            << static_cast<long>(static_cast<double>(r.time_s.size()) / std::max(1e-9, r.seconds_kinematics + r.seconds_dynamics))
            << " frames/s\n";
  return r;
}

int run_estimate(const EstimateArgs& a) {
  const kin2grf::Trial trial = kin2grf::load_trial(a.trial);
  const auto r = run_estimate_core(a, trial);
  if (!a.out_mot.empty()) kin2grf::write_grf_mot(a.out_mot, r);
  if (!a.out_csv.empty()) kin2grf::write_file_text(a.out_csv, kin2grf::format_results_csv(r));
  if (!a.out_json.empty()) kin2grf::write_file_text(a.out_json, kin2grf::results_summary(r, settings_json(a)).dump(2) + "\n");
  if (a.out_mot.empty() && a.out_csv.empty() && a.out_json.empty())
    std::cout << kin2grf::results_summary(r, settings_json(a)).dump(2) << "\n";
  return 0;
}

struct ValidateArgs {
  EstimateArgs est;
  std::string plates, out_json, report, zero_offset = "unloaded";
  kin2grf::ValidationOptions options;
};

int run_validate(const ValidateArgs& a) {
  const kin2grf::Trial trial = kin2grf::load_trial(a.est.trial, load_options(a.zero_offset));
  std::optional<kin2grf::Trial> plates_file;
  if (!a.plates.empty()) plates_file = kin2grf::load_trial(a.plates, load_options(a.zero_offset));
  const kin2grf::Trial& source = plates_file ? *plates_file : trial;
  if (!source.plates || source.plates->plates.empty())
    throw kin2grf::InputError(source.path + ": no force plates to validate against" +
                              (plates_file ? std::string() : std::string("; give --plates GRF.mot")));
  const auto r = run_estimate_core(a.est, trial);
  const auto v = kin2grf::validate(r, *source.plates, a.options);
  nlohmann::json settings = settings_json(a.est);
  settings["plates"] = source.path;
  settings["threshold_N"] = a.options.threshold_N;
  settings["zero_offset"] = a.zero_offset;
  std::cout << kin2grf::format_validation_table(a.est.trial, v);
  const auto j = kin2grf::validation_json(a.est.trial, r, v, settings);
  if (!a.out_json.empty()) kin2grf::write_file_text(a.out_json, j.dump(2) + "\n");
  if (!a.report.empty()) kin2grf::write_file_text(a.report, kin2grf::validation_report_html(a.est.trial, r, v, j));
  return 0;
}

/// The bundled example: a synthetic squat on two force plates whose signals are the model's own
/// ground reactions (written by kin2grf's own C3D, TRC and MOT writers).
int run_make_example(const std::string& dir, double seconds) {
  std::filesystem::create_directories(dir);
  kin2grf::SyntheticOptions so;
  so.duration_s = seconds;
  kin2grf::Trial t = kin2grf::make_synthetic_trial(so);
  const auto* set = kin2grf::find_marker_set("kin2grf-example");
  kin2grf::EstimateOptions eo;
  const auto r = kin2grf::estimate(t, nullptr, *set, eo);
  const auto feet = kin2grf::as_lab_plates(r);
  kin2grf::ForcePlateRecording rec;
  rec.rate_hz = t.markers.rate_hz;
  rec.time_s = t.markers.time_s;
  for (int side = 0; side < 2; ++side) {
    kin2grf::ForcePlate p = feet[side];
    p.name = side ? "FP2" : "FP1";
    p.type = 2;
    p.has_geometry = true;
    const double y0 = side ? 0.0 : -0.5;  // right plate at -Y, left at +Y
    p.corners_m = {Eigen::Vector3d(0.4, y0 + 0.5, 0), Eigen::Vector3d(-0.2, y0 + 0.5, 0), Eigen::Vector3d(-0.2, y0, 0),
                   Eigen::Vector3d(0.4, y0, 0)};
    Eigen::Matrix<double, 3, 4> C;
    for (int c = 0; c < 4; ++c) C.col(c) = p.corners_m[static_cast<std::size_t>(c)];
    p.lab_R_plate = kin2grf::plate_axes(C);
    p.centre_m = C.rowwise().mean();
    p.origin_m = Eigen::Vector3d(0, 0, -0.04);
    for (Eigen::Index i = 0; i < p.cop_m.rows(); ++i)
      if (!p.cop_m.row(i).allFinite()) p.cop_m.row(i) = p.centre_m.transpose();
    rec.plates.push_back(p);
  }
  t.plates = rec;
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
    if (*info) return run_info(info_file, info_json, info_threshold, info_zero);
    if (*estimate) return run_estimate(est);
    if (*validate) return run_validate(val);
    if (*make_example) return run_make_example(example_dir, example_seconds);
  } catch (const kin2grf::InputError& e) {
    std::cerr << "kin2grf: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "kin2grf: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
