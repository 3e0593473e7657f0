#include "kin2grf/output/results.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "kin2grf/io/opensim.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {

void write_grf_mot(const std::string& path, const EstimateResult& r, const std::string& settings) {
  const auto plates = as_lab_plates(r);
  Table t = grf_table(r.time_s, plates[0], plates[1]);
  t.name = "kin2grf_estimated_grf";
  t.header["DataType"] = "double";
  t.header["kin2grf_version"] = KIN2GRF_VERSION;
  if (!settings.empty()) t.header["kin2grf_settings"] = settings;
  write_sto(path, t);
}

ResultsTable results_table(const EstimateResult& r) {
  ResultsTable t;
  auto& c = t.columns;
  c = {"frame", "time_s"};
  for (const char* s : {"r", "l"})
    for (const char* name : {"grf_anterior_%s_N", "grf_vertical_%s_N", "cop_x_%s_m", "contact_%s", "gap_%s_m",
                             "foot_inclination_%s_rad", "grf_vertical_unfiltered_%s_N"}) {
      char buf[64];
      std::snprintf(buf, sizeof buf, name, s);
      c.emplace_back(buf);
    }
  c.emplace_back("grm_Nm");
  for (int j = 0; j < kJointCount; ++j) c.push_back(std::string("torque_") + joint_name(j) + "_Nm");
  for (int j = 0; j < kJointCount; ++j) {
    c.push_back(std::string("force_") + joint_name(j) + "_x_N");
    c.push_back(std::string("force_") + joint_name(j) + "_y_N");
  }
  for (const char* name : {"residual_x_N", "residual_y_N", "residual_moment_Nm", "iterations"}) c.emplace_back(name);
  const Eigen::Index n = r.time_s.size();
  auto& v = t.values;
  v.resize(n, static_cast<Eigen::Index>(c.size()));
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Index k = 0;
    v(i, k++) = static_cast<double>(r.first_frame_number + i);
    v(i, k++) = r.time_s[i];
    for (int s = 0; s < 2; ++s) {
      const auto& f = r.feet[s];
      v(i, k++) = f.force_N(i, 0), v(i, k++) = f.force_N(i, 1), v(i, k++) = f.cop_x_m[i];
      v(i, k++) = f.contact[static_cast<std::size_t>(i)] ? 1.0 : 0.0;
      v(i, k++) = f.gap_m[i], v(i, k++) = f.inclination_rad[i], v(i, k++) = f.raw_force_N(i, 1);
    }
    v(i, k++) = r.grm_Nm[i];
    for (int j = 0; j < kJointCount; ++j) v(i, k++) = r.joint_torque_Nm(i, j);
    for (int j = 0; j < 2 * kJointCount; ++j) v(i, k++) = r.joint_force_N(i, j);
    for (int j = 0; j < 3; ++j) v(i, k++) = r.residual(i, j);
    v(i, k++) = r.iterations[static_cast<std::size_t>(i)];
  }
  return t;
}

std::string format_results_csv(const EstimateResult& r) {
  const ResultsTable t = results_table(r);
  std::ostringstream os;
  for (std::size_t k = 0; k < t.columns.size(); ++k) os << (k ? "," : "") << t.columns[k];
  os << "\n";
  // Counts (frame, contact, iterations) as integers; the rest to 6 significant digits; NaN empty.
  std::vector<bool> integer(t.columns.size());
  for (std::size_t k = 0; k < t.columns.size(); ++k)
    integer[k] = t.columns[k] == "frame" || t.columns[k].rfind("contact_", 0) == 0 || t.columns[k] == "iterations";
  char buf[64];
  for (Eigen::Index i = 0; i < t.values.rows(); ++i) {
    for (Eigen::Index k = 0; k < t.values.cols(); ++k) {
      const double x = t.values(i, k);
      if (k) os << ',';
      if (integer[static_cast<std::size_t>(k)]) os << static_cast<long long>(x);
      else if (std::isfinite(x)) {
        const auto end = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, 6).ptr;  // = %.6g
        os.write(buf, end - buf);
      }
    }
    os << "\n";
  }
  return os.str();
}

namespace {

/// The runs of frames in contact.
std::vector<IndexRun> contact_runs(const std::vector<bool>& c) {
  return runs_where(static_cast<Eigen::Index>(c.size()), [&](Eigen::Index i) { return c[static_cast<std::size_t>(i)]; });
}

}  // namespace

nlohmann::json results_summary(const EstimateResult& r, const nlohmann::json& settings) {
  using nlohmann::json;
  json j;
  j["kin2grf_version"] = KIN2GRF_VERSION;
  j["settings"] = settings;
  j["marker_set"] = r.marker_set;
  j["mass_kg"] = r.mass_kg;
  j["ground_level_m"] = r.ground_level_m();
  j["progression"] = {{"forward", {r.frame.forward.x(), r.frame.forward.y(), r.frame.forward.z()}},
                      {"up", {r.frame.up.x(), r.frame.up.y(), r.frame.up.z()}},
                      {"treadmill", r.frame.treadmill},
                      {"turning", r.frame.turning()},
                      {"belt_velocity_mps", r.calibration.belt_velocity_mps},
                      {"speed_mps", r.calibration.progression_speed_mps},
                      {"how", r.frame.how}};
  j["contact_speed_gate_mps"] = r.calibration.speed_gate_mps;
  j["kinematic_cutoff_hz"] = r.kinematic_cutoff_hz;  // the one used (lowered for noisy markers)
  j["post_cutoff_hz"] = r.post_cutoff_hz;            // the one used (per stance, or fixed)
  const auto n = r.time_s.size();
  j["frames"] = {{"first", r.first_frame_number}, {"last", r.first_frame_number + n - 1}, {"count", n}};
  json contacts = json::object();
  for (int s = 0; s < 2; ++s) {
    json iv = json::array();
    for (const auto& run : contact_runs(r.feet[s].contact)) iv.push_back({{"start_s", r.time_s[run.first]}, {"end_s", r.time_s[run.last]}});
    contacts[s ? "left" : "right"] = iv;
  }
  j["contact_intervals"] = contacts;
  double mean_it = 0;
  int max_it = 0;
  for (int it : r.iterations) { mean_it += it; max_it = std::max(max_it, it); }
  j["iterations"] = {{"mean", n ? mean_it / static_cast<double>(n) : 0.0}, {"max", max_it},
                     {"cycled_frames", r.cycled_frames}, {"capped_frames", r.capped_frames}};
  j["residual_rms"] = {{"x_N", std::sqrt(r.residual.col(0).squaredNorm() / std::max<double>(1, static_cast<double>(n)))},
                       {"y_N", std::sqrt(r.residual.col(1).squaredNorm() / std::max<double>(1, static_cast<double>(n)))},
                       {"moment_Nm", std::sqrt(r.residual.col(2).squaredNorm() / std::max<double>(1, static_cast<double>(n)))}};
  j["timing"] = {{"kinematics_s", r.seconds_kinematics}, {"dynamics_s", r.seconds_dynamics},
                 {"frames_per_s", static_cast<double>(n) / std::max(1e-9, r.seconds_kinematics + r.seconds_dynamics)}};
  j["messages"] = r.messages;
  json seg = json::array();
  for (int s = 0; s < kSegmentCount; ++s)
    seg.push_back({{"segment", segment_name(s)}, {"length_m", r.model.bodies[s].length_m}, {"mass_kg", r.model.bodies[s].mass_kg}});
  j["segments"] = seg;
  return j;
}

std::string format_results_text(const EstimateResult& r) {
  std::ostringstream os;
  char b[256];
  const auto n = r.time_s.size();
  if (n == 0) return "no frames\n";
  std::snprintf(b, sizeof b, "frames %d-%d (%.3f-%.3f s), body mass %.1f kg, marker set %s\n", r.first_frame_number,
                r.first_frame_number + static_cast<int>(n) - 1, r.time_s[0], r.time_s[n - 1], r.mass_kg, r.marker_set.c_str());
  os << b;
  std::snprintf(b, sizeof b, "progression: %s, speed %.2f m/s, contact speed gate %.2f m/s\n", r.frame.how.c_str(),
                r.calibration.progression_speed_mps, r.calibration.speed_gate_mps);
  os << b;
  const double bw = r.mass_kg * r.model.gravity_mps2;
  for (int s = 0; s < 2; ++s) {
    const auto& f = r.feet[static_cast<std::size_t>(s)];
    std::snprintf(b, sizeof b, "%-5s foot: %zu contact interval(s), peak vertical %.0f N (%.2f body weights)\n", s ? "left" : "right",
                  contact_runs(f.contact).size(), f.force_N.col(1).maxCoeff(), f.force_N.col(1).maxCoeff() / bw);
    os << b;
  }
  return os.str();
}

}  // namespace kin2grf
