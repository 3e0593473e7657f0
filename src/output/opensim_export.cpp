#include "kin2grf/output/opensim_export.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {

namespace {
/// Lab -> OpenSim: rows forward, up, right.
Eigen::Matrix3d lab_to_opensim(const EstimateResult& r) {
  Eigen::Matrix3d R;
  R.row(0) = r.frame.forward.transpose();
  R.row(1) = r.frame.up.transpose();
  R.row(2) = r.frame.forward.cross(r.frame.up).transpose();
  return R;
}
}  // namespace

std::string external_loads_xml(const std::string& mot, const OpenSimExportOptions& o) {
  std::ostringstream os;
  os << "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n"
     << "<!-- Written by kin2grf " << KIN2GRF_VERSION << ": estimated ground reactions. The free moment is zero (not\n"
     << "     estimated); the mediolateral force and the COP's lateral place are estimated by the 3D model or\n"
     << "     the mediolateral option, else zero and the foot's midpoint: frontal- and transverse-plane joint moments are\n"
     << "     then not valid. -->\n"
     << "<OpenSimDocument Version=\"40000\">\n"
     << "  <ExternalLoads name=\"kin2grf_external_loads\">\n"
     << "    <objects>\n";
  for (const auto& [name, body, prefix] : {std::tuple{"right", o.right_body, ""}, std::tuple{"left", o.left_body, "1_"}}) {
    os << "      <ExternalForce name=\"" << name << "\">\n"
       << "        <applied_to_body>" << body << "</applied_to_body>\n"
       << "        <force_expressed_in_body>ground</force_expressed_in_body>\n"
       << "        <point_expressed_in_body>ground</point_expressed_in_body>\n"
       << "        <force_identifier>" << prefix << "ground_force_v</force_identifier>\n"
       << "        <point_identifier>" << prefix << "ground_force_p</point_identifier>\n"
       << "        <torque_identifier>" << prefix << "ground_torque_</torque_identifier>\n"
       << "      </ExternalForce>\n";
  }
  os << "    </objects>\n"
     << "    <groups />\n"
     << "    <datafile>" << mot << "</datafile>\n"
     << "  </ExternalLoads>\n"
     << "</OpenSimDocument>\n";
  return os.str();
}

OpenSimExportFiles opensim_export_paths(const std::string& dir, const std::string& stem) {
  namespace fs = std::filesystem;
  return {(fs::path(dir) / (stem + "_grf.mot")).string(), (fs::path(dir) / (stem + "_markers.trc")).string(),
          (fs::path(dir) / (stem + "_external_loads.xml")).string()};
}

Table opensim_grf_table(const Eigen::VectorXd& trial_time_s, const EstimateResult& r, const std::string& settings) {
  const Eigen::Index N = trial_time_s.size();
  // The GRF over the whole trial.
  auto feet = trial_foot_plates(r, N, lab_to_opensim(r));
  for (auto& f : feet) {
    // A finite COP everywhere: the nearest contact COP held (OpenSim applies a zero force there).
    Eigen::Index last = -1;
    for (Eigen::Index k = 0; k < N; ++k) {
      if (f.cop_m.row(k).allFinite()) last = k;
      else if (last >= 0) f.cop_m.row(k) = f.cop_m.row(last);
    }
    Eigen::Index next = -1;
    for (Eigen::Index k = N - 1; k >= 0; --k) {
      if (f.cop_m.row(k).allFinite()) next = k;
      else if (next >= 0) f.cop_m.row(k) = f.cop_m.row(next);
      else f.cop_m.row(k).setZero();  // a foot that never touches the ground
    }
  }
  Table t = grf_table(trial_time_s, feet[0], feet[1]);
  t.header["DataType"] = "double";
  t.header["kin2grf_version"] = KIN2GRF_VERSION;
  t.header["kin2grf_frame"] = kOpenSimFrameHeader;
  if (!settings.empty()) t.header["kin2grf_settings"] = settings;
  return t;
}

void write_opensim_grf_mot(const std::string& path, const std::string& stem, const Eigen::VectorXd& trial_time_s,
                           const EstimateResult& r, const std::string& settings) {
  Table t = opensim_grf_table(trial_time_s, r, settings);
  t.name = stem + "_grf";  // as the OpenSim set's TRIAL_grf.mot: the same file
  write_file_text(path, format_sto(t));
}

OpenSimExportFiles write_opensim_export(const std::string& dir, const std::string& stem, const Trial& trial,
                                        const EstimateResult& r, const OpenSimExportOptions& o) {
  ensure_output_folder(dir);
  const Eigen::Matrix3d R = lab_to_opensim(r);
  Table t = opensim_grf_table(trial.markers.time_s, r, o.settings);
  t.name = stem + "_grf";
  const OpenSimExportFiles out = opensim_export_paths(dir, stem);
  write_file_text(out.grf_mot, format_sto(t));

  write_file_text(out.markers_trc, format_trc(rotated(trial.markers, R, Axis::Y), stem + "_markers.trc"));

  write_file_text(out.external_loads_xml, external_loads_xml(stem + "_grf.mot", o));
  return out;
}

}  // namespace kin2grf
