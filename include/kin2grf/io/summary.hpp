// kin2grf: what `kin2grf info` reports about a trial, as JSON and as text.
//
// JSON schema (stable; documented in docs/FORMATS.md):
//   format: "C3D"|"TRC"|"MOT"|"STO", encoding: string, path: string,
//   rate_hz: number|null (marker rate), frames: {first, last, count}, duration_s,
//   up_axis: "X"|"Y"|"Z", markers: [names], missing: [{marker, frames: count,
//   intervals: [[first_frame, last_frame], ...]}], model_outputs: count,
//   marker_set: {preset: name} | {preset: null, labels: [rules], notes: [..], missing: [..]} | null,
//   force_plates: [{name, type, rate_hz, size_m: [w, l]|null, centre_m: [x,y,z]|null,
//                   side_hint, loaded: [{start_s, end_s, peak_vertical_N}]}],
//   events: [{label, side, time_s}], body_mass_kg: number|null, height_m: number|null,
//   warnings: [strings]
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "kin2grf/io/load.hpp"
#include "kin2grf/trial.hpp"

namespace kin2grf {

struct LoadedInterval {
  double start_s = 0, end_s = 0, peak_vertical_N = 0;
  Eigen::Index first_sample = 0, last_sample = 0;
};

/// Intervals where the plate's vertical force exceeds `threshold_N`; dips under 10 ms are
/// bridged and intervals under 10 ms dropped (noise around the threshold, not contacts).
std::vector<LoadedInterval> loaded_intervals(const ForcePlateRecording& rec, const ForcePlate& plate,
                                             double threshold_N = 20.0);

nlohmann::json trial_summary(const Trial& t, double load_threshold_N = 20.0);
/// `kin2grf info`: the file read with `load`, the up axis set to `up_axis` when given (the user's
/// word over the data's), then trial_summary. InputError for a threshold that is not above 0 N.
/// `loaded`, when given, receives the trial read (info --write-mapping maps its labels).
nlohmann::json describe_file(const std::string& path, double load_threshold_N, const LoadOptions& load,
                             std::optional<Axis> up_axis = std::nullopt, Trial* loaded = nullptr);
std::string format_summary(const nlohmann::json& s);

}  // namespace kin2grf
