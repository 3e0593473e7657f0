// kin2grf synthetic trials of the project's own making (no recorded data): the bundled example
// and the self-contained tests. A sagittal stick figure with the kin2grf-example marker set
// (joint centres and foot landmarks as markers), written in a C3D lab frame (X forward, Y left,
// Z up, floor at 0).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "kin2grf/trial.hpp"

namespace kin2grf {

struct SyntheticOptions {
  double duration_s = 3.0;
  double rate_hz = 100.0;
  double mass_kg = 70.0;
  double squat_depth = 1.0;     ///< 0 = quiet standing
  double squat_period_s = 1.5;
  double flight_height_m = 0.0; ///< > 0: a ballistic flight of this apex height mid-trial
  /// > 0: the left leg swung forward by this hip angle as one rigid piece (single support on
  /// the right foot; the left foot clears the floor by L (1 - cos a)).
  double left_leg_raised_rad = 0.0;
};

/// A trial with the kin2grf-example markers (R/L SHO, HJC, KJC, AJC, HEE, MT1, HLX), Z up, their
/// positions to be filled (uninitialised).
Trial example_trial_frame(const std::string& path, double duration_s, double rate_hz, double mass_kg);

/// Markers only (plates are added by the caller from the model's own estimate).
Trial make_synthetic_trial(const SyntheticOptions& options);

struct EstimateResult;
struct ForcePlate;

/// Two force plates (FP1 under the right foot, FP2 under the left; C3D TYPE-2 geometry, lab
/// frame) whose signals are an estimate's own per-foot forces at the marker rate: the bundled
/// example's plates, and exact "measurements" for the validation tests. Frames within
/// `unloaded_ends` of either end are zeroed so that stances start and end inside the trial.
ForcePlateRecording example_plates(const EstimateResult& estimate, const Trial& trial, int unloaded_ends = 0);

/// A level walk (src/synth/walk.cpp says how it is made).
struct SyntheticWalkOptions {
  double duration_s = 4.4;
  double rate_hz = 100.0;
  double mass_kg = 70.0;
  double speed_mps = 1.2;
  double stride_time_s = 1.1;
  double hip_height_m = 0.86;       ///< mean hip-joint height
  double hip_oscillation_m = 0.02;  ///< amplitude of its rise at each mid-stance
  double speed_oscillation_mps = 0.15;  ///< amplitude of the hips' forward speed, slowest at mid-stance
  double clearance_m = 0.08;        ///< heel lift at mid-swing
  double heel_strike_angle_rad = 0.25;  ///< foot inclination at heel strike (toes up)
  double toe_off_angle_rad = 0.7;       ///< at toe-off (heel up)
  /// The heel's descent at heel strike, m/s: 0 lands the swing foot at rest (the example's); a real
  /// heel lands at 0.1-0.35 m/s and stops at the impact, which the kinematics' zero-lag filter
  /// spreads over the frames before it (the touchdown rule's case, issue 29).
  double heel_strike_descent_mps = 0.0;
  /// 3D gait (issue 28's synthetic walk; the defaults keep every marker in its side's vertical
  /// plane, the walk of the 2D tests):
  double step_width_m = 0.2;    ///< lateral distance between the feet's lines
  double lateral_sway_m = 0.0;  ///< amplitude of the hips' and shoulders' sway toward the stance foot
  double toe_out_rad = 0.0;     ///< each foot's long axis turned outward about the vertical
};

struct SyntheticWalk {
  Trial trial;  ///< markers (kin2grf-example set), body mass; no plates
  /// Per foot (0 right, 1 left), per frame: in stance by construction, the stance's phase (0
  /// heel strike, 1 toe-off) and the nominal COP along x (m; NaN in swing).
  std::array<std::vector<bool>, 2> stance;
  std::array<Eigen::VectorXd, 2> stance_phase, nominal_cop_x_m;
  std::array<Eigen::MatrixX2d, 2> sole_x_m;  ///< x of the heel's ground point and the hallux in stance
  /// In stance, the foot's long axis on the floor: the point (x, y) it turns about for toe-out
  /// (the heel's ground point at heel strike) and its direction (cos a, -+sin a) rotated outward
  /// by SyntheticWalkOptions::toe_out_rad: a COP at lab x lies at y = y0 + (x - x0) tan(+-a).
  std::array<Eigen::MatrixX2d, 2> sole_axis_origin_m;
  std::array<Eigen::Vector2d, 2> sole_axis_direction{Eigen::Vector2d::UnitX(), Eigen::Vector2d::UnitX()};
};

SyntheticWalk make_synthetic_walk(const SyntheticWalkOptions& options);

/// The walk's ground reactions per foot, lab frame, one row per trial frame (zero in swing): the
/// estimate's kinematic totals shared between the feet by the synthetic rule (walk.cpp), not by
/// the method. `estimate` is estimate() on `walk.trial`; with a lateral force (ModelKind::ThreeD)
/// its total (the sum of the feet's) is shared by the same rule, and each COP lies on its foot's
/// long axis (SyntheticWalk::sole_axis_origin_m), so the plates carry the model's own 3D totals.
std::array<ForcePlate, 2> synthetic_walk_feet(const SyntheticWalk& walk, const EstimateResult& estimate);

/// The bundled example: the walk with two force plates in series along the walkway, the right
/// foot's middle stance on FP1 and the left foot's next on FP2 (each plate records the foot whose
/// COP is over it). With sway or toe-out the plates carry the 3D model's totals
/// (synthetic_walk_feet), a lateral force included.
Trial make_example_walk(const SyntheticWalkOptions& options = {});

/// The bundled examples in `dir` (`kin2grf make-example`): example_walk.c3d/.trc/_grf.mot (the
/// walk, at least 2.5 strides long) and example_squat.c3d/.trc/_grf.mot (a squat on two plates
/// whose signals are the method's own estimate), `seconds` long (1-600). Returns what was written,
/// a line per example. `rate_hz`: the markers' rate (50-2000 Hz); `analog_rate_hz`: the walk's
/// plates' rate, an integer multiple of it (0: the marker rate), their signals interpolated
/// linearly between frames: a capture's size and shape for the memory benchmark (2 kHz
/// markers, 10 kHz analog). The squat's plates are at the marker rate. `marker_noise_m`: Gaussian
/// noise (SD, m; 0-0.01, seeded, the same every time) on the walk's marker coordinates, as real
/// capture has: the trial the noise rule and its stance floor act on (min_kinematic_cycles).
std::vector<std::string> write_examples(const std::string& dir, double seconds, double rate_hz = 100.0,
                                        double analog_rate_hz = 0.0, double marker_noise_m = 0.0);

}  // namespace kin2grf
