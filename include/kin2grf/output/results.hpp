// kin2grf outputs: an estimate as OpenSim GRF .mot (lab frame), CSV (sagittal frame, units in
// the header) and a JSON summary.
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "kin2grf/dynamics/joint_moments_2d.hpp"
#include "kin2grf/dynamics/stance_parameters.hpp"
#include "kin2grf/pipeline.hpp"

namespace kin2grf {

/// OpenSim ExternalLoads-ready: ground_force_v/p, ground_torque_ (right), 1_-prefixed (left),
/// lab frame of the input, metres, force on the body.
/// `settings`: the run's settings as one line (compact JSON), written to the header with the
/// version (kin2grf_version=, kin2grf_settings=). Written row by row as it is made (AtomicFile).
void write_grf_mot(const std::string& path, const EstimateResult& r, const std::string& settings = "");
/// What write_grf_mot's header says of its frame (key kin2grf_frame).
inline constexpr const char* kLabFrameHeader =
    "lab: the input file's axes (its up axis up, not OpenSim's Y unless the input's is); the processed window";
/// The per-frame results as one table (sagittal frame; units in the column names): what the CSV
/// writes and the Python module returns. NaN where a value does not exist (COP without contact).
struct ResultsTable {
  std::vector<std::string> columns;
  Eigen::MatrixXd values;  ///< frames x columns
};
ResultsTable results_table(const EstimateResult& r);
/// results_table's columns, and its row `i` into `out` (out.size() == the columns' count).
/// The per-frame table's columns; `mediolateral` (EstimateOptions::lateral_force): and each
/// foot's lateral force, grf_lateral_r_N and grf_lateral_l_N; `moments_3d` (ModelKind::ThreeD):
/// and per side (r, l) the ankle's, the knee's and the hip's internal 3D moments, ankle_sagittal_r_Nm,
/// ankle_frontal_r_Nm, ankle_transverse_r_Nm, knee_..., hip_..., then knee_adduction_moment_r_Nm, the
/// external knee adduction moment (dynamics/joint_moments_3d.hpp's signs), last.
std::vector<std::string> results_columns(bool mediolateral = false, bool moments_3d = false);
void results_row(const EstimateResult& r, Eigen::Index i, std::span<double> out);
/// results_table as CSV: counts (frame, contact, iterations) as integers, the rest to 6
/// significant digits, NaN as an empty cell. Written row by row as made, never held whole; the
/// file through AtomicFile.
void write_results_csv(std::ostream& os, const EstimateResult& r);
void write_results_csv(const std::string& path, const EstimateResult& r);
std::string format_results_csv(const EstimateResult& r);
/// The JSON summary (docs/FORMATS.md); among its keys `stance_parameters`, per side and stance.
nlohmann::json results_summary(const EstimateResult& r, const nlohmann::json& settings);
/// One stance's parameters as JSON (the summary's and validate's; docs/FORMATS.md): each in its
/// unit, the forces and the loading rate in body weights too (`*_bw`, by `body_weight_N`); null
/// where a value does not exist.
nlohmann::json stance_parameters_json(const StanceParameters& p, double body_weight_N);
/// A stance's joint kinetic peaks (dynamics/joint_moments_2d.hpp) as JSON: each in its unit (N m,
/// W) and per kg of `mass_kg` (`*_per_kg`); null where a value does not exist.
nlohmann::json joint_kinetic_peaks_json(const JointKineticPeaks& p, double mass_kg);
/// A few lines for a person: frames, mass, progression, each foot's contact intervals and peak
/// vertical force (what `estimate` prints).
std::string format_results_text(const EstimateResult& r);

/// Each stance's parameters (the summary's `stance_parameters`) as CSV, one row per stance in time
/// order: side, frame_first, frame_last (the file's frame numbers), start_s, duration_s, complete
/// (0 where the processed window cuts the stance), then each force in N and in body weights
/// (`_bw`), the impulses (N s) and the loading rate (N/s, body weights/s); an empty cell where a
/// value does not exist. For spreadsheets and statistics packages (docs/FORMATS.md).
std::string stance_parameters_csv(const EstimateResult& r);
/// Each complete stance time-normalised (stance_normalised: 0 to 100 % of the stance, foot strike
/// to foot off as the gait events mark it, `points` instants), one row per stance and instant, in
/// the units gait reports and normative data use: side (0 right, 1 left), frame_first (the file's
/// frame number of the foot strike: the `--stances` CSV's row), start_s, duration_s, percent; the
/// foot's force in body weights (grf_vertical_bw, grf_anterior_bw, and with the lateral force
/// grf_lateral_bw), the COP's progression from where it was at foot strike (cop_progression_m,
/// along progression over the ground: on a treadmill over the belt, which carries the foot back),
/// the foot's inclination (rad), the side's hip, knee and ankle torques (N m
/// per kg of body mass, the per-frame CSV's torque_* signs) and powers (W/kg), and with
/// ModelKind::ThreeD the external knee adduction moment (N m/kg), then every joint's 3D moment in
/// every plane (joint_moment_curve_name, N m/kg, the per-frame CSV's order and signs). The values
/// are the per-frame CSV's (results_row) between frames. A stance the processed window cuts is
/// left out: part of a stance is not its 0-100 %.
ResultsTable stance_curves_table(const EstimateResult& r, int points = kStanceCurvePoints);
/// The stance-curves column of a 3D joint moment per kg (kJoint3DNames, kPlaneNames):
/// "hip_frontal_Nm_per_kg"; `validate --stance-curves` adds _estimate and _plate.
std::string joint_moment_curve_name(const std::string& joint, const std::string& plane);
/// stance_curves_table as CSV (side as right / left, numbers to 6 significant digits, an empty
/// cell where a value does not exist): `estimate --stance-curves` (docs/FORMATS.md). Written
/// stance by stance as made, never held whole; the file through AtomicFile.
void write_stance_curves_csv(std::ostream& os, const EstimateResult& r);
/// One row of a stance-curves CSV (this one's and `validate --stance-curves`'): the side as right /
/// left, then `label` (a CSV cell, e.g. the plate) where given, frame_first as an integer, start_s at
/// full precision, then `rest` to 6 significant digits (empty where a value does not exist).
void append_stance_curve_row(std::string& out, int side, const std::string* label, double frame_first, double start_s,
                             const Eigen::Ref<const Eigen::RowVectorXd>& rest);
void write_stance_curves_csv(const std::string& path, const EstimateResult& r);
std::string stance_curves_csv(const EstimateResult& r);
/// The gait events (gait_events: foot strike, foot off per side) as CSV: side,event,frame,time_s
/// (frame: the file's frame number).
std::string gait_events_csv(const EstimateResult& r);

}  // namespace kin2grf
