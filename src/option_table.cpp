#include "kin2grf/option_table.hpp"

#include <cstring>

namespace kin2grf {

const std::vector<NumericOption>& numeric_options() {
  using O = EstimateOptions;
  static const std::vector<NumericOption> table = {
      {"min-kinematic-cycles", "min_kinematic_cycles", [](O& o) -> double& { return o.min_kinematic_cycles; }, 0.0, 20.0, std::nullopt,
       "Where the noise rule lowers the kinematic cut-off, the dynamics' cut-off stays at least this many cycles over the median "
       "stance (the COP function's foot angle keeps the lowered one); 0 = no floor",
       // measured where it acts: as recorded no development trial's cut-off is lowered
       {0.0, 2.5, 3.0, 3.5, 4.0, 5.0}, "%.1f cycles, 2 mm", 1.0, "off, 2 mm", 0.002},
      {"kinematic-edge-span", "kinematic_edge_span_periods", [](O& o) -> double& { return o.kinematic_edge_span_periods; }, 0.05, 5.0,
       std::nullopt,
       "With --kinematic-edges curvature, the share of a kinematic cut-off period each window end's curvature is fitted over "
       "(default 0.5: the filter's own resolution)",
       {0.25, 0.5, 0.75, 1.0}, "%.2f periods"},
      {"post-cutoff-floor", "post_cutoff_floor_ratio", [](O& o) -> double& { return o.post_cutoff_floor_ratio; }, 0.0, 10.0, std::nullopt,
       "The per-stance post-filter cut-off is not taken below this multiple of the dynamics' kinematic cut-off (default 0.75: a "
       "slow walker's stance; 0 = no floor)",
       {0.0, 0.5, 0.75, 1.0, 1.5, 2.0}, "%.2f x kinematic", 1.0, "none"},
      {"ground-shift", "ground_shift_m", [](O& o) -> double& { return o.contact.ground_shift_m; }, 1.0, -1.0, std::nullopt,
       "Shift the ground by this much, m (robustness study)",
       {-0.01, 0.0, 0.01}, "%+.0f mm", 1000.0},
      {"speed-gate-ratio", "speed_gate_ratio", [](O& o) -> double& { return o.contact.speed_gate.ratio; }, 0.0, 20.0, 0.0,
       "The speed gate as this multiple of the progression speed (hip or belt), at least --speed-gate-standstill (near a flight "
       "phase --speed-gate-floor); 0 = the fixed --speed-gate"},  // its study varies the ratio alone (validation/study)
      {"speed-gate-floor", "speed_gate_floor_mps", [](O& o) -> double& { return o.contact.speed_gate.floor_mps; }, 0.0, 20.0, std::nullopt,
       "Lowest speed gate with --speed-gate-ratio near a flight phase (a jump's or a run's landing), m/s",
       {0.2, 0.3, 0.5, 0.75, 1.0}, "%.2f m/s"},
      {"speed-gate-standstill", "speed_gate_standstill_mps", [](O& o) -> double& { return o.contact.speed_gate.standstill_mps; }, 0.0,
       20.0, std::nullopt, "Lowest speed gate with --speed-gate-ratio away from flight phases (a slow walk, standing), m/s",
       {0.05, 0.1, 0.2, 0.3, 0.5, 0.75}, "%.2f m/s"},
      {"touchdown-fraction", "touchdown_fraction", [](O& o) -> double& { return o.contact.touchdown_fraction; }, 0.0, 1.0, 0.0,
       "A landing foot takes no load before its descent speed, past the final approach's peak, has fallen to this fraction of the "
       "peak (1: from the peak on; 0 = off, the default and the paper)",
       {0.0, 0.5, 0.7, 0.8, 0.9, 1.0}, "%.1f of the peak", 1.0, "off"},
      {"touchdown-stop", "touchdown_stop_fraction", [](O& o) -> double& { return o.touchdown_stop_fraction; }, 0.0, 1.0, 0.0,
       "A landing foot carries no load before its heel or MT head, seen at 15 Hz, has stopped descending: its descent fallen to "
       "this fraction of its recent peak and under 0.1 m/s (0 = off, the paper); the load the kinematics ask for before is dropped",
       {0.0, 0.1, 0.2, 0.3, 0.5}, "%.1f of the peak", 1.0, "off"},
      // No study grid: the sagittal criterion does not see it; scripts/validate-all.sh's 3d-toe runs
      // choose it leave-one-lab-out by the lateral COP (docs/VALIDATION.md).
      {"toe-medial-slope", "toe_medial_slope", [](O& o) -> double& { return o.toe_medial_slope; }, -2.0, 2.0, std::nullopt,
       "With the lateral COP (--model 3d, --mediolateral): past the forefoot's midline end (the MT heads) the COP turns medially, "
       "towards the hallux the push-off rolls onto, by this many m per m ahead of it (default 0.25; 0 = it stays on the midline)"},
      {"still-foot", "still_foot_rad_per_s", [](O& o) -> double& { return o.contact.still_foot_rad_per_s; }, 0.0, 10.0, 0.0,
       "The contact calibration's foot-flat reference from frames where the foot is also still, its angle turning slower than "
       "this, rad/s (0 = every frame with the heel and MT near the floor, the paper)",
       {0.0, 0.25, 0.5, 1.0, 2.0}, "%.2f rad/s", 1.0, "off"},
      {"split-distance", "min_split_distance_m", [](O& o) -> double& { return o.solver.min_split_distance_m; }, 0.0, 1.0, 0.0,
       "Feet closer than this along progression share the load by the minimum norm, m (0 = off, the paper)",
       {0.0, 0.05, 0.1, 0.15, 0.2}, "%.2f m", 1.0, "off"},
      // The lever in leg lengths: 1.06 is the fixed 0.9 m of sessions before 39 for the development
      // subjects' mean leg (0.85 m), not chosen from the grid (VALIDATION.md); 0 keeps the fixed 0.9 m.
      {"torque-length", "torque_length_legs", [](O& o) -> double& { return o.torque_length_legs; }, 0.0, 10.0, std::nullopt,
       "The multiplier norm's joint torques are divided by this multiple of the subject's leg length (thigh + shank), so that "
       "they weigh against the contact forces as for a subject of any size; 0 = a fixed 0.9 m",
       {0.0, 0.5, 0.75, 1.0, 1.06, 1.25, 1.5, 2.0}, "%.2f x leg", 1.0, "fixed 0.9 m"},
      {"torso-lag", "torso_lag_s", [](O& o) -> double& { return o.torso_lag_s; }, 0.0, 0.2, 0.0,
       "The upper body's fore-aft lag behind the pelvis, s: the HAT's fore-aft inertial force is delayed by this time, less what "
       "the trunk markers already lag the hip by (0 = none, the paper)",
       {0.0, 0.01, 0.02, 0.025, 0.03, 0.035, 0.04, 0.05}, "%.0f ms", 1000.0, "off"},
      {"thigh-lag", "thigh_lag_s", [](O& o) -> double& { return o.thigh_lag_s; }, 0.0, 0.2, 0.0,
       "Each thigh's fore-aft lag behind its femur, s: the thigh's fore-aft inertial force is delayed by this time where its knee "
       "point is a marker on the bone (not where a thigh cluster carries it; 0 = none, the paper)",
       {0.0, 0.01, 0.015, 0.02, 0.025, 0.03, 0.04}, "%.0f ms", 1000.0, "off"},
      // A fixed reference, off by default: on the development adults it is mixed (docs/METHOD-NOTES.md,
      // session 39); the development range's ends below act outside it alone (session 50).
      {"time-scale-leg", "time_scale_leg_m", [](O& o) -> double& { return o.time_scale_leg_m; }, 0.0, 3.0, std::nullopt,
       "The leg length (thigh + shank, m) the settings in seconds and hertz (the kinematic, torso-vertical, lateral and fixed "
       "post-filter cut-offs, the torso and thigh lags) are for: a subject's are scaled by sqrt(its leg / this), its gait's time "
       "scale at the same Froude number (0.85: the development adults' mean leg; default 0 = the development range's nearer end "
       "for a leg outside --time-scale-short-leg .. --time-scale-long-leg, as given within it)"},
      // The development subjects' legs (0.763-0.896 m): their figures are the same with these.
      {"time-scale-short-leg", "time_scale_short_leg_m", [](O& o) -> double& { return o.time_scale_short_leg_m; }, 0.0, 3.0, 0.0,
       "A subject whose leg (thigh + shank) is shorter than this, m, has the settings in seconds and hertz scaled by sqrt(its leg / "
       "this): the shortest leg they were chosen for (default 0.76, the development subjects'; 0 = never)"},
      {"time-scale-long-leg", "time_scale_long_leg_m", [](O& o) -> double& { return o.time_scale_long_leg_m; }, 0.0, 3.0, 0.0,
       "A subject whose leg (thigh + shank) is longer than this, m, has the settings in seconds and hertz scaled by sqrt(its leg / "
       "this): the longest leg they were chosen for (default 0.90, the development subjects'; 0 = never)"},
      {"torso-vertical-cutoff", "torso_vertical_cutoff_hz", [](O& o) -> double& { return o.torso_vertical_cutoff_hz; }, 0.0, 100.0, 0.0,
       "The HAT's vertical inertial force is low-passed at this cut-off, Hz (the upper body does not pass on the pelvis markers' "
       "heel-strike jolt), in a trial without flight phases, below the kinematic cut-off (0 = none, the paper)",
       {0.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0}, "%.1f Hz", 1.0, "off"},
      // Measured on the run with trunk markers (kTrunkSwayGainRunning), not fitted: only a run
      // without trunk markers (the RBDS runs' lab) feels it, so held out that lab's choice ties.
      {"running-sway-gain", "running_sway_gain", [](O& o) -> double& { return o.running_sway_gain; }, 0.0, 1.5, std::nullopt,
       "A model torso's fore-aft sway (a set without trunk markers) in a trial with flight phases (a run, a jump), as a share of "
       "the hip centre's fore-aft oscillation: a runner's, measured; the set's own walking share (0.5 in the presets) turns it off",
       {0.0, 0.05, 0.1, 0.2, 0.3, 0.5}, "%.2f x the hip's"},
      // Up to 0.6: the criterion turns up past 0.4. Until session 29 the grid stopped at 0.2, where a
      // 1 cm error of the ground level moves a walk by 0.2 points (0.3 at 0.4; docs/ROBUSTNESS.md):
      // the double supports' ends move with the ground, and the prior's timing with them.
      {"double-support-sta", "double_support_sta_weight", [](O& o) -> double& { return o.double_support_sta_weight; }, 0.0, 1.0, 0.0,
       "Weight (0-1) of the smooth transition towards which each walking double support's split between the feet is blended "
       "(0 = none, the paper)",
       {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6}, "%.1f", 1.0, "off"},
      {"double-support-angle", "double_support_angle", [](O& o) -> double& { return o.double_support_angle; }, 0.0, 1.0, 0.0,
       "With --double-support-sta: how far each foot's fore-aft force follows its vertical force's new share in a double support "
       "(1: each foot keeps the solve's force angle; 0 = the fore-aft forces as solved, the paper)",
       {0.0, 0.25, 0.5, 0.75, 1.0}, "%.2f", 1.0, "off"},
      // No value fitted (1: the frontal balance wherever the solver's sagittal split fades out). It
      // acts only on feet side by side (a landing, standing), which no development walk or run has
      // on its plates: measured with `validate` on the drop jump (docs/METHOD-NOTES.md), no grid.
      {"frontal-split", "frontal_split_weight", [](O& o) -> double& { return o.frontal_split_weight; }, 0.0, 1.0, 0.0,
       "Feet side by side (within --split-distance along progression) share the vertical load by the whole body's frontal "
       "balance (its centre of mass across the feet), with this weight; 0 = off: the sagittal minimum norm's shares, the paper"},
      // Chosen leave-one-lab-out on the mediolateral force (scripts/validate-all.sh's 3d-lc runs,
      // VALIDATION.md's table), not by `kin2grf study`, whose criterion is the sagittal one: no grid here.
      {"lateral-cutoff", "lateral_cutoff_hz", [](O& o) -> double& { return o.lateral_cutoff_hz; }, 0.0, 100.0, std::nullopt,
       "Low-pass cut-off of the whole body's lateral acceleration (the mediolateral force, --model 3d), Hz; never above the "
       "kinematic cut-off; 0 = the kinematic cut-off"},
  };
  return table;
}

const NumericOption* find_numeric_option(const char* flag) {
  for (const NumericOption& s : numeric_options())
    if (std::strcmp(s.flag, flag) == 0) return &s;
  return nullptr;
}

}  // namespace kin2grf
