// kin2grf outputs: an estimate ready for OpenSim's inverse dynamics (ID tool) with no hand edits.
//
// Three files in one folder, all in OpenSim's frame and one time base:
//  - STEM_grf.mot: per foot ground_force_v[xyz] (N, on the body), ground_force_p[xyz] (COP, m),
//    ground_torque_[xyz] (N m, free moment: zero), the left foot's with the prefix "1_"; one row per
//    marker frame of the WHOLE trial: zero force outside contact and outside the processed window,
//    and a finite COP everywhere (the foot's nearest contact COP held, zero for a foot that never
//    touches the ground);
//  - STEM_markers.trc: every marker of the trial (mm), for OpenSim's scaling and IK;
//  - STEM_external_loads.xml: an ExternalLoads document applying the two forces to calcn_r and
//    calcn_l (overridable), expressed in ground, naming the .mot as its datafile.
// OpenSim's frame: X along the walker's progression (the sagittal frame's forward), Y up, Z to the
// walker's right (X x Y), origin the lab's. Time: the trial's own time column ((frame - 1) / rate
// for a C3D, as in the TRC), the same in both data files.
//
// What is 2D: kin2grf's model is sagittal. The mediolateral force (Z) and the free moment are zero,
// and the COP's lateral place is the foot's (its heel-MT midpoint), not a measured one: joint
// moments about the sagittal axes (flexion-extension) are meaningful, frontal- and transverse-plane
// moments from inverse dynamics (ab/adduction, rotation) are not.
#pragma once

#include <string>

#include "kin2grf/io/opensim.hpp"
#include "kin2grf/trial.hpp"
#include "kin2grf/pipeline.hpp"

namespace kin2grf {

struct OpenSimExportOptions {
  std::string right_body = "calcn_r";
  std::string left_body = "calcn_l";
  std::string settings;  ///< the run's settings (compact JSON), recorded in the .mot header
};

struct OpenSimExportFiles {
  std::string grf_mot, markers_trc, external_loads_xml;  ///< paths written
};

/// The three files' paths in `dir` for `stem` (what write_opensim_export writes; checked against
/// the inputs before a run).
OpenSimExportFiles opensim_export_paths(const std::string& dir, const std::string& stem);

/// Write the three files into `dir` (created if needed), names starting with `stem`.
OpenSimExportFiles write_opensim_export(const std::string& dir, const std::string& stem, const Trial& trial,
                                        const EstimateResult& estimate, const OpenSimExportOptions& options = {});

/// What the header of an OpenSim-convention GRF .mot says of its frame (key kin2grf_frame).
inline constexpr const char* kOpenSimFrameHeader =
    "OpenSim ground: X forward (the walker's progression), Y up, Z to the right; every frame of the trial";

/// STEM_grf.mot's table: the GRF in OpenSim's frame over the trial's `trial_time_s` (every marker
/// frame; zero force outside contact and the processed window), with its header.
Table opensim_grf_table(const Eigen::VectorXd& trial_time_s, const EstimateResult& estimate, const std::string& settings = "");
/// That table as a .mot file at `path`, named STEM_grf as the OpenSim set's (estimate -o, Python):
/// the same bytes as write_opensim_export's STEM_grf.mot.
void write_opensim_grf_mot(const std::string& path, const std::string& stem, const Eigen::VectorXd& trial_time_s,
                           const EstimateResult& estimate, const std::string& settings = "");

/// The ExternalLoads XML text for a .mot file name (exposed for tests).
std::string external_loads_xml(const std::string& mot_file_name, const OpenSimExportOptions& options);

}  // namespace kin2grf
