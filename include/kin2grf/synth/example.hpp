// kin2grf synthetic trials of the project's own making (no recorded data): the bundled example
// and the self-contained tests. A sagittal stick figure with the kin2grf-example marker set
// (joint centres and foot landmarks as markers), written in a C3D lab frame (X forward, Y left,
// Z up, floor at 0).
#pragma once

#include "kin2grf/io/trial.hpp"

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

/// Markers only (plates are added by the caller from the model's own estimate).
Trial make_synthetic_trial(const SyntheticOptions& options);

struct EstimateResult;

/// Two force plates (FP1 under the right foot, FP2 under the left; C3D TYPE-2 geometry, lab
/// frame) whose signals are an estimate's own per-foot forces at the marker rate: the bundled
/// example's plates, and exact "measurements" for the validation tests. Frames within
/// `unloaded_ends` of either end are zeroed so that stances start and end inside the trial.
ForcePlateRecording example_plates(const EstimateResult& estimate, const Trial& trial, int unloaded_ends = 0);

}  // namespace kin2grf
