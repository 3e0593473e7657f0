// kin2grf outputs: self-contained HTML reports with plots.
//
// One HTML file that a browser opens without network: the data as JSON, Chart.js (Debian's
// libjs-chart.js, embedded at build time) and a few lines of script that draw one chart per
// figure, contact phases shaded. When every chart is drawn, the script sets
// <body data-charts-rendered="N">; the tests read that attribute from headless Chromium.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "kin2grf/pipeline.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"

namespace kin2grf {

struct ReportSeries {
  std::string label;
  std::vector<double> x, y;  ///< NaN y values leave a gap
  bool measured = false;     ///< drawn as the reference (solid black)
};

struct ReportFigure {
  std::string title, x_label, y_label;
  std::vector<ReportSeries> series;
  std::vector<std::pair<double, double>> shaded;  ///< x intervals (contact phases)
  bool log_x = false;
};

struct Report {
  std::string title;
  std::vector<std::string> sections_html;  ///< trusted HTML built by kin2grf (tables)
  std::vector<ReportFigure> figures;
};

/// The embedded Chart.js source (generated at build time).
const std::string& chartjs_source();

std::string render_report_html(const Report& report);

/// HTML-escape text for the report.
std::string html_escape(const std::string& s);

/// validate's report: per foot and in total, estimate against plates over time, the metrics
/// table, exclusions and the settings.
std::string validation_report_html(const std::string& trial, const EstimateResult& e, const ValidationResult& v,
                                   const nlohmann::json& validation);

/// estimate's report, without plates: per foot the vertical and anterior GRF and the COP, the
/// sagittal GRM (where the result holds it) and the joint torques over time, each foot's stances
/// shaded; the gait events, the messages and the settings (`summary`: results_summary's JSON).
std::string estimate_report_html(const std::string& trial, const EstimateResult& r, const nlohmann::json& summary);

/// study's report: per activity, mean rRMSE of each component against the setting.
std::string study_report_html(const StudyResult& study);

}  // namespace kin2grf
