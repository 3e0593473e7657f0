#include "kin2grf/output/report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "kin2grf/dynamics/joint_moments_2d.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {

std::string html_escape(const std::string& s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

namespace {

// JSON inside <script>: "</" would close the element.
std::string script_safe(std::string s) {
  for (std::size_t p = 0; (p = s.find("</", p)) != std::string::npos; p += 3) s.replace(p, 2, "<\\/");
  return s;
}

const char* kScript = R"js(
const figs = JSON.parse(document.getElementById('kin2grf-data').textContent);
const shade = {id: 'shade', beforeDatasetsDraw(chart, args, opts) {
  const {ctx, chartArea: a, scales: {x}} = chart;
  ctx.save(); ctx.fillStyle = 'rgba(110,110,110,0.13)';
  for (const [s, e] of (opts.intervals || [])) {
    const x0 = Math.max(a.left, x.getPixelForValue(s)), x1 = Math.min(a.right, x.getPixelForValue(e));
    if (x1 > x0) ctx.fillRect(x0, a.top, x1 - x0, a.bottom - a.top);
  }
  ctx.restore();
}};
const colors = ['#d62728', '#1f77b4', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#e377c2'];
let rendered = 0, points = 0;
figs.forEach((f, i) => {
  let c = 0;
  const datasets = f.series.map(s => {
    points += s.x.length;
    return {label: s.label, data: s.x.map((x, k) => ({x: x, y: s.y[k]})),
            borderColor: s.measured ? '#000' : colors[c++ % colors.length],
            borderWidth: s.measured ? 2 : 1.5, pointRadius: f.log_x ? 3 : 0, spanGaps: false};
  });
  new Chart(document.getElementById('fig' + i), {type: 'line', data: {datasets: datasets},
    options: {animation: false, responsive: true, maintainAspectRatio: false, parsing: true,
      plugins: {title: {display: true, text: f.title}, shade: {intervals: f.shaded}, legend: {position: 'bottom'}},
      scales: {x: {type: f.log_x ? 'logarithmic' : 'linear', title: {display: true, text: f.x_label}},
               y: {title: {display: true, text: f.y_label}}}},
    plugins: [shade]});
  rendered++;
});
document.body.dataset.chartsRendered = String(rendered);
document.body.dataset.points = String(points);
)js";

const char* kStyle = R"css(
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 0.9em; }
td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f2f2f2; } td.l, th.l { text-align: left; }
.fig { height: 300px; max-width: 1100px; margin-bottom: 1.2em; }
pre { background: #f7f7f7; padding: 0.6em; font-size: 0.85em; overflow-x: auto; }
)css";

}  // namespace

std::string render_report_html(const Report& r) {
  nlohmann::json figs = nlohmann::json::array();
  for (const auto& f : r.figures) {
    nlohmann::json jf = {{"title", f.title}, {"x_label", f.x_label}, {"y_label", f.y_label}, {"log_x", f.log_x}};
    jf["shaded"] = nlohmann::json::array();
    for (const auto& [a, b] : f.shaded) jf["shaded"].push_back({a, b});
    jf["series"] = nlohmann::json::array();
    for (const auto& s : f.series) {
      nlohmann::json y = nlohmann::json::array();
      for (double v : s.y) y.push_back(std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr));
      jf["series"].push_back({{"label", s.label}, {"x", s.x}, {"y", y}, {"measured", s.measured}});
    }
    figs.push_back(jf);
  }
  std::ostringstream os;
  os << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" << html_escape(r.title)
     << "</title>\n<style>" << kStyle << "</style>\n<script>" << chartjs_source() << "</script>\n</head>\n<body>\n<h1>"
     << html_escape(r.title) << "</h1>\n";
  for (const auto& s : r.sections_html) os << s << "\n";
  for (std::size_t i = 0; i < r.figures.size(); ++i) os << "<div class=\"fig\"><canvas id=\"fig" << i << "\"></canvas></div>\n";
  os << "<script id=\"kin2grf-data\" type=\"application/json\">" << script_safe(figs.dump()) << "</script>\n<script>" << kScript
     << "</script>\n<p><small>Made by kin2grf " << KIN2GRF_VERSION << "; plots drawn with Chart.js (MIT licence).</small></p>\n"
     << "</body></html>\n";
  return os.str();
}

namespace {

std::string fmt(const nlohmann::json& x, const char* f = "%.1f") {
  if (!x.is_number()) return "-";
  char b[32];
  std::snprintf(b, sizeof b, f, x.get<double>());
  return b;
}

std::vector<double> to_vec(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

/// A figure that takes the plate's COP, in brackets where the plate fails validate's registration
/// check (StanceValidation::cop_reference_suspect: kept for the record, left out of the means).
/// A cell of a stance whose plate fails the registration check, in brackets (not scored); "-" as it is.
std::string bracket_if_misregistered(const nlohmann::json& stance, const std::string& text) {
  return stance.value("cop_reference_suspect", false) && text != "-" ? "[" + text + "]" : text;
}

std::string fmt_cop(const nlohmann::json& stance, const nlohmann::json& x, const char* f = "%.1f") {
  return bracket_if_misregistered(stance, fmt(x, f));
}

/// The stance parameters' table rows' cells (dynamics/stance_parameters.hpp): the vertical peaks and
/// valley and the braking and propulsive peaks in body weights, the impulses in N s, the loading
/// rate in body weights per second.
std::string stance_parameter_cells(const nlohmann::json& p) {
  std::string out;
  for (const char* k : {"vertical_first_peak_bw", "vertical_valley_bw", "vertical_second_peak_bw", "braking_peak_bw", "propulsive_peak_bw"})
    out += "<td>" + fmt(p.value(k, nlohmann::json()), "%.2f") + "</td>";
  for (const char* k : {"braking_impulse_Ns", "propulsive_impulse_Ns"}) out += "<td>" + fmt(p.value(k, nlohmann::json())) + "</td>";
  return out + "<td>" + fmt(p.value("loading_rate_bw_per_s", nlohmann::json())) + "</td>";
}

constexpr const char* kStanceParameterHeads =
    "<th>vertical first peak BW</th><th>valley BW</th><th>second peak BW</th><th>braking peak BW</th>"
    "<th>propulsive peak BW</th><th>braking impulse N s</th><th>propulsive impulse N s</th><th>loading rate BW/s</th>";

}  // namespace

namespace {

/// The time-normalised tables' instants a stance (stance_curves_table, validation_stance_curves_table).
constexpr Eigen::Index kCurvePoints = kStanceCurvePoints;

Eigen::Index curve_column_index(const ResultsTable& c, const std::string& name) {
  const auto it = std::find(c.columns.begin(), c.columns.end(), name);
  if (it == c.columns.end()) throw std::logic_error("report: no stance-curve column " + name);
  return static_cast<Eigen::Index>(it - c.columns.begin());
}

/// One stance's curve of `name` (the stance-th block of kCurvePoints rows).
std::vector<double> curve_column(const ResultsTable& c, const std::string& name, Eigen::Index stance) {
  const Eigen::Index col = curve_column_index(c, name);
  std::vector<double> out(static_cast<std::size_t>(kCurvePoints));
  for (Eigen::Index k = 0; k < kCurvePoints; ++k) out[static_cast<std::size_t>(k)] = c.values(stance * kCurvePoints + k, col);
  return out;
}

/// The joints as a gait report lists them, proximal first (the sagittal torques' and the 3D moments').
constexpr std::span<const char* const> kReportJoints{kLegJointNames, 3};

/// A stance's COP RMSE in mm and in % of the foot's length (issue 29), bracketed as fmt_cop does.
std::string cop_mm_cell(const nlohmann::json& stance) {
  const auto& mm = stance["rmse"]["cop_mm"];
  if (!mm.is_number()) return "-";
  const auto& foot = stance.value("cop_rmse_percent_foot", nlohmann::json());
  return bracket_if_misregistered(stance, fmt(mm) + (foot.is_number() ? " (" + fmt(foot) + " %)" : std::string()));
}

/// Both reports' time-normalised 3D joint moments (--model 3d): per joint and plane, the figure's
/// title (the moment and its sign, dynamics/joint_moments_3d.hpp) and its stance-curves column.
std::vector<std::pair<std::string, std::string>> joint_moment_curves() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const char* joint : kReportJoints)
    for (const char* plane : kPlaneNames) {
      const std::string p = plane;
      const char* sign = p == "sagittal" ? "+ counter-clockwise in the sagittal frame"
                         : p == "frontal" ? "+ adducts the distal segment"
                                          : "+ rotates the distal segment internally";
      out.emplace_back(std::string(joint) + " " + p + " moment (internal, " + sign + ")", joint_moment_curve_name(joint, p));
    }
  return out;
}

/// The stances' mean curve of `name` at each instant, over the stances of `side` (-1: every
/// stance), each instant over the stances where the value exists (NaN where none has it).
std::vector<double> mean_curve(const ResultsTable& c, const std::string& name, int side) {
  const Eigen::Index col = curve_column_index(c, name), side_col = curve_column_index(c, "side");
  std::vector<double> m(static_cast<std::size_t>(kCurvePoints), std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index k = 0; k < kCurvePoints; ++k) {
    double sum = 0;
    int n = 0;
    for (Eigen::Index st = 0; st < c.values.rows() / kCurvePoints; ++st)
      if (const double x = c.values(st * kCurvePoints + k, col); (side < 0 || c.values(st * kCurvePoints, side_col) == side) && std::isfinite(x))
        sum += x, ++n;
    if (n > 0) m[static_cast<std::size_t>(k)] = sum / n;
  }
  return m;
}

}  // namespace

std::string validation_report_html(const std::string& trial, const EstimateResult& e, const ValidationResult& v,
                                   const nlohmann::json& j) {
  Report rep;
  rep.title = "kin2grf validation: " + trial;
  std::ostringstream t;
  t << "<h2>Errors against the force plates</h2>\n<p>rRMSE and RMSE as in the paper's Eqs. 11-12, per plate stance "
       "(measured vertical force above the threshold) and in total where every loaded foot stands on a plate. "
       "COP compared where the plate carries at least 5 % of body weight; moment about the plate centre (total: GRM about "
       "the midpoint of the plates in use). Timing: estimate minus plate, + = late; an onset on a plate filtered before "
       "export by the loading ramp's zero intercept (20-80 % of the peak, on both; \"ramp\"), the threshold crossings' figure "
       "in brackets. Loaded span: the stance with the frames "
       "next to it where the estimate loads the foot while the plate reads under the threshold (a landing loaded before "
       "it lands), against the plate's reading there. In brackets: a plate whose COP is "
       "not where the markers put the foot (validate's registration check), kept for the record, left out of the "
       "means.</p>\n";
  t << "<table><tr><th class=l>foot</th><th class=l>plate</th><th>frames</th><th>vertical rRMSE %</th><th>anterior rRMSE %</th>"
       "<th>COP rRMSE %</th><th>moment rRMSE %</th><th>vertical RMSE N</th><th>anterior RMSE N</th><th>COP RMSE mm (% of foot length)</th>"
       "<th>vertical r</th><th>onset ms</th><th>offset ms</th><th>vertical rRMSE % over the loaded span</th></tr>\n";
  // A stance timed by the ramps' intercepts (a filtered export's) is marked, the crossings' figure beside it.
  const auto timing = [](const nlohmann::json& s, const std::string& key) {
    const auto& tm = s["timing_ms"];
    std::string cell = fmt(tm[key], "%.0f");
    if (tm.value(key + "_timed_by", "") == "ramp") cell += " ramp (" + fmt(tm[key + "_crossing"], "%.0f") + ")";
    return cell;
  };
  for (const auto& s : j["per_foot"]) {
    t << "<tr><td class=l>" << s["foot"].get<std::string>() << "</td><td class=l>" << html_escape(s["plate"].get<std::string>())
      << "</td><td>" << s["frames"][0] << "-" << s["frames"][1] << "</td><td>" << fmt(s["rrmse_percent"]["vertical"]) << "</td><td>"
      << fmt(s["rrmse_percent"]["anterior"]) << "</td><td>" << fmt_cop(s, s["rrmse_percent"]["cop"]) << "</td><td>"
      << fmt_cop(s, s["rrmse_percent"]["moment"]) << "</td><td>" << fmt(s["rmse"]["vertical_N"]) << "</td><td>"
      << fmt(s["rmse"]["anterior_N"]) << "</td><td>"
      << cop_mm_cell(s) << "</td><td>" << fmt(s["r"]["vertical"], "%.3f")
      << "</td><td>" << timing(s, "onset") << "</td><td>" << timing(s, "offset") << "</td><td>"
      << fmt(s.contains("loaded_span") ? s["loaded_span"]["vertical_rrmse_percent"] : nlohmann::json()) << "</td></tr>\n";
  }
  if (!j["total"].is_null()) {
    const auto& s = j["total"];
    t << "<tr><td class=l>total</td><td class=l>GRM</td><td>" << s["frames_compared"] << " frames</td><td>"
      << fmt(s["rrmse_percent"]["vertical"]) << "</td><td>" << fmt(s["rrmse_percent"]["anterior"]) << "</td><td>-</td><td>"
      // The GRM's RMSE in N m beside its rRMSE: a window of single support spans a few tens of N m.
      << fmt(s["rrmse_percent"]["moment"]) << " (" << fmt(s["rmse"]["moment_Nm"]) << " N m)</td><td>" << fmt(s["rmse"]["vertical_N"]) << "</td><td>"
      << fmt(s["rmse"]["anterior_N"]) << "</td><td>-</td><td>" << fmt(s["r"]["vertical"], "%.3f") << "</td><td></td><td></td><td></td></tr>\n";
  }
  t << "<tr><td class=l colspan=3>paper, Table 1 (24 gait trials)</td><td>4.1 (1.1)</td><td>11.2 (1.7)</td><td>-</td>"
       "<td>5.3 (1.1)</td><td colspan=7></td></tr>\n</table>\n";
  // The marker-plate time offset (validate's step 6, issue 29: "report it with its confidence, in
  // the text, the JSON and the report"), as the text gives it.
  if (const auto& sync = j.value("sync", nlohmann::json()); sync.is_object()) {
    t << "<p>Marker-plate time offset: ";
    if (sync.value("estimated_offset_ms", nlohmann::json()).is_number())
      t << fmt(sync["estimated_offset_ms"], "%+.0f") << " ms (&plusmn;" << fmt(sync["uncertainty_ms"], "%.1f")
        << " ms; + = the plates lead), from the plates' total vertical force against the whole body's from the markers "
           "(median |plates - kinematics| "
        << fmt(sync["total_vertical_error_as_recorded_N"], "%.0f") << " N as recorded, "
        << fmt(sync["total_vertical_error_at_offset_N"], "%.0f") << " N at the offset)";
    else
      t << "not estimated (too few loaded frames clear of the recording's ends, or the best shift at the search's limit)";
    const double shift = sync.value("applied_shift_ms", 0.0);
    if (std::abs(shift) < 0.5) t << "; the figures above compare the plates as recorded (--sync auto aligns them first).</p>\n";
    else t << "; the figures above compare the plates shifted by " << fmt(sync["applied_shift_ms"], "%+.0f") << " ms (--sync).</p>\n";
  }
  t << "<h3>Stance parameters</h3>\n<p>Each stance's ground reaction parameters, kin2grf's against the plate's over the "
       "stance's loaded span: the vertical force's largest value in each half of the stance and the least between them, "
       "the braking and propulsive peaks and impulses, the loading rate (20-80 % of the first peak).</p>\n"
       "<table><tr><th class=l>foot</th><th class=l>plate</th><th class=l>from</th>"
    << kStanceParameterHeads << "</tr>\n";
  for (const auto& s : j["per_foot"]) {
    if (!s.contains("parameters")) continue;
    for (const char* from : {"estimated", "measured"})
      t << "<tr><td class=l>" << s["foot"].get<std::string>() << "</td><td class=l>" << html_escape(s["plate"].get<std::string>())
        << "</td><td class=l>" << (std::string(from) == "estimated" ? "kin2grf" : "plate") << "</td>"
        << stance_parameter_cells(s["parameters"][from]) << "</tr>\n";
  }
  t << "</table>\n";
  if (v.measured_joint_torque_Nm.size() != 0) {
    t << "<h3>Joint torques</h3>\n<p>The sagittal hip, knee and ankle torques, kin2grf's (the least squares' joint "
         "torques, the CSV's) against the torques a lab's inverse dynamics takes from the plate (bottom-up from the foot's "
         "plate on kin2grf's own motion), and beside them the same bottom-up from kin2grf's forces: rRMSE %, RMSE N m. A "
         "plate that fails the registration check is not compared (its torques take its COP as their lever).</p>\n"
         "<table><tr><th class=l>foot</th><th class=l>plate</th><th>hip rRMSE %</th><th>knee rRMSE %</th><th>ankle rRMSE %</th>"
         "<th>hip RMSE N m</th><th>knee RMSE N m</th><th>ankle RMSE N m</th><th>bottom-up from kin2grf's forces: hip / knee / ankle rRMSE %</th></tr>\n";
    for (const auto& s : j["per_foot"]) {
      if (!s.contains("joint_torques")) continue;
      const auto& jt = s["joint_torques"];
      const auto cell = [&](const char* joint, const char* from, const char* key) {
        return jt[joint][from].is_null() ? std::string("-") : fmt(jt[joint][from][key]);
      };
      t << "<tr><td class=l>" << s["foot"].get<std::string>() << "</td><td class=l>" << html_escape(s["plate"].get<std::string>()) << "</td>";
      for (const char* k : {"rrmse_percent", "rmse_Nm"})
        for (const char* joint : kReportJoints) t << "<td>" << cell(joint, "least_squares", k) << "</td>";
      t << "<td>" << cell("hip", "bottom_up", "rrmse_percent") << " / " << cell("knee", "bottom_up", "rrmse_percent") << " / "
        << cell("ankle", "bottom_up", "rrmse_percent") << "</td></tr>\n";
    }
    t << "</table>\n";
  }
  if (!v.excluded.empty() || !v.notes.empty()) {
    t << "<h3>Excluded and notes</h3><ul>\n";
    for (const auto& x : v.excluded) t << "<li>excluded: " << html_escape(x) << "</li>\n";
    for (const auto& x : v.notes) t << "<li>note: " << html_escape(x) << "</li>\n";
    t << "</ul>\n";
  }
  if (e.legs_3d) {
    t << "<h3>3D model</h3>\n<p>Mediolateral force and the COP's lateral place against the plates; the external knee "
         "adduction moment (KAM) by inverse dynamics with kin2grf's GRF against with the plates' GRF, on the same "
         "kinematics: rRMSE, its first and second peaks (largest value in each half of the stance) and its impulse (the "
         "time integral of its positive part over the stance). In brackets: "
         "a plate that fails the registration check (its moments take its COP as their lever).</p>\n"
         "<table><tr><th class=l>foot</th><th class=l>plate</th><th>lateral rRMSE %</th><th>lateral RMSE N</th>"
         "<th>lateral COP RMSE mm</th><th>KAM rRMSE %</th><th>KAM peaks, kin2grf N m</th><th>KAM peaks, plates N m</th>"
         "<th>KAM impulse, kin2grf / plates N m s</th>"
         "<th>knee sagittal rRMSE %</th><th>plate's free moment RMS N m (the estimate's is zero)</th></tr>\n";
    for (const auto& s : j["per_foot"]) {
      const nlohmann::json none;
      const auto& jm = s.contains("joint_moments_3d") ? s["joint_moments_3d"] : none;
      const auto& kam = jm.is_null() ? none : jm["knee_adduction_moment"];
      const auto peaks = [&](const char* key) {
        if (kam.is_null()) return std::string("-");
        return bracket_if_misregistered(s, fmt(kam[key][0], "%.0f") + " / " + fmt(kam[key][1], "%.0f"));
      };
      const auto impulse = [&]() {
        if (kam.is_null()) return std::string("-");
        return bracket_if_misregistered(s, fmt(kam.value("impulse_estimated_Nm_s", nlohmann::json()), "%.1f") + " / " +
                                               fmt(kam.value("impulse_measured_Nm_s", nlohmann::json()), "%.1f"));
      };
      t << "<tr><td class=l>" << s["foot"].get<std::string>() << "</td><td class=l>" << html_escape(s["plate"].get<std::string>())
        << "</td><td>" << fmt(s["rrmse_percent"].value("lateral", nlohmann::json())) << "</td><td>"
        << fmt(s["rmse"].value("lateral_N", nlohmann::json())) << "</td><td>"
        << fmt_cop(s, s["rmse"].value("cop_lateral_mm", nlohmann::json()), "%.0f") << "</td><td>"
        << fmt_cop(s, kam.is_null() ? none : kam["rrmse_percent"]) << "</td><td>" << peaks("peaks_estimated_Nm") << "</td><td>"
        << peaks("peaks_measured_Nm") << "</td><td>" << impulse() << "</td><td>"
        << fmt_cop(s, jm.is_null() ? none : jm["knee"]["sagittal"]["rrmse_percent"])
        << "</td><td>" << fmt_cop(s, s["rmse"].value("free_moment_Nm", nlohmann::json())) << "</td></tr>\n";
    }
    t << "</table>\n";
    // The totals' frontal and transverse moments (validate_total_3d), about the GRM reference on
    // the walker's midline, where every loaded foot stands on a plate.
    if (const auto& total = j.value("total", nlohmann::json()); total.is_object() && total.contains("frontal_moment")) {
      const auto& fm = total["frontal_moment"];
      const auto& tm = total["transverse_moment"];
      t << "<p>The total ground reaction's moments about the GRM reference on the walker's midline, where every loaded "
           "foot stands on a plate (the plates' free moments in theirs): frontal rRMSE "
        << fmt(fm.value("rrmse_percent", nlohmann::json())) << " % (RMSE " << fmt(fm.value("rmse_Nm", nlohmann::json())) << " N m, r "
        << fmt(fm.value("r", nlohmann::json()), "%.2f") << "), transverse rRMSE " << fmt(tm.value("rrmse_percent", nlohmann::json()))
        << " % (RMSE " << fmt(tm.value("rmse_Nm", nlohmann::json())) << " N m, r " << fmt(tm.value("r", nlohmann::json()), "%.2f")
        << ").</p>\n";
    }
    // Every joint in every plane (issue 28: "what the estimate does to the hip, knee and ankle
    // moments in all three planes").
    t << "<p>The hip's, the knee's and the ankle's internal moments in the three planes, estimate-driven against "
         "plate-driven: rRMSE % (r).</p>\n<table><tr><th class=l>foot</th><th class=l>plate</th>";
    for (const char* joint : kReportJoints)
      for (const char* plane : kPlaneNames) t << "<th>" << joint << " " << plane << "</th>";
    t << "</tr>\n";
    for (const auto& s : j["per_foot"]) {
      if (!s.contains("joint_moments_3d") || s["joint_moments_3d"].is_null()) continue;
      t << "<tr><td class=l>" << s["foot"].get<std::string>() << "</td><td class=l>" << html_escape(s["plate"].get<std::string>()) << "</td>";
      for (const char* joint : kReportJoints)
        for (const char* plane : kPlaneNames) {
          const auto& m = s["joint_moments_3d"][joint][plane];
          if (m.is_null()) {
            t << "<td>-</td>";
            continue;
          }
          t << "<td>" << fmt_cop(s, m["rrmse_percent"]) << " (" << fmt(m["r"], "%.2f") << ")</td>";
        }
      t << "</tr>\n";
    }
    t << "</table>\n";
  }
  rep.sections_html.push_back(t.str());

  const std::vector<double> time = to_vec(e.time_s);
  for (int f = 0; f < 2; ++f) {
    const std::string foot = side_name(f);
    std::vector<std::pair<double, double>> shaded;
    for (const auto* list : {&v.stances, &v.cut_stances})
      for (const auto& s : *list)
        if (s.foot == f) shaded.emplace_back(e.time_s[s.first], e.time_s[s.last]);
    const auto& fe = e.feet[static_cast<std::size_t>(f)];
    const auto& mf = v.measured_force_N[static_cast<std::size_t>(f)];
    auto fig = [&](const std::string& what, const std::string& unit, const Eigen::VectorXd& est, const Eigen::VectorXd& meas) {
      ReportFigure g;
      g.title = foot + " foot: " + what + " (shaded: plate stances compared)";
      g.x_label = "time (s)";
      g.y_label = unit;
      g.shaded = shaded;
      g.series.push_back({"force plate", time, to_vec(meas), true});
      g.series.push_back({"kin2grf estimate", time, to_vec(est), false});
      rep.figures.push_back(g);
    };
    fig("vertical GRF", "N", fe.force_N.col(1), mf.col(1));
    fig("anterior GRF", "N", fe.force_N.col(0), mf.col(0));
    fig("COP along progression", "m", fe.cop_x_m, v.measured_cop_x_m[static_cast<std::size_t>(f)]);
    const auto k = static_cast<std::size_t>(f);
    if (fe.force_lateral_N.size() == e.time_s.size() && v.measured_lateral_N[k].size() == e.time_s.size()) {
      fig("mediolateral GRF (+ towards the walker's right)", "N", fe.force_lateral_N, v.measured_lateral_N[k]);
      fig("COP's lateral place (+ towards the walker's right)", "m",
          fe.cop_lateral_m.size() == e.time_s.size() ? fe.cop_lateral_m : e.foot_lateral_m[k], v.measured_cop_lateral_m[k]);
    }
    if (v.measured_joint_torque_Nm.rows() == e.time_s.size())
      for (int c = 0; c < 3; ++c) {
        const int joint = 4 * f + c;
        ReportFigure g;
        g.title = foot + " " + kReportJoints[c] + ": sagittal joint torque (on the distal segment, + counter-clockwise), kin2grf's "
                  "and the plates' inverse dynamics";
        g.x_label = "time (s)";
        g.y_label = "N m";
        g.shaded = shaded;
        g.series.push_back({"plates, bottom-up", time, to_vec(v.measured_joint_torque_Nm.col(joint)), true});
        g.series.push_back({"kin2grf", time, to_vec(e.joint_torque_Nm.col(joint)), false});
        rep.figures.push_back(g);
      }
    if (e.legs_3d && v.measured_moments_3d) {
      // Plate-driven only where a plate stance is compared (zero ground reaction elsewhere).
      Eigen::VectorXd plate = Eigen::VectorXd::Constant(e.time_s.size(), std::numeric_limits<double>::quiet_NaN());
      const Eigen::VectorXd kam = knee_adduction_moment(*v.measured_moments_3d, f);
      for (const auto& s : v.stances)
        if (s.foot == f) plate.segment(s.first, s.last - s.first + 1) = kam.segment(s.first, s.last - s.first + 1);
      ReportFigure g;
      g.title = foot + " knee: external knee adduction moment, estimate-driven and plate-driven inverse dynamics";
      g.x_label = "time (s)";
      g.y_label = "N m";
      g.shaded = shaded;
      g.series.push_back({"with the plates' GRF", time, to_vec(plate), true});
      g.series.push_back({"with kin2grf's GRF", time, to_vec(knee_adduction_moment(e.legs_3d->moments, f)), false});
      rep.figures.push_back(g);
    }
  }
  if (!v.stances.empty()) {
    // Time-normalised (validate --stance-curves): the scored stances' mean at each per cent of the
    // plate's stance, kin2grf's beside the plates', as papers draw them.
    const ResultsTable c = validation_stance_curves_table(e, v);
    const Eigen::Index stances = c.values.rows() / kCurvePoints;
    const std::vector<double> percent = curve_column(c, "percent", 0);
    const std::string of = " (mean of the " + std::to_string(stances) + " plate stance" + (stances == 1 ? "" : "s") + " compared)";
    std::vector<std::tuple<std::string, std::string, std::string>> figures = {
        {"vertical GRF", "body weights", "vertical_bw"},
        {"anterior GRF", "body weights", "anterior_bw"},
        {"COP along progression from the plate's first COP", "m", "cop_progression_m"}};
    if (std::find(c.columns.begin(), c.columns.end(), "knee_adduction_moment_Nm_per_kg_plate") != c.columns.end()) {
      figures.emplace_back("external knee adduction moment, with each ground reaction", "N m/kg", "knee_adduction_moment_Nm_per_kg");
      for (const auto& [title, key] : joint_moment_curves()) figures.emplace_back(title + ", with each ground reaction", "N m/kg", key);
    }
    for (const auto& [what, unit, key] : figures) {
      ReportFigure g;
      g.title = what + ", per cent of the plate's stance" + of;
      g.x_label = "% of stance";
      g.y_label = unit;
      g.series.push_back({"force plates", percent, mean_curve(c, key + "_plate", -1), true});
      g.series.push_back({"kin2grf estimate", percent, mean_curve(c, key + "_estimate", -1), false});
      rep.figures.push_back(g);
    }
  }
  if (v.total) {
    ReportFigure g;
    g.title = "total vertical GRF (frames where every loaded foot is on a plate)";
    g.x_label = "time (s)";
    g.y_label = "N";
    g.series.push_back({"force plates", time, to_vec(v.total->vertical_measured_N), true});
    g.series.push_back({"kin2grf estimate", time, to_vec(v.total->vertical_estimated_N), false});
    rep.figures.push_back(g);
    if (v.total->frontal_estimated_Nm.size() == e.time_s.size()) {
      for (const auto& [what, est, meas] :
           {std::tuple{"total frontal moment, about the forward axis through the GRM reference on the walker's midline",
                       &v.total->frontal_estimated_Nm, &v.total->frontal_measured_Nm},
            {"total transverse moment, about the vertical through the GRM reference on the walker's midline (the plates' free "
             "moments in theirs)",
             &v.total->transverse_estimated_Nm, &v.total->transverse_measured_Nm}}) {
        ReportFigure g3;
        g3.title = what;
        g3.x_label = "time (s)";
        g3.y_label = "N m";
        g3.series.push_back({"force plates", time, to_vec(*meas), true});
        g3.series.push_back({"kin2grf estimate", time, to_vec(*est), false});
        rep.figures.push_back(g3);
      }
    }
    ReportFigure m;
    char b[96];
    std::snprintf(b, sizeof b, "sagittal GRM about x = %.3f m, y = %.3f m", v.total->grm_reference_m.x(), v.total->grm_reference_m.y());
    m.title = b;
    m.x_label = "time (s)";
    m.y_label = "N m";
    m.series.push_back({"force plates", time, to_vec(v.total->grm_measured_Nm), true});
    m.series.push_back({"kin2grf estimate", time, to_vec(v.total->grm_estimated_Nm), false});
    rep.figures.push_back(m);
  }
  rep.sections_html.push_back("<h2>Settings</h2><pre>" + html_escape(j["settings"].dump(2)) + "</pre>");
  return render_report_html(rep);
}

std::string estimate_report_html(const std::string& trial, const EstimateResult& e, const nlohmann::json& j) {
  Report rep;
  rep.title = "kin2grf estimate: " + trial;
  std::ostringstream t;
  t << "<h2>Estimate</h2>\n<p>Ground reaction forces, centre of pressure and joint torques from the markers alone "
       "(no plates compared). Body mass " << fmt(j["mass_kg"]) << " kg, marker set " << html_escape(j["marker_set"].get<std::string>())
    << ", frames " << j["frames"]["first"] << "-" << j["frames"]["last"] << ", progression speed "
    << fmt(j["progression"]["speed_mps"], "%.2f") << " m/s. Shaded: each foot's stances.</p>\n";
  t << "<h3>Gait events</h3>\n<table><tr><th class=l>side</th><th class=l>event</th><th>frame</th><th>time s</th></tr>\n";
  for (const auto& ev : j["gait_events"])
    t << "<tr><td class=l>" << ev["side"].get<std::string>() << "</td><td class=l>" << ev["event"].get<std::string>() << "</td><td>"
      << ev["frame"] << "</td><td>" << fmt(ev["time_s"], "%.3f") << "</td></tr>\n";
  t << "</table>\n";
  if (j.contains("stance_parameters")) {
    t << "<h3>Stance parameters</h3>\n<p>Per stance (foot strike to foot off; * a stance the processed window cuts): the "
         "vertical force's largest value in each half of the stance and the least between them, the braking and propulsive "
         "peaks and impulses, the loading rate (20-80 % of the first peak).</p>\n"
         "<table><tr><th class=l>side</th><th>start s</th><th>duration s</th>"
      << kStanceParameterHeads << "</tr>\n";
    for (int f = 0; f < 2; ++f)
      for (const auto& p : j["stance_parameters"].value(side_name(f), nlohmann::json::array()))
        t << "<tr><td class=l>" << side_name(f) << (p.value("complete", true) ? "" : " *") << "</td><td>"
          << fmt(p["start_s"], "%.3f") << "</td><td>" << fmt(p["duration_s"], "%.3f") << "</td>" << stance_parameter_cells(p) << "</tr>\n";
    t << "</table>\n";
  }
  if (!e.messages.empty()) {
    t << "<h3>Messages</h3><ul>\n";
    for (const auto& m : e.messages) t << "<li>" << html_escape(m) << "</li>\n";
    t << "</ul>\n";
  }
  rep.sections_html.push_back(t.str());
  const std::vector<double> time = to_vec(e.time_s);
  std::array<std::vector<std::pair<double, double>>, 2> stances;
  for (int f = 0; f < 2; ++f) {
    const auto& c = e.feet[static_cast<std::size_t>(f)].contact;
    for (const IndexRun& run : runs_where(static_cast<Eigen::Index>(c.size()), [&](Eigen::Index i) { return c[static_cast<std::size_t>(i)]; }))
      stances[static_cast<std::size_t>(f)].emplace_back(e.time_s[run.first], e.time_s[run.last]);
  }
  const auto figure = [&](const std::string& title, const std::string& unit, int foot, std::vector<ReportSeries> series) {
    ReportFigure g;
    g.title = title;
    g.x_label = "time (s)";
    g.y_label = unit;
    if (foot >= 0) g.shaded = stances[static_cast<std::size_t>(foot)];
    g.series = std::move(series);
    rep.figures.push_back(std::move(g));
  };
  const Eigen::MatrixXd omega = joint_angular_velocity_series(e.motion);  // for the powers
  for (int f = 0; f < 2; ++f) {
    const std::string foot = side_name(f);
    const auto& fe = e.feet[static_cast<std::size_t>(f)];
    figure(foot + " foot: vertical GRF", "N", f, {{"kin2grf estimate", time, to_vec(fe.force_N.col(1)), false}});
    figure(foot + " foot: anterior GRF", "N", f, {{"kin2grf estimate", time, to_vec(fe.force_N.col(0)), false}});
    figure(foot + " foot: COP along progression", "m", f, {{"kin2grf estimate", time, to_vec(fe.cop_x_m), false}});
    // Hip, knee, ankle of this side (joint_torque_Nm: per side hip, knee, ankle, MTP); the powers,
    // each torque times its joint's angular velocity (+ generation, - absorption).
    std::vector<ReportSeries> torques, powers;
    for (int k = 0; k < 3; ++k) {
      const int joint = 4 * f + k;
      torques.push_back({kReportJoints[k], time, to_vec(e.joint_torque_Nm.col(joint)), false});
      powers.push_back({kReportJoints[k], time, to_vec(e.joint_torque_Nm.col(joint).cwiseProduct(omega.col(joint))), false});
    }
    figure(foot + " leg: joint torques", "N m", f, std::move(torques));
    figure(foot + " leg: joint powers (+ generation, - absorption)", "W", f, std::move(powers));
  }
  if (e.grm_Nm.size() == e.time_s.size()) {
    char b[96];
    std::snprintf(b, sizeof b, "sagittal GRM about x = %.3f m, y = %.3f m", e.grm_reference_m.x(), e.grm_reference_m.y());
    figure(b, "N m", -1, {{"kin2grf estimate", time, to_vec(e.grm_Nm), false}});
  }
  // Time-normalised (estimate --stance-curves): each side's complete stances' mean at each per
  // cent of the stance, in body weights and N m per kg, as a gait report draws them.
  const ResultsTable c = stance_curves_table(e);
  if (c.values.rows() > 0) {
    const std::vector<double> percent = curve_column(c, "percent", 0);
    std::array<int, 2> count{0, 0};
    for (Eigen::Index st = 0; st < c.values.rows() / kCurvePoints; ++st)
      ++count[static_cast<std::size_t>(c.values(st * kCurvePoints, curve_column_index(c, "side")))];
    const std::string of = " (mean of " + std::to_string(count[0]) + " right and " + std::to_string(count[1]) + " left complete stances)";
    std::vector<std::tuple<std::string, std::string, std::string>> curves = {
        {"vertical GRF", "body weights", "grf_vertical_bw"},
        {"anterior GRF", "body weights", "grf_anterior_bw"},
        {"hip torque", "N m/kg", "torque_hip_Nm_per_kg"},
        {"knee torque", "N m/kg", "torque_knee_Nm_per_kg"},
        {"ankle torque", "N m/kg", "torque_ankle_Nm_per_kg"},
        {"external knee adduction moment", "N m/kg", "knee_adduction_moment_Nm_per_kg"}};
    for (const auto& [title, key] : joint_moment_curves()) curves.emplace_back(title, "N m/kg", key);  // --model 3d
    for (const auto& [what, unit, key] : curves) {
      if (std::find(c.columns.begin(), c.columns.end(), key) == c.columns.end()) continue;  // the KAM and the 3D moments: --model 3d
      ReportFigure g;
      g.title = std::string(what) + ", per cent of stance" + of;
      g.x_label = "% of stance";
      g.y_label = unit;
      for (int side = 0; side < 2; ++side)
        if (count[static_cast<std::size_t>(side)] > 0) g.series.push_back({side_name(side), percent, mean_curve(c, key, side), false});
      rep.figures.push_back(std::move(g));
    }
  }
  rep.sections_html.push_back("<h2>Settings</h2><pre>" + html_escape(j["settings"].dump(2)) + "</pre>");
  return render_report_html(rep);
}

std::string study_report_html(const StudyResult& s) {
  Report rep;
  rep.title = "kin2grf study: " + s.kind;
  rep.sections_html.push_back("<pre>" + html_escape(format_study_table(s)) + "</pre>");
  if (!s.rows.empty()) {
    const bool numeric = s.kind != "foot-model";
    for (std::size_t a = 0; a < s.rows.front().cells.size(); ++a) {
      ReportFigure g;
      g.title = s.rows.front().cells[a].activity + ": mean rRMSE against " + s.kind;
      g.x_label = numeric ? s.kind : "foot model (1 = three points, 2 = moving COP)";
      g.y_label = "rRMSE (%)";
      g.log_x = s.kind == "r";
      const std::array<std::string, 5> names = {"vertical", "anterior", "COP", "moment (plate centre)", "total GRM"};
      for (std::size_t k = 0; k < names.size(); ++k) {
        ReportSeries series;
        series.label = names[k];
        for (const auto& r : s.rows) {
          const auto& c = r.cells[a];
          const std::array<double, 5> val = {c.per_foot.vertical, c.per_foot.anterior, c.per_foot.cop, c.per_foot.moment, c.total_grm};
          series.x.push_back(s.kind == "ground-shift" ? 1000 * r.value : r.value);
          series.y.push_back(val[k]);
        }
        g.series.push_back(series);
      }
      rep.figures.push_back(g);
    }
  }
  return render_report_html(rep);
}

}  // namespace kin2grf
