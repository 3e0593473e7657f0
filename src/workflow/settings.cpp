// The command line's names for the settings, shared by the CLI, trial lists and Python.
#include "kin2grf/workflow/settings.hpp"

#include <CLI/CLI.hpp>

#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/trial.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/io/marker_labels.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/option_table.hpp"
#include "kin2grf/parallel.hpp"

namespace kin2grf {

namespace {
const char* torso_length_name(TorsoLength t) { return t == TorsoLength::Fixed ? "fixed" : "measured"; }

/// A setting that takes one of a few words, its default shown in the help.
void add_choice(CLI::App* c, const std::string& flag, std::string& value, const std::string& help, const std::vector<std::string>& words) {
  c->add_option(flag, value, help)->check(CLI::IsMember(words))->capture_default_str();
}
}  // namespace

void add_settings_options(CLI::App* c, Settings& a) {
  c->add_option("TRIAL", a.trial, "Motion trial (C3D or TRC)")->required();
  c->add_option("--static", a.static_trial, "Static calibration trial (for virtual knee/ankle landmarks)");
  c->add_option("--markers", a.markers, "Marker-set preset name, mapping file (JSON), or labels (a mapping made from the file's own marker labels); default: the preset recognised, else labels");
  c->add_option("--mass", a.mass, "Body mass, kg (default: the C3D's PROCESSING:Bodymass or SUBJECT(S):WEIGHT); 20-300");
  c->add_flag("--force-mass", a.force_mass, "Accept a body mass outside 20-300 kg");
  c->add_flag("--mediolateral", a.mediolateral,
              "Estimate each foot's mediolateral force too (the whole body's lateral acceleration, shared between the feet as "
              "--lateral-split says; docs/METHOD-NOTES.md); off: the sagittal model's zero lateral force");
  add_choice(c, "--model", a.model,
             "sagittal (the paper's model) or 3d: the sagittal results plus each foot's mediolateral force (as "
             "--mediolateral) and the ankles', knees' and hips' 3D moments, the knee adduction moment among them",
             {"sagittal", "3d"});
  add_choice(c, "--lateral-split", a.lateral_split,
             "How the feet share the whole body's lateral force (--model 3d): own-leg (each foot in contact carries its own "
             "lower leg's lateral inertia, the rest by vertical load) or load (all by vertical load)",
             {"own-leg", "load"});
  add_choice(c, "--upper-body", a.upper_body,
             "The arms and the head in the lateral force (--model 3d): segments (their own, where the marker set names their "
             "markers and the file holds them) or lumped (into the torso, as the sagittal model has them)",
             {"segments", "lumped"});
  add_choice(c, "--lateral-lag", a.lateral_lag,
             "The torso's share of the lateral force (--model 3d): torso (delayed as its fore-aft force is, by --torso-lag less "
             "what the trunk markers already lag the hip by, where trunk markers measure the torso and away from flight phases) "
             "or none",
             {"torso", "none"});
  add_choice(c, "--lateral-bilateral", a.lateral_bilateral,
             "The lateral force in a landing's bilateral stance (both feet down near a flight phase): least-squares (the paper's "
             "least squares with the legs' 3D joint moments) or split (as --lateral-split, as everywhere else)",
             {"least-squares", "split"});
  add_choice(c, "--foot-model", a.foot_model, "cop (paper's model 2) or three-point (model 1)", {"cop", "three-point"});
  c->add_option_function<double>(
       "--r", [&a](double v) { a.r = v, a.r_given = true; },
       "Activation parameter r, N/m (Eq. 8); default 1000 (from `kin2grf study r`), 10000 with --paper");
  c->add_option("--kinematic-cutoff", a.kinematic_cutoff, "Kinematics low-pass cut-off, Hz")->capture_default_str();
  add_choice(c, "--kinematic-cutoff-rule", a.kinematic_cutoff_rule,
             "noise: --kinematic-cutoff lowered where the markers' noise needs it (residual analysis); fixed: as given (--paper)",
             {"noise", "fixed"});
  c->add_option("--post-cutoff", a.post_cutoff,
                "Multiplier post-filter at this fixed cut-off, Hz (the paper: 12; 0: none); replaces --post-cutoff-cycles");
  c->add_option_function<double>(
       "--post-cutoff-cycles", [&a](double v) { a.post_cutoff_cycles = v, a.post_cutoff_cycles_given = true; },
       "Multiplier post-filter cut-off as cycles per stance: this over the trial's median stance duration (default 4; "
       "0, --paper or a trial with no complete stance: 12 Hz)");
  c->add_option("--ground-level", a.ground_level, "Floor height in the lab's up axis, m (default: estimated)");
  c->add_option("--grm-reference", a.grm_reference,
                 "GRM reference point in the sagittal frame: along progression and up from the lab origin, m (default 0 0)")
      ->expected(2);
  c->add_option_function<double>(
       "--speed-gate", [&a](double v) { a.speed_gate = v, a.numeric.contact.speed_gate.ratio = 0; },
       "A fixed speed gate: contact allowed only below this sole speed, m/s (0 = off, the paper); replaces --speed-gate-ratio")
      ->check(CLI::Range(0.0, 20.0));
  add_choice(c, "--torso-length", a.torso_length,
             "measured (the hip-shoulder distance of each frame, filtered) or fixed (its median, the paper's rigid HAT)",
             {"measured", "fixed"});
  add_choice(c, "--kinematic-edges", a.kinematic_edges,
             "How the kinematics' low-pass filter extends the coordinates past the processed window's ends: curvature (each end's own "
             "acceleration kept, from a quadratic over half a cut-off period) or odd (a point-symmetric reflection, which reads the "
             "ends' acceleration as zero; --paper)",
             {"curvature", "odd"});
  add_choice(c, "--norm", a.norm, "Multiplier norm: paper (pseudo-inverse) or torque-scaled", {"paper", "torque-scaled"});
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
  c->add_flag("--paper", a.paper, "The paper's own configuration: plain pseudo-inverse norm, no speed gate, no side-by-side split, fixed torso length, no torso or thigh lag, no vertical smoothing of the torso, no time scale for a leg outside the development subjects', the kinematics filtered with the odd reflection at the window's ends");
  c->add_option("--max-gap", a.max_gap, "Longest landmark gap filled by cubic interpolation, frames")->capture_default_str();
  add_choice(c, "--rigid-fill", a.rigid_fill,
             "A marker's longer gap inside the trial: on (filled from three markers that move rigidly with it, where the "
             "trial has them; the message names them) or off (it ends the processed window)",
             {"on", "off"});
  c->add_option("--frames", a.frames,
                "Process only the file's frames FIRST:LAST (its own frame numbers, inclusive; FIRST: or :LAST leave an end "
                "open), as if the trial were cut there");
  for (const NumericOption& s : numeric_options()) {
    CLI::Option* opt = c->add_option(std::string("--") + s.flag, s.field(a.numeric), s.help)->capture_default_str();
    if (s.lo <= s.hi) opt->check(CLI::Range(s.lo, s.hi));
  }
}

void parse_settings(const std::vector<std::string>& words, Settings& s, const std::string& where) {
  CLI::App parser{"settings"};
  add_settings_options(&parser, s);
  std::vector<std::string> args(words.rbegin(), words.rend());  // CLI11 parses a reversed vector
  try {
    parser.parse(args);
  } catch (const CLI::ParseError& e) {
    throw InputError(where + ": " + e.what());
  }
}

LoadOptions load_options(const std::string& zero) {
  LoadOptions lo;
  if (zero == "zero") lo.c3d.zero_offset = ZeroOffset::ZeroParameter;
  else if (zero == "unloaded") lo.c3d.zero_offset = ZeroOffset::Unloaded;
  else if (zero != "none") throw InputError("zero offset '" + zero + "': must be none, zero or unloaded");
  return lo;
}

std::optional<Axis> parse_axis(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
  if (c < 'X' || c > 'Z' || text.size() != 1) throw InputError("up axis '" + text + "': must be X, Y or Z");
  return static_cast<Axis>(c - 'X');
}

EstimateOptions to_options(const Settings& a) {
  EstimateOptions o;
  o.mass_kg = a.mass;  // any given value, checked by the library (a negative one is refused, not ignored)
  o.allow_unusual_mass = a.force_mass;
  o.mediolateral = a.mediolateral;
  o.model = model_kind(a.model);
  o.lateral_own_leg_inertia = a.lateral_split == "own-leg";
  o.upper_body_segments = a.upper_body == "segments";
  o.lateral_torso_lag = a.lateral_lag == "torso";
  o.lateral_least_squares = a.lateral_bilateral == "least-squares";
  o.anthropometry = (a.paper && !a.anthropometry_given) ? "winter" : a.anthropometry;
  o.kinematic_cutoff_hz = a.kinematic_cutoff;
  if (a.post_cutoff && a.post_cutoff_cycles_given)
    throw InputError("--post-cutoff and --post-cutoff-cycles: give one of them (a fixed cut-off or one per stance)");
  if (a.post_cutoff) o.post_cutoff_hz = *a.post_cutoff;
  const bool fixed_post_cutoff = a.post_cutoff || (a.paper && !a.post_cutoff_cycles_given);
  o.post_cutoff_cycles = fixed_post_cutoff ? 0.0 : a.post_cutoff_cycles;
  o.cutoff_from_noise = !a.paper && a.kinematic_cutoff_rule == "noise";
  o.ground_level_m = a.ground_level;
  o.contact.foot_model = a.foot_model == "cop" ? FootModel::Cop : FootModel::ThreePoint;
  if (a.grm_reference.size() == 2) o.grm_reference_m = Eigen::Vector2d(a.grm_reference[0], a.grm_reference[1]);
  if (a.paper) o.contact.cop = CopFunction::paper();
  if (!a.cop_function.empty()) o.contact.cop = read_cop_function(a.cop_function);
  // The running function: kin2grf's own unless the paper's configuration, a user's function for
  // every frame, or "off" is asked for; a file replaces it.
  if (a.running_cop == "off" || (a.running_cop == "builtin" && (a.paper || !a.cop_function.empty()))) o.contact.running_cop.reset();
  else if (a.running_cop != "builtin") o.contact.running_cop = read_cop_function(a.running_cop);
  o.solver.r_N_per_m = (a.paper && !a.r_given) ? 1e4 : a.r;
  o.solver.norm = (a.paper || a.norm == "paper") ? MultiplierNorm::Paper : MultiplierNorm::TorqueScaled;
  o.contact.speed_gate.fixed_mps = a.paper ? 0.0 : a.speed_gate;
  o.torso_length = (a.paper || a.torso_length == "fixed") ? TorsoLength::Fixed : TorsoLength::Measured;
  o.kinematic_edges = (a.paper || a.kinematic_edges == "odd") ? FilterEdge::OddReflection : FilterEdge::Curvature;
  o.landmarks.max_gap_frames = a.max_gap;
  o.landmarks.rigid_fill = a.rigid_fill == "on";
  o.landmarks.up_axis = parse_axis(a.up_axis);
  EstimateOptions given = a.numeric;
  for (const NumericOption& s : numeric_options()) s.field(o) = (a.paper && s.paper) ? *s.paper : s.field(given);
  return o;
}

namespace {
nlohmann::json cop_json(const CopFunction& c, const std::string& source) {
  return {{"source", source},
          {"delta_rad", {c.delta_hs, c.delta_ho, c.delta_mo, c.delta_to}},
          {"s", {c.s_hs, c.s_ho, c.s_mo, c.s_to}},
          {"com_gain", c.com_gain},
          {"length", cop_length_name(c.length)}};
}
}  // namespace

nlohmann::json settings_json(const Settings& a, const EstimateOptions& o) {
  nlohmann::json j = {{"trial", a.trial},
          {"static", a.static_trial},
          {"paper_configuration", a.paper},
          {"foot_model", a.foot_model},
          {"cop_function", cop_json(o.contact.cop, !a.cop_function.empty() ? a.cop_function : a.paper ? "paper event angles" : "built-in fit")},
          {"running_cop_function", o.contact.running_cop
                                       ? cop_json(*o.contact.running_cop, a.running_cop == "builtin" ? "built-in running fit" : a.running_cop)
                                       : nlohmann::json(nullptr)},
          {"r_N_per_m", o.solver.r_N_per_m},
          {"norm", o.solver.norm == MultiplierNorm::Paper ? "paper" : "torque-scaled"},
          {"speed_gate_mps", o.contact.speed_gate.fixed_mps},
          {"model", model_kind_name(o.model)},
          {"mediolateral", o.lateral_force()},
          {"lateral_split", o.lateral_own_leg_inertia ? "own-leg" : "load"},
          {"upper_body", o.upper_body_segments ? "segments" : "lumped"},
          {"lateral_lag", o.lateral_torso_lag ? "torso" : "none"},
          {"lateral_bilateral", o.lateral_least_squares ? "least-squares" : "split"},
          {"torso_length", torso_length_name(o.torso_length)},
          {"kinematic_edges", filter_edge_name(o.kinematic_edges)},
          {"kinematic_cutoff_hz", o.kinematic_cutoff_hz},
          {"kinematic_cutoff_rule", o.cutoff_from_noise ? "noise" : "fixed"},
          {"post_cutoff_hz", o.post_cutoff_hz},
          {"post_cutoff_cycles", o.post_cutoff_cycles},
          {"anthropometry", o.anthropometry},
          {"ground_level_m", o.ground_level_m ? nlohmann::json(*o.ground_level_m) : nlohmann::json("auto")},
          {"grm_reference_m", {o.grm_reference_m.x(), o.grm_reference_m.y()}},
          {"max_gap_frames", o.landmarks.max_gap_frames},
          {"rigid_fill", o.landmarks.rigid_fill ? "on" : "off"},
          {"frames", a.frames.empty() ? nlohmann::json("all") : nlohmann::json(a.frames)}};
  EstimateOptions used = o;
  for (const NumericOption& s : numeric_options()) j[s.json_key] = s.field(used);
  return j;
}

const MarkerSet& resolve_marker_set(const Settings& a, const Trial& trial, MarkerSet& custom, std::string* why, const Trial* static_trial) {
  std::vector<std::string> presets;
  for (const auto& s : builtin_marker_sets()) presets.push_back(s.name);
  // A mapping made from the file's own labels (io/marker_labels.hpp): every rule is said in `why`,
  // and a landmark no label gives is named in the error.
  const auto from_labels = [&](const std::string& because, const std::string& presets_tried) -> const MarkerSet& {
    const LabelMapping lm = map_marker_labels(trial.markers, static_trial ? &static_trial->markers : nullptr);
    if (!lm.mapping) {
      std::string found, lacking;
      for (const auto& r : lm.rules) found += "\n  " + r;
      for (const auto& r : lm.missing) lacking += "\n  " + r;
      std::string empty;
      constexpr std::size_t kListed = 12;
      for (std::size_t i = 0; i < std::min(lm.too_few.size(), kListed); ++i) empty += (i ? ", " : "") + lm.too_few[i];
      if (lm.too_few.size() > kListed) empty += " and " + std::to_string(lm.too_few.size() - kListed) + " more";
      throw InputError(a.trial + ": " + because + presets_tried + "; from the file's labels no mapping could be made. Missing:" + lacking +
                       (found.empty() ? std::string() : "\nFound:" + found) +
                       (empty.empty() ? std::string()
                                      : "\nLeft out for holding samples in too few of the trial's " + std::to_string(trial.markers.frames()) +
                                            " frames (under a fifth of the best-held marker's): " + empty) +
                       "\nGive a mapping file (--markers FILE.json, docs/MARKERSETS.md) with a rule for each landmark: shoulder, hip, knee_r, "
                       "ankle_r, heel_r, mt_r, hallux_r and the same _l; `kin2grf info " + a.trial +
                       " --write-mapping FILE.json` writes what the labels give, to complete");
    }
    custom = parse_marker_set(*lm.mapping, a.trial + " (its labels)");
    if (why) {
      *why = "made from the file's labels (" + because + "): ";
      for (std::size_t i = 0; i < lm.rules.size(); ++i) *why += (i ? "; " : "") + lm.rules[i];
      for (const auto& n : lm.notes) *why += "; " + n;
    }
    return custom;
  };
  if (a.markers == "labels") return from_labels("--markers labels", "");
  if (!a.markers.empty()) {
    if (const auto* set = find_marker_set(a.markers)) return *set;
    std::error_code ec;
    if (!std::filesystem::exists(a.markers, ec)) {
      // Neither a preset nor a file: most likely a preset's name misspelt.
      std::string list;
      for (const auto& n : presets) list += (list.empty() ? "" : ", ") + n;
      const std::string near = closest_match(a.markers, presets);
      throw InputError("--markers " + a.markers + ": neither a preset nor a file" + (near.empty() ? "" : "; did you mean " + near + "?") +
                       " (presets: " + list + "; labels, a mapping from the file's own labels; or a mapping file, docs/MARKERSETS.md)");
    }
    custom = load_marker_set(a.markers);
    return custom;
  }
  if (trial.markers.names.empty() && trial.plates && !trial.plates->plates.empty())
    throw InputError(a.trial + ": a force file (ground reaction columns, no markers), not a motion trial: give the markers' file as "
                     "the trial and this one to validate with --plates");
  std::string reason;
  const auto* set = recognise_marker_set(trial.markers, &reason);
  if (!set) {
    std::string names;
    for (const auto& s : builtin_marker_sets()) names += " " + s.name;
    return from_labels("no preset recognised", " (presets:" + names + ")");
  }
  if (why) *why = set->name + " (" + reason + ")";
  return *set;
}

std::vector<std::string> input_files(const Settings& a) {
  std::vector<std::string> in = {a.trial, a.static_trial, a.markers, a.cop_function};
  if (a.running_cop != "builtin" && a.running_cop != "off") in.push_back(a.running_cop);
  return in;
}

void apply_frame_range(Trial& t, const std::string& range) {
  if (range.empty()) return;
  const auto colon = range.find(':');
  const int first_file = t.markers.first_frame, last_file = t.markers.first_frame + static_cast<int>(t.markers.frames()) - 1;
  const auto malformed = [&] {
    return InputError(t.path + ": --frames " + range + ": give FIRST:LAST, the file's own frame numbers (" +
                      std::to_string(first_file) + ":" + std::to_string(last_file) + " in this file)");
  };
  auto number = [&](const std::string& text, int open) {
    if (text.empty()) return open;
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != text.size()) throw malformed();
    return v;
  };
  if (colon == std::string::npos) throw malformed();
  const int a = number(range.substr(0, colon), first_file), b = number(range.substr(colon + 1), last_file);
  if (a > b) throw InputError(t.path + ": --frames " + range + ": its first frame comes after its last");
  // A cut where no marker holds a sample is named as such, with the file's frames that hold
  // some, not left to fail later as a marker set no label matches (every label is empty there) or
  // a walker who does not travel. The file is scanned for those frames only then.
  const auto sampled = [&](Eigen::Index k) {
    return std::any_of(t.markers.positions_m.begin(), t.markers.positions_m.end(), [k](const Eigen::MatrixX3d& P) { return P.row(k).allFinite(); });
  };
  const Eigen::Index n = t.markers.frames(), lo = std::max<Eigen::Index>(0, a - first_file), hi = std::min<Eigen::Index>(n - 1, b - first_file);
  bool seen = false;
  for (Eigen::Index k = lo; k <= hi && !seen; ++k) seen = sampled(k);
  Eigen::Index seen_first = -1, seen_last = -1;
  if (!seen)
    for (Eigen::Index k = 0; k < n; ++k) {
      if (!sampled(k)) continue;
      if (seen_first < 0) seen_first = k;
      seen_last = k;
    }
  try {
    t.markers = cropped(std::move(t.markers), a - first_file, b - a + 1);  // it refuses frames the recording does not hold
  } catch (const InputError& e) {
    throw InputError(t.path + ": --frames " + range + ": " + e.what());
  }
  if (seen_first >= 0)
    throw InputError(t.path + ": --frames " + range + ": no marker holds a sample in frames " + std::to_string(a) + "-" + std::to_string(b) +
                     " (the markers hold samples in frames " + std::to_string(first_file + seen_first) + "-" +
                     std::to_string(first_file + seen_last) + ")");
}

TrialAndStatic load_trial_and_static(const Settings& s, const LoadOptions& load) {
  TrialAndStatic out;
  // Two files, two threads, when both are long enough to pay for a thread (about 5 ns a byte):
  // the static trial is read while the trial is; the first file's error is the one reported.
  std::error_code ec;
  const auto bytes = [&](const std::string& f) { return static_cast<double>(std::filesystem::file_size(f, ec)); };
  const bool both = !s.static_trial.empty() && std::min(bytes(s.trial), bytes(s.static_trial)) * 5e-9 >= kMinSecondsPerChunk;
  if (!both) {
    out.trial = load_trial(s.trial, load);
    if (!s.static_trial.empty()) out.static_trial = load_trial(s.static_trial);
  } else {
    for_chunks(2, 1, [&](std::size_t, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        if (i == 0) out.trial = load_trial(s.trial, load);
        else out.static_trial = load_trial(s.static_trial);
      }
    });
  }
  apply_frame_range(out.trial, s.frames);
  return out;
}

LoadOptions estimate_load_options() {
  LoadOptions load;
  load.c3d.plate_samples = false;
  return load;
}

namespace {

EstimateResult estimate_trial_impl(const Settings& s, const EstimateOptions& options, const Trial& trial, Trial* release,
                                   const std::optional<Trial>& st) {
  MarkerSet custom;
  std::string why;
  const MarkerSet& set = resolve_marker_set(s, trial, custom, &why, st ? &*st : nullptr);
  try {
    auto r = release ? estimate(std::move(*release), st ? &*st : nullptr, set, options)
                     : estimate(trial, st ? &*st : nullptr, set, options);
    if (!why.empty()) r.messages.insert(r.messages.begin(), "marker set recognised: " + why);
    return r;
  } catch (const InputError& e) {
    // The readers' warnings travel in the result; when there is none, they go with the error.
    std::string warnings;
    for (const auto& w : trial.warnings) warnings += "\n  input: " + w;
    if (st)
      for (const auto& w : st->warnings) warnings += "\n  static trial: " + w;
    if (warnings.empty()) throw;
    throw InputError(std::string(e.what()) + warnings);
  }
}

}  // namespace

EstimateResult estimate_trial(const Settings& s, EstimateOptions options, const Trial& trial, const std::optional<Trial>& st) {
  return estimate_trial_impl(s, options, trial, nullptr, st);
}

EstimateResult estimate_trial(const Settings& s, EstimateOptions options, Trial&& trial, const std::optional<Trial>& st) {
  return estimate_trial_impl(s, options, trial, &trial, st);
}

}  // namespace kin2grf
