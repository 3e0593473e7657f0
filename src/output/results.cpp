#include "kin2grf/output/results.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>

#include "kin2grf/dynamics/joint_moments_2d.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {

namespace {

/// Rows are gathered into a buffer and written out every so often: the file is written as it is
/// made, never held whole.
constexpr std::size_t kFlushBytes = std::size_t{1} << 16;

void flush_if_full(std::string& buf, std::ostream& os, bool force = false) {
  if (force || buf.size() >= kFlushBytes) {
    os.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    buf.clear();
  }
}

}  // namespace

void write_grf_mot(const std::string& path, const EstimateResult& r, const std::string& settings) {
  Table t;
  t.name = "kin2grf_estimated_grf";
  t.labels = grf_labels();
  t.header["DataType"] = "double";
  t.header["kin2grf_version"] = KIN2GRF_VERSION;
  t.header["kin2grf_frame"] = kLabFrameHeader;
  if (!settings.empty()) t.header["kin2grf_settings"] = settings;
  const Eigen::Index n = r.time_s.size();
  AtomicFile file(path);
  std::string buf = sto_header(t, n);
  std::array<double, 19> row{};  // time, per foot force and COP (NaN -> 0), per foot free moment (0)
  for (Eigen::Index i = 0; i < n; ++i) {
    std::size_t c = 0;
    row[c++] = r.time_s[i];
    for (int side = 0; side < 2; ++side) {
      const LabFootFrame f = lab_foot_frame(r, side, i);
      for (int a = 0; a < 3; ++a) row[c++] = f.force_N[a];
      for (int a = 0; a < 3; ++a) row[c++] = std::isfinite(f.cop_m[a]) ? f.cop_m[a] : 0.0;
    }
    append_sto_row(buf, row);
    flush_if_full(buf, file.stream());
  }
  flush_if_full(buf, file.stream(), true);
  file.commit();
}

std::vector<std::string> results_columns(bool mediolateral, bool moments_3d) {
  std::vector<std::string> c = {"frame", "time_s"};
  for (const char* s : {"r", "l"})
    for (const char* name : {"grf_anterior_%s_N", "grf_vertical_%s_N", "cop_x_%s_m", "contact_%s", "gap_%s_m",
                             "foot_inclination_%s_rad", "grf_vertical_unfiltered_%s_N"}) {
      char buf[64];
      std::snprintf(buf, sizeof buf, name, s);
      c.emplace_back(buf);
    }
  c.emplace_back("grm_Nm");
  for (int j = 0; j < kJointCount; ++j) c.push_back(std::string("torque_") + joint_name(j) + "_Nm");
  for (int j = 0; j < kJointCount; ++j) c.push_back(std::string("power_") + joint_name(j) + "_W");
  for (int j = 0; j < kJointCount; ++j) {
    c.push_back(std::string("force_") + joint_name(j) + "_x_N");
    c.push_back(std::string("force_") + joint_name(j) + "_y_N");
  }
  for (const char* name : {"residual_x_N", "residual_y_N", "residual_moment_Nm", "iterations"}) c.emplace_back(name);
  if (mediolateral)
    for (const char* name : {"grf_lateral_r_N", "grf_lateral_l_N", "cop_lateral_r_m", "cop_lateral_l_m"}) c.emplace_back(name);
  if (moments_3d)
    for (const char* s : {"r", "l"}) {
      for (const char* joint : kJoint3DNames)
        for (const char* plane : kPlaneNames) c.push_back(std::string(joint) + "_" + plane + "_" + s + "_Nm");
      c.push_back(std::string("knee_adduction_moment_") + s + "_Nm");
    }
  return c;
}

void results_row(const EstimateResult& r, Eigen::Index i, std::span<double> v) {
  std::size_t k = 0;
  v[k++] = static_cast<double>(r.first_frame_number + i);
  v[k++] = r.time_s[i];
  for (int s = 0; s < 2; ++s) {
    const auto& f = r.feet[static_cast<std::size_t>(s)];
    v[k++] = f.force_N(i, 0), v[k++] = f.force_N(i, 1), v[k++] = f.cop_x_m[i];
    v[k++] = f.contact[static_cast<std::size_t>(i)] ? 1.0 : 0.0;
    v[k++] = f.gap_m[i], v[k++] = f.inclination_rad[i], v[k++] = f.raw_force_N(i, 1);
  }
  // The totals: held, or remade from the motion (a result that holds no series of them).
  const bool held = r.grm_Nm.size() == r.time_s.size();
  const FrameTotals t = held ? FrameTotals{} : frame_totals(r, i);
  v[k++] = held ? r.grm_Nm[i] : t.grm_Nm;
  for (int j = 0; j < kJointCount; ++j) v[k++] = r.joint_torque_Nm(i, j);
  const std::array<double, kJointCount> w = joint_angular_velocities(r.motion, i);
  for (int j = 0; j < kJointCount; ++j) v[k++] = r.joint_torque_Nm(i, j) * w[static_cast<std::size_t>(j)];
  for (int j = 0; j < 2 * kJointCount; ++j) v[k++] = held ? r.joint_force_N(i, j) : t.joint_force_N[static_cast<std::size_t>(j)];
  for (int j = 0; j < 3; ++j) v[k++] = held ? r.residual(i, j) : t.residual[j];
  v[k++] = r.iterations[static_cast<std::size_t>(i)];
  if (r.feet[0].force_lateral_N.size() > 0) {
    for (const auto& f : r.feet) v[k++] = f.force_lateral_N[i];
    // The COP's lateral place, as the ground reaction's wrench takes it (lab_foot_frame).
    for (const auto& f : r.feet) v[k++] = f.cop_lateral_m.size() > i ? f.cop_lateral_m[i] : std::numeric_limits<double>::quiet_NaN();
  }
  if (r.legs_3d)
    for (int s = 0; s < 2; ++s) {
      const JointMoments3D& m = r.legs_3d->moments;
      for (int joint = 0; joint < 3; ++joint)
        for (int a = 0; a < 3; ++a) v[k++] = joint_moments_of(m, joint, s)(i, a);
      v[k++] = knee_adduction_moment(m, s, i);
    }
}

ResultsTable results_table(const EstimateResult& r) {
  ResultsTable t;
  t.columns = results_columns(r.feet[0].force_lateral_N.size() > 0, r.legs_3d.has_value());
  const Eigen::Index n = r.time_s.size();
  const auto nc = static_cast<Eigen::Index>(t.columns.size());
  t.values.resize(n, nc);
  std::vector<double> row(static_cast<std::size_t>(nc));
  for (Eigen::Index i = 0; i < n; ++i) {
    results_row(r, i, row);
    t.values.row(i) = Eigen::Map<const Eigen::RowVectorXd>(row.data(), nc);
  }
  return t;
}

void write_results_csv(std::ostream& os, const EstimateResult& r) {
  const std::vector<std::string> columns = results_columns(r.feet[0].force_lateral_N.size() > 0, r.legs_3d.has_value());
  std::string buf;
  for (std::size_t k = 0; k < columns.size(); ++k) (buf += k ? "," : "") += columns[k];
  buf += '\n';
  // Counts (frame, contact, iterations) as integers; the rest to 6 significant digits; NaN empty.
  std::vector<bool> integer(columns.size());
  for (std::size_t k = 0; k < columns.size(); ++k)
    integer[k] = columns[k] == "frame" || columns[k].rfind("contact_", 0) == 0 || columns[k] == "iterations";
  std::vector<double> row(columns.size());
  char num[64];
  for (Eigen::Index i = 0; i < r.time_s.size(); ++i) {
    results_row(r, i, row);
    for (std::size_t k = 0; k < row.size(); ++k) {
      const double x = row[k];
      if (k) buf += ',';
      if (integer[k]) buf += std::to_string(static_cast<long long>(x));
      else if (std::isfinite(x)) buf.append(num, std::to_chars(num, num + sizeof num, x, std::chars_format::general, 6).ptr);  // = %.6g
    }
    buf += '\n';
    flush_if_full(buf, os);
  }
  flush_if_full(buf, os, true);
}

void write_results_csv(const std::string& path, const EstimateResult& r) {
  AtomicFile file(path);
  write_results_csv(file.stream(), r);
  file.commit();
}

std::string format_results_csv(const EstimateResult& r) {
  std::ostringstream os;
  write_results_csv(os, r);
  return os.str();
}

namespace {

/// The runs of frames in contact.
std::vector<IndexRun> contact_runs(const std::vector<bool>& c) {
  return runs_where(static_cast<Eigen::Index>(c.size()), [&](Eigen::Index i) { return c[static_cast<std::size_t>(i)]; });
}

/// Per side, per stance (a contact run): the external knee adduction moment's first and second
/// peaks, its largest value in the stance's first and second halves (N m and N m/kg), and its
/// angular impulse (stance_impulse: the positive part's time integral, N m s and N m s/kg), as
/// validate takes them; `complete` is false for a stance the processed window cuts (its peaks may
/// lie outside it, and its impulse is the part inside).
nlohmann::json knee_adduction_peaks_json(const EstimateResult& r) {
  nlohmann::json out = nlohmann::json::object();
  const auto n = r.time_s.size();
  for (int s = 0; s < 2; ++s) {
    const Eigen::VectorXd kam = knee_adduction_moment(r.legs_3d->moments, s);
    nlohmann::json stances = nlohmann::json::array();
    for (const auto& run : contact_runs(r.feet[static_cast<std::size_t>(s)].contact)) {
      if (run.last <= run.first) continue;  // a stance of one frame has no halves
      const auto [first, second] = stance_peaks(kam, run.first, run.last);
      const double impulse = stance_impulse(kam, r.time_s, run.first, run.last);
      stances.push_back({{"start_s", r.time_s[run.first]}, {"end_s", r.time_s[run.last]},
                         {"complete", run.first > 0 && run.last < n - 1},
                         {"first_peak_Nm", first}, {"second_peak_Nm", second},
                         {"first_peak_Nm_per_kg", first / r.mass_kg}, {"second_peak_Nm_per_kg", second / r.mass_kg},
                         {"impulse_Nm_s", impulse}, {"impulse_Nm_s_per_kg", impulse / r.mass_kg}});
    }
    out[side_name(s)] = stances;
  }
  return out;
}

}  // namespace

nlohmann::json stance_parameters_json(const StanceParameters& p, double body_weight_N) {
  const auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  const auto bw = [&](double x) { return num(body_weight_N > 0 ? x / body_weight_N : std::numeric_limits<double>::quiet_NaN()); };
  return {{"duration_s", num(p.duration_s)},
          {"vertical_first_peak_N", num(p.vertical_first_peak_N)}, {"vertical_first_peak_bw", bw(p.vertical_first_peak_N)},
          {"vertical_valley_N", num(p.vertical_valley_N)}, {"vertical_valley_bw", bw(p.vertical_valley_N)},
          {"vertical_second_peak_N", num(p.vertical_second_peak_N)}, {"vertical_second_peak_bw", bw(p.vertical_second_peak_N)},
          {"vertical_peak_N", num(p.vertical_peak_N)}, {"vertical_peak_bw", bw(p.vertical_peak_N)},
          {"braking_peak_N", num(p.braking_peak_N)}, {"braking_peak_bw", bw(p.braking_peak_N)},
          {"propulsive_peak_N", num(p.propulsive_peak_N)}, {"propulsive_peak_bw", bw(p.propulsive_peak_N)},
          {"vertical_impulse_Ns", num(p.vertical_impulse_Ns)}, {"braking_impulse_Ns", num(p.braking_impulse_Ns)},
          {"propulsive_impulse_Ns", num(p.propulsive_impulse_Ns)},
          {"loading_rate_N_per_s", num(p.loading_rate_N_per_s)}, {"loading_rate_bw_per_s", bw(p.loading_rate_N_per_s)}};
}

nlohmann::json joint_kinetic_peaks_json(const JointKineticPeaks& p, double mass_kg) {
  const auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  const auto kg = [&](double x) { return num(mass_kg > 0 ? x / mass_kg : std::numeric_limits<double>::quiet_NaN()); };
  return {{"ankle_plantarflexor_moment_Nm", num(p.ankle_plantarflexor_moment_Nm)},
          {"ankle_plantarflexor_moment_Nm_per_kg", kg(p.ankle_plantarflexor_moment_Nm)},
          {"ankle_push_off_power_W", num(p.ankle_push_off_power_W)}, {"ankle_push_off_power_W_per_kg", kg(p.ankle_push_off_power_W)},
          {"knee_extensor_moment_Nm", num(p.knee_extensor_moment_Nm)}, {"knee_extensor_moment_Nm_per_kg", kg(p.knee_extensor_moment_Nm)},
          {"hip_extensor_moment_Nm", num(p.hip_extensor_moment_Nm)}, {"hip_extensor_moment_Nm_per_kg", kg(p.hip_extensor_moment_Nm)},
          {"hip_flexor_moment_Nm", num(p.hip_flexor_moment_Nm)}, {"hip_flexor_moment_Nm_per_kg", kg(p.hip_flexor_moment_Nm)}};
}

namespace {

/// One stance of the estimate's own contact (gait_stances: the stances the gait events mark) and
/// its parameters (dynamics/stance_parameters.hpp) from the post-filtered force.
struct EstimatedStance {
  int side = 0;
  IndexRun run;
  bool complete = false;  ///< false where the processed window cuts it
  StanceParameters parameters;
  JointKineticPeaks kinetics;  ///< from the joint torques and powers
};

/// Every foot's stances, in time order (at one frame: the right foot first).
std::vector<EstimatedStance> estimated_stances(const EstimateResult& r) {
  std::vector<EstimatedStance> out;
  const auto n = r.time_s.size();
  for (int s = 0; s < 2; ++s) {
    const FootResult& f = r.feet[static_cast<std::size_t>(s)];
    for (const auto& run : gait_stances(f.contact, r.motion.rate_hz))
      out.push_back({s, run, run.first > 0 && run.last < n - 1, stance_parameters(f.force_N, r.motion.rate_hz, run.first, run.last),
                     joint_kinetic_peaks(r.joint_torque_Nm, r.motion, s, run.first, run.last)});
  }
  std::stable_sort(out.begin(), out.end(), [](const EstimatedStance& a, const EstimatedStance& b) {
    return a.run.first != b.run.first ? a.run.first < b.run.first : a.side < b.side;
  });
  return out;
}

/// The summary's `stance_parameters`: per side, its stances in time order.
nlohmann::json stance_parameters_by_side_json(const EstimateResult& r) {
  nlohmann::json out = {{side_name(0), nlohmann::json::array()}, {side_name(1), nlohmann::json::array()}};
  const double body_weight_N = r.mass_kg * r.model().gravity_mps2;
  for (const EstimatedStance& st : estimated_stances(r)) {
    nlohmann::json j = {{"start_s", r.time_s[st.run.first]}, {"end_s", r.time_s[st.run.last]}, {"complete", st.complete}};
    j.update(stance_parameters_json(st.parameters, body_weight_N));
    j["joint_kinetics"] = joint_kinetic_peaks_json(st.kinetics, r.mass_kg);
    out[side_name(st.side)].push_back(std::move(j));
  }
  return out;
}

}  // namespace

std::string stance_parameters_csv(const EstimateResult& r) {
  std::ostringstream os;
  os << "side,frame_first,frame_last,start_s,duration_s,complete,vertical_first_peak_N,vertical_first_peak_bw,vertical_valley_N,"
        "vertical_valley_bw,vertical_second_peak_N,vertical_second_peak_bw,vertical_peak_N,vertical_peak_bw,braking_peak_N,"
        "braking_peak_bw,propulsive_peak_N,propulsive_peak_bw,vertical_impulse_Ns,braking_impulse_Ns,propulsive_impulse_Ns,"
        "loading_rate_N_per_s,loading_rate_bw_per_s,ankle_plantarflexor_moment_Nm_per_kg,ankle_push_off_power_W_per_kg,"
        "knee_extensor_moment_Nm_per_kg,hip_extensor_moment_Nm_per_kg,hip_flexor_moment_Nm_per_kg\n";
  const double bw = r.mass_kg * r.model().gravity_mps2;
  const auto cell = [&os](double x) {
    os << ',';
    if (!std::isfinite(x)) return;  // an empty cell: the value does not exist
    char b[32];
    os << std::string_view(b, static_cast<std::size_t>(std::to_chars(b, b + sizeof b, x, std::chars_format::general, 6).ptr - b));
  };
  for (const EstimatedStance& st : estimated_stances(r)) {
    const StanceParameters& p = st.parameters;
    os << side_name(st.side) << ',' << r.first_frame_number + st.run.first << ',' << r.first_frame_number + st.run.last << ',';
    char b[32];  // the start at full precision, as the gait events CSV gives times (6 digits are 1 ms at 100 s)
    os << std::string_view(b, static_cast<std::size_t>(std::to_chars(b, b + sizeof b, r.time_s[st.run.first]).ptr - b));
    cell(p.duration_s);
    os << ',' << (st.complete ? 1 : 0);
    for (double f : {p.vertical_first_peak_N, p.vertical_valley_N, p.vertical_second_peak_N, p.vertical_peak_N, p.braking_peak_N,
                     p.propulsive_peak_N}) {
      cell(f);
      cell(bw > 0 ? f / bw : std::numeric_limits<double>::quiet_NaN());
    }
    for (double x : {p.vertical_impulse_Ns, p.braking_impulse_Ns, p.propulsive_impulse_Ns, p.loading_rate_N_per_s}) cell(x);
    cell(bw > 0 ? p.loading_rate_N_per_s / bw : std::numeric_limits<double>::quiet_NaN());
    const JointKineticPeaks& k = st.kinetics;
    for (double x : {k.ankle_plantarflexor_moment_Nm, k.ankle_push_off_power_W, k.knee_extensor_moment_Nm, k.hip_extensor_moment_Nm,
                     k.hip_flexor_moment_Nm})
      cell(r.mass_kg > 0 ? x / r.mass_kg : std::numeric_limits<double>::quiet_NaN());
    os << '\n';
  }
  return os.str();
}

std::string joint_moment_curve_name(const std::string& joint, const std::string& plane) { return joint + "_" + plane + "_Nm_per_kg"; }

namespace {

/// The five columns that place a stance's rows, before its series.
constexpr const char* kStanceCurveKeys[] = {"side", "frame_first", "start_s", "duration_s", "percent"};

/// One series of stance_curves_table: its column, and its value on `side` at frame i (the
/// per-frame CSV's, results_row's, times the series' scale); `w`: the frame's joint angular
/// velocities, which the powers take.
struct CurveSeries {
  std::string name;
  std::function<double(int side, Eigen::Index i, const std::array<double, kJointCount>& w)> at;
};

/// stance_curves_table's series, in its columns' order: forces per body weight, moments and
/// powers per kg of body mass.
std::vector<CurveSeries> stance_curve_series(const EstimateResult& r) {
  const double per_bw = 1 / (r.mass_kg * r.model().gravity_mps2), per_kg = 1 / r.mass_kg;
  const auto foot = [&r](int side) -> const FootResult& { return r.feet[static_cast<std::size_t>(side)]; };
  std::vector<CurveSeries> c;
  c.push_back({"grf_vertical_bw", [=](int s, Eigen::Index i, const auto&) { return foot(s).force_N(i, 1) * per_bw; }});
  c.push_back({"grf_anterior_bw", [=](int s, Eigen::Index i, const auto&) { return foot(s).force_N(i, 0) * per_bw; }});
  if (r.feet[0].force_lateral_N.size() > 0)
    c.push_back({"grf_lateral_bw", [=](int s, Eigen::Index i, const auto&) { return foot(s).force_lateral_N[i] * per_bw; }});
  c.push_back({"cop_progression_m", [=](int s, Eigen::Index i, const auto&) { return foot(s).cop_x_m[i]; }});  // made progression below
  c.push_back({"foot_inclination_rad", [=](int s, Eigen::Index i, const auto&) { return foot(s).inclination_rad[i]; }});
  for (int k = 0; k < 3; ++k)
    c.push_back({std::string("torque_") + kLegJointNames[k] + "_Nm_per_kg",
                 [&r, k, per_kg](int s, Eigen::Index i, const auto&) { return r.joint_torque_Nm(i, 4 * s + k) * per_kg; }});
  for (int k = 0; k < 3; ++k)
    c.push_back({std::string("power_") + kLegJointNames[k] + "_W_per_kg", [&r, k, per_kg](int s, Eigen::Index i, const auto& w) {
                   return r.joint_torque_Nm(i, 4 * s + k) * w[static_cast<std::size_t>(4 * s + k)] * per_kg;
                 }});
  if (r.legs_3d) {
    c.push_back({"knee_adduction_moment_Nm_per_kg",
                 [&r, per_kg](int s, Eigen::Index i, const auto&) { return knee_adduction_moment(r.legs_3d->moments, s, i) * per_kg; }});
    // The 3D joint moments in every plane, as the per-frame CSV's (a 3D gait report's curves).
    for (int joint = 0; joint < 3; ++joint)
      for (int a = 0; a < 3; ++a)
        c.push_back({joint_moment_curve_name(kJoint3DNames[joint], kPlaneNames[a]),
                     [&r, joint, a, per_kg](int s, Eigen::Index i, const auto&) {
                       return joint_moments_of(r.legs_3d->moments, joint, s)(i, a) * per_kg;
                     }});
  }
  return c;
}

std::vector<std::string> stance_curve_columns(const EstimateResult& r) {
  std::vector<std::string> c(std::begin(kStanceCurveKeys), std::end(kStanceCurveKeys));
  for (const CurveSeries& x : stance_curve_series(r)) c.push_back(x.name);
  return c;
}

/// Every complete stance's rows of stance_curves_table (points x its columns), one stance at a
/// time to `emit`: a long trial's curves are never held together.
template <class Emit>
void each_stance_curve(const EstimateResult& r, int points, Emit emit) {
  const std::vector<CurveSeries> series_of = stance_curve_series(r);
  const auto cop = static_cast<Eigen::Index>(
      std::find_if(series_of.begin(), series_of.end(), [](const CurveSeries& x) { return x.name == "cop_progression_m"; }) - series_of.begin());
  const auto keys = static_cast<Eigen::Index>(std::size(kStanceCurveKeys)), n = static_cast<Eigen::Index>(series_of.size());
  for (const EstimatedStance& st : estimated_stances(r)) {
    if (!st.complete) continue;  // part of a stance is not its 0-100 %
    const Eigen::Index frames = st.run.last - st.run.first + 1;
    Eigen::MatrixXd series(frames, n);
    for (Eigen::Index i = 0; i < frames; ++i) {
      const std::array<double, kJointCount> w = joint_angular_velocities(r.motion, st.run.first + i);
      for (Eigen::Index k = 0; k < n; ++k) series(i, k) = series_of[static_cast<std::size_t>(k)].at(st.side, st.run.first + i, w);
    }
    // The COP's progression over the ground: on a treadmill over the belt, which carries the foot
    // back (TrialCalibration::belt_velocity_mps; 0 overground), so that it reads as overground.
    // From the first frame it exists on (a landing's first frame can be unloaded).
    const double belt = r.calibration.belt_velocity_mps;
    for (Eigen::Index i = 0; i < frames; ++i) series(i, cop) -= belt * (r.time_s[st.run.first + i] - r.time_s[st.run.first]);
    double origin = std::numeric_limits<double>::quiet_NaN();
    for (Eigen::Index i = 0; i < frames && !std::isfinite(origin); ++i) origin = series(i, cop);
    series.col(cop).array() -= origin;
    Eigen::MatrixXd block(points, keys + n);
    block.rightCols(n) = stance_normalised(series, 0, frames - 1, points);
    for (int k = 0; k < points; ++k) {
      block(k, 0) = st.side;
      block(k, 1) = static_cast<double>(r.first_frame_number + st.run.first);
      block(k, 2) = r.time_s[st.run.first];
      block(k, 3) = st.parameters.duration_s;
      block(k, 4) = 100.0 * k / (points - 1);
    }
    emit(block);
  }
}

}  // namespace

ResultsTable stance_curves_table(const EstimateResult& r, int points) {
  ResultsTable t;
  t.columns = stance_curve_columns(r);
  std::vector<Eigen::MatrixXd> blocks;
  each_stance_curve(r, points, [&](const Eigen::MatrixXd& b) { blocks.push_back(b); });
  t.values.resize(static_cast<Eigen::Index>(blocks.size()) * points, static_cast<Eigen::Index>(t.columns.size()));
  for (std::size_t k = 0; k < blocks.size(); ++k) t.values.middleRows(static_cast<Eigen::Index>(k) * points, points) = blocks[k];
  return t;
}

void write_stance_curves_csv(std::ostream& os, const EstimateResult& r) {
  const auto columns = stance_curve_columns(r);
  std::string buf;
  for (std::size_t k = 0; k < columns.size(); ++k) (buf += k ? "," : "") += columns[k];
  buf += '\n';
  each_stance_curve(r, kStanceCurvePoints, [&](const Eigen::MatrixXd& b) {
    for (Eigen::Index i = 0; i < b.rows(); ++i)
      append_stance_curve_row(buf, static_cast<int>(b(i, 0)), nullptr, b(i, 1), b(i, 2), b.row(i).tail(b.cols() - 3));
    flush_if_full(buf, os);
  });
  flush_if_full(buf, os, true);
}

void append_stance_curve_row(std::string& out, int side, const std::string* label, double frame_first, double start_s,
                             const Eigen::Ref<const Eigen::RowVectorXd>& rest) {
  out += side_name(side);
  if (label) out += ',' + csv_quoted(*label);
  out += ',' + std::to_string(static_cast<long long>(frame_first)) + ',';
  char num[64];
  out.append(num, std::to_chars(num, num + sizeof num, start_s).ptr);  // the start at full precision, as --stances
  for (Eigen::Index k = 0; k < rest.size(); ++k) append_csv_number(out += ',', rest[k]);
  out += '\n';
}

void write_stance_curves_csv(const std::string& path, const EstimateResult& r) {
  AtomicFile file(path);
  write_stance_curves_csv(file.stream(), r);
  file.commit();
}

std::string stance_curves_csv(const EstimateResult& r) {
  std::ostringstream os;
  write_stance_curves_csv(os, r);
  return os.str();
}

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
  j["kinematic_cutoff_hz"] = r.kinematic_cutoff_hz;  // the dynamics' (lowered for noisy markers, not below the stance floor)
  j["position_cutoff_hz"] = r.position_cutoff_hz;    // the COP function's foot angle's
  j["post_cutoff_hz"] = r.post_cutoff_hz;            // the one used (per stance, or fixed)
  const auto n = r.time_s.size();
  j["frames"] = {{"first", r.first_frame_number}, {"last", r.first_frame_number + n - 1}, {"count", n}};
  json contacts = json::object();
  for (int s = 0; s < 2; ++s) {
    json iv = json::array();
    for (const auto& run : contact_runs(r.feet[s].contact)) iv.push_back({{"start_s", r.time_s[run.first]}, {"end_s", r.time_s[run.last]}});
    contacts[side_name(s)] = iv;
  }
  j["contact_intervals"] = contacts;
  json events = json::array();
  for (const GaitEvent& e : gait_events({r.feet[0].contact, r.feet[1].contact}, r.time_s, r.motion.rate_hz))
    events.push_back({{"event", e.label}, {"side", side_name(e.side)}, {"frame", r.first_frame_number + e.index}, {"time_s", e.time_s}});
  j["gait_events"] = events;
  j["stance_parameters"] = stance_parameters_by_side_json(r);
  if (r.legs_3d) j["knee_adduction_moment"] = knee_adduction_peaks_json(r);
  double mean_it = 0;
  int max_it = 0;
  for (int it : r.iterations) { mean_it += it; max_it = std::max(max_it, it); }
  j["iterations"] = {{"mean", n ? mean_it / static_cast<double>(n) : 0.0}, {"max", max_it},
                     {"cycled_frames", r.cycled_frames}, {"capped_frames", r.capped_frames}};
  Eigen::MatrixX3d remade;  // the residual of a result that does not hold it, for these three numbers
  if (r.residual.rows() != n) {
    remade.resize(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) remade.row(i) = frame_totals(r, i).residual.transpose();
  }
  const Eigen::MatrixX3d& residual = r.residual.rows() == n ? r.residual : remade;
  j["residual_rms"] = {{"x_N", std::sqrt(residual.col(0).squaredNorm() / std::max<double>(1, static_cast<double>(n)))},
                       {"y_N", std::sqrt(residual.col(1).squaredNorm() / std::max<double>(1, static_cast<double>(n)))},
                       {"moment_Nm", std::sqrt(residual.col(2).squaredNorm() / std::max<double>(1, static_cast<double>(n)))}};
  j["timing"] = {{"kinematics_s", r.seconds_kinematics}, {"dynamics_s", r.seconds_dynamics},
                 {"frames_per_s", static_cast<double>(n) / std::max(1e-9, r.seconds_kinematics + r.seconds_dynamics)}};
  j["messages"] = r.messages;
  json seg = json::array();
  for (int s = 0; s < kSegmentCount; ++s)
    seg.push_back({{"segment", segment_name(s)}, {"length_m", r.model().bodies[s].length_m}, {"mass_kg", r.model().bodies[s].mass_kg}});
  j["segments"] = seg;
  return j;
}

std::string gait_events_csv(const EstimateResult& r) {
  std::ostringstream os;
  os << "side,event,frame,time_s\n";
  for (const GaitEvent& e : gait_events({r.feet[0].contact, r.feet[1].contact}, r.time_s, r.motion.rate_hz)) {
    char b[32];
    const auto end = std::to_chars(b, b + sizeof b, e.time_s).ptr;  // the shortest text that reads back the same
    os << side_name(e.side) << ',' << e.label << ',' << r.first_frame_number + e.index << ',' << std::string_view(b, end - b) << '\n';
  }
  return os.str();
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
  const double bw = r.mass_kg * r.model().gravity_mps2;
  for (int s = 0; s < 2; ++s) {
    const auto& f = r.feet[static_cast<std::size_t>(s)];
    std::snprintf(b, sizeof b, "%-5s foot: %zu contact interval(s), peak vertical %.0f N (%.2f body weights)\n", side_name(s),
                  contact_runs(f.contact).size(), f.force_N.col(1).maxCoeff(), f.force_N.col(1).maxCoeff() / bw);
    os << b;
  }
  return os.str();
}

}  // namespace kin2grf
