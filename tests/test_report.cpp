// Tests of output/report: the HTML reports.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>

#include "kin2grf/error.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/cop_fit.hpp"
#include "kin2grf/validation/metrics.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"
#include "test_support.hpp"

using namespace kin2grf;
using kin2grf::test::synthetic_with_exact_plates;

namespace {
/// The first Chromium found, or "" (the tests that need one skip without it).
std::string chromium() {
  for (const char* c : {"/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"})
    if (std::filesystem::exists(c)) return c;
  return "";
}
/// The DOM that headless `browser` makes of the HTML file `html` (a profile folder in `dir`).
std::string rendered_dom(const std::string& browser, const std::filesystem::path& dir, const std::filesystem::path& html) {
  const std::string cmd = browser + " --headless --no-sandbox --disable-gpu --user-data-dir=" + (dir / "profile").string() +
                          " --dump-dom file://" + html.string() + " 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string dom;
  if (!pipe) return dom;
  char buf[4096];
  while (std::size_t k = std::fread(buf, 1, sizeof buf, pipe.get())) dom.append(buf, k);
  return dom;
}
}  // namespace

TEST(Report, RendersInHeadlessChromium) {
  const auto s = synthetic_with_exact_plates();
  const auto v = validate(s.estimate, s.plates);
  const auto j = validation_json("synthetic", s.estimate, v, nlohmann::json::object());
  // The total row gives the GRM's RMSE in N m beside its rRMSE.
  ASSERT_TRUE(v.total && v.total->metrics.moment);
  const std::string page = validation_report_html("synthetic", s.estimate, v, j);
  const auto total = page.find("<td class=l>total</td>");
  ASSERT_NE(total, std::string::npos);
  EXPECT_NE(page.substr(total, page.find("</tr>", total) - total).find(" N m)</td>"), std::string::npos);
  const std::string browser = chromium();
  if (browser.empty()) GTEST_SKIP() << "no Chromium found (scripts/setup.sh installs Debian's chromium)";
  const auto dir = test::temp_dir("report");
  const auto html = dir / "report.html";
  write_file_text(html.string(), validation_report_html("synthetic", s.estimate, v, j));
  const std::string dom = rendered_dom(browser, dir, html);
  ASSERT_FALSE(dom.empty());
  // 3 figures per foot (GRF, COP), 3 per foot of joint torques, 3 time-normalised (the stances'
  // mean, per cent of stance) and 2 totals, each drawn by Chart.js (the script sets the attribute
  // only after every chart was constructed).
  ASSERT_EQ(v.measured_joint_torque_Nm.rows(), s.estimate.time_s.size());
  ASSERT_FALSE(v.stances.empty());
  EXPECT_NE(dom.find("data-charts-rendered=\"17\""), std::string::npos) << dom.substr(0, 400);
  EXPECT_NE(page.find("per cent of the plate's stance (mean of the "), std::string::npos);
  const auto p = dom.find("data-points=\"");
  ASSERT_NE(p, std::string::npos);
  EXPECT_GT(std::stoi(dom.substr(p + 13)), 1000);
}

// The marker-plate time offset (validate's step 6) in the report as in the text and the JSON
// (issue 29: "report it with its confidence, in the text, the JSON and the report"): plates 30 ms
// late read -30 ms, compared as recorded unless --sync aligns them, which the report says.
TEST(Report, TheMarkerPlateOffsetIsReportedWithItsUncertaintyAndTheShiftApplied) {
  auto s = synthetic_with_exact_plates();
  s.plates.time_s.array() += 0.03;
  const auto page = [&](const ValidationOptions& o) {
    const ValidationResult v = validate(s.estimate, s.plates, o);
    EXPECT_TRUE(v.sync.has_value());
    const std::string html = validation_report_html("synthetic", s.estimate, v, validation_json("synthetic", s.estimate, v, nlohmann::json::object()));
    const auto p = html.find("<p>Marker-plate time offset: ");
    EXPECT_NE(p, std::string::npos);
    return p == std::string::npos ? std::string() : html.substr(p, html.find("</p>", p) - p);
  };
  const std::string recorded = page({});
  EXPECT_TRUE(recorded.find("offset: -30 ms (&plusmn;") != std::string::npos || recorded.find("offset: -29 ms (&plusmn;") != std::string::npos ||
              recorded.find("offset: -31 ms (&plusmn;") != std::string::npos)
      << recorded;
  EXPECT_NE(recorded.find("+ = the plates lead"), std::string::npos) << recorded;
  EXPECT_NE(recorded.find("compare the plates as recorded"), std::string::npos) << recorded;
  ValidationOptions fixed;
  fixed.sync = ValidationOptions::Sync::Fixed;
  fixed.plate_shift_s = -0.03;
  EXPECT_NE(page(fixed).find("compare the plates shifted by -30 ms"), std::string::npos) << page(fixed);
}

// estimate's report without plates (issue 30, item 8): per foot GRF, COP, joint torques and powers, the
// GRM, the gait events in a table; drawn by Chart.js in headless Chromium.
TEST(Report, AnEstimateReportWithoutPlatesRendersWithItsGaitEvents) {
  const std::string browser = chromium();
  const SyntheticWalk w = make_synthetic_walk({});
  const EstimateResult e = estimate(w.trial, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  const auto events = gait_events({e.feet[0].contact, e.feet[1].contact}, e.time_s, e.motion.rate_hz);
  ASSERT_FALSE(events.empty());
  nlohmann::json j = {{"mass_kg", e.mass_kg}, {"marker_set", e.marker_set}, {"frames", {{"first", 1}, {"last", e.time_s.size()}}},
                      {"progression", {{"speed_mps", 1.0}}}, {"settings", nlohmann::json::object()}, {"gait_events", nlohmann::json::array()}};
  for (const auto& ev : events)
    j["gait_events"].push_back({{"event", ev.label}, {"side", ev.side ? "left" : "right"}, {"frame", ev.index + 1}, {"time_s", ev.time_s}});
  const std::string html = estimate_report_html("synthetic", e, j);
  EXPECT_NE(html.find("Foot Strike"), std::string::npos);
  if (browser.empty()) GTEST_SKIP() << "no Chromium found (scripts/setup.sh installs Debian's chromium)";
  const auto dir = test::temp_dir("estimate-report");
  const auto file = dir / "report.html";
  write_file_text(file.string(), html);
  const std::string dom = rendered_dom(browser, dir, file);
  ASSERT_FALSE(dom.empty());
  // 5 figures per foot (vertical, anterior, COP, joint torques, joint powers), the GRM, and 5
  // time-normalised (the vertical and anterior GRF, the hip, knee and ankle torques: each side's
  // complete stances' mean at each per cent of the stance).
  ASSERT_GT(stance_curves_table(e).values.rows(), 0);
  EXPECT_NE(dom.find("data-charts-rendered=\"16\""), std::string::npos) << dom.substr(0, 400);
  EXPECT_NE(html.find("right leg: joint powers"), std::string::npos);
  EXPECT_NE(html.find("knee torque, per cent of stance (mean of "), std::string::npos);
}

// The 3D model's validation report (issue 28: "the HTML report plots them"): per foot the
// mediolateral force, the COP's lateral place and the knee adduction moment, estimate-driven
// against plate-driven, and a table of the 3D figures; and the total's frontal moment.
TEST(Report, TheThreeDReportPlotsTheLateralForceAndTheKneeAdductionMoment) {
  const Trial walk = load_trial(std::string(KIN2GRF_SOURCE_DIR) + "/data/example/walking2.c3d");
  ASSERT_TRUE(walk.plates.has_value());
  EstimateOptions o;
  o.mass_kg = 64.9;
  o.model = ModelKind::ThreeD;
  const EstimateResult e = estimate(walk, nullptr, *recognise_marker_set(walk.markers), o);
  const ValidationResult v = validate(e, *walk.plates);
  ASSERT_FALSE(v.stances.empty());
  const std::string html = validation_report_html("walking2", e, v, validation_json("walking2", e, v, nlohmann::json::object()));
  const auto count = [&](const std::string& what) {
    int k = 0;
    for (auto p = html.find(what); p != std::string::npos; p = html.find(what, p + 1)) ++k;
    return k;
  };
  EXPECT_EQ(count("foot: mediolateral GRF"), 2);
  EXPECT_EQ(count("foot: COP's lateral place"), 2);
  EXPECT_EQ(count("knee: external knee adduction moment"), 2);
  EXPECT_EQ(count("<h3>3D model</h3>"), 1);
  // Time-normalised, the KAM with each ground reaction (validate --stance-curves): at the plate
  // stance's first frame the estimate-driven and the plate-driven moments per kg.
  EXPECT_EQ(count("external knee adduction moment, with each ground reaction, per cent of the plate's stance"), 1);
  const ResultsTable curves = validation_stance_curves_table(e, v);
  const auto column = [&](const std::string& name) {
    const auto it = std::find(curves.columns.begin(), curves.columns.end(), name);
    EXPECT_NE(it, curves.columns.end()) << name;
    return static_cast<Eigen::Index>(it - curves.columns.begin());
  };
  ASSERT_TRUE(v.measured_moments_3d.has_value());
  const StanceValidation& st = v.stances.front();
  EXPECT_NEAR(curves.values(0, column("knee_adduction_moment_Nm_per_kg_estimate")),
              knee_adduction_moment(e.legs_3d->moments, st.foot, st.first) / e.mass_kg, 1e-12);
  if (!st.cop_reference_suspect) {
    EXPECT_NEAR(curves.values(0, column("knee_adduction_moment_Nm_per_kg_plate")),
                knee_adduction_moment(*v.measured_moments_3d, st.foot, st.first) / e.mass_kg, 1e-12);
  }
  // Every joint in every plane: a table of their rRMSE and a time-normalised figure each, the
  // curves at the stance's first frame the moments of each inverse dynamics per kg.
  EXPECT_EQ(count("internal moments in the three planes, estimate-driven against plate-driven"), 1);
  EXPECT_EQ(count(" moment (internal, + "), 9);
  EXPECT_EQ(count("hip frontal moment (internal, + adducts the distal segment), with each ground reaction, per cent of the plate's stance"), 1);
  for (int joint = 0; joint < 3; ++joint)
    for (int a = 0; a < 3; ++a) {
      const std::string name = std::string(kJoint3DNames[joint]) + "_" + kPlaneNames[a] + "_Nm_per_kg";
      EXPECT_NEAR(curves.values(0, column(name + "_estimate")), joint_moments_of(e.legs_3d->moments, joint, st.foot)(st.first, a) / e.mass_kg,
                  1e-12);
      if (!st.cop_reference_suspect) {
        EXPECT_NEAR(curves.values(0, column(name + "_plate")), joint_moments_of(*v.measured_moments_3d, joint, st.foot)(st.first, a) / e.mass_kg,
                    1e-12);
      }
    }
  // The estimate's report likewise draws each side's mean curve of every joint's moment in every plane.
  const std::string estimate_html = estimate_report_html("walking2", e, results_summary(e, nlohmann::json::object()));
  int moment_curves = 0;
  for (auto p = estimate_html.find(" moment (internal, + "); p != std::string::npos; p = estimate_html.find(" moment (internal, + ", p + 1))
    ++moment_curves;
  EXPECT_EQ(moment_curves, 9);
  EXPECT_NE(estimate_html.find("knee transverse moment (internal, + rotates the distal segment internally), per cent of stance"),
            std::string::npos);
  // The sagittal model's report has none of it.
  EstimateOptions sagittal;
  sagittal.mass_kg = 64.9;
  const EstimateResult e2 = estimate(walk, nullptr, *recognise_marker_set(walk.markers), sagittal);
  const ValidationResult v2 = validate(e2, *walk.plates);
  const std::string html2 = validation_report_html("walking2", e2, v2, validation_json("walking2", e2, v2, nlohmann::json::object()));
  EXPECT_EQ(html2.find("mediolateral GRF"), std::string::npos);
  EXPECT_EQ(html2.find("<h3>3D model</h3>"), std::string::npos);
  // The total's frontal and transverse moments (validate_total_3d): with the lateral force only.
  // The frontal one is mostly each foot's vertical force times its lateral place, which the
  // estimate has: a sign or frame error would show as a low or negative r.
  ASSERT_TRUE(v.total && v2.total);
  ASSERT_TRUE(v.total->frontal_moment && v.total->transverse_moment);
  EXPECT_GT(v.total->frontal_moment->pearson_r, 0.9);
  EXPECT_GT(v.total->transverse_moment->pearson_r, 0.5);
  EXPECT_FALSE(v2.total->frontal_moment.has_value());
  // Both tabulated and drawn in the report: their rRMSE in a sentence, their series over the total's
  // frames (NaN elsewhere) in a figure each; the sagittal report has neither.
  char sentence[96];
  std::snprintf(sentence, sizeof sentence, "frontal rRMSE %.1f %% (RMSE %.1f N m", v.total->frontal_moment->rrmse_percent, v.total->frontal_moment->rmse);
  EXPECT_EQ(count(sentence), 1) << sentence;
  EXPECT_EQ(count("total frontal moment, about the forward axis through the GRM reference"), 1);
  EXPECT_EQ(count("total transverse moment, about the vertical through the GRM reference"), 1);
  EXPECT_EQ(html2.find("total frontal moment"), std::string::npos);
  ASSERT_EQ(v.total->frontal_estimated_Nm.size(), e.time_s.size());
  EXPECT_EQ(static_cast<std::size_t>(v.total->frontal_estimated_Nm.array().isFinite().count()), v.total->frames.size());
  EXPECT_EQ(static_cast<std::size_t>(v.total->transverse_measured_Nm.array().isFinite().count()), v.total->frames.size());
  EXPECT_EQ(count("plate's free moment RMS N m (the estimate's is zero)"), 1);
  // The plate's free moment (the estimate's is zero): a few N m in walking. Leaving out the COP's
  // c x F would read the plate's whole moment about the origin, hundreds of N m.
  ASSERT_TRUE(v.stances[0].metrics.free_moment.has_value());
  EXPECT_GT(v.stances[0].metrics.free_moment->rmse, 0.5);
  EXPECT_LT(v.stances[0].metrics.free_moment->rmse, 15.0);
}

// The report brackets, as the text table does, the figures of a plate that fails the registration
// check (here FP1 registered 20 cm off under a 3D walk): its KAM cell in brackets, FP2's plain.
TEST(Report, AMisregisteredPlatesFiguresAreBracketed) {
  Trial t = make_example_walk(kin2grf::test::walk_3d_options());
  EstimateOptions eo;
  eo.model = ModelKind::ThreeD;
  eo.keep_all_series = true;
  const EstimateResult r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
  kin2grf::test::misregister_plate(t.plates->plates[0], 0.2);
  const ValidationResult v = validate(r, *t.plates);
  ASSERT_EQ(v.stances.size(), 2u);
  const std::string html = validation_report_html("walk", r, v, validation_json("walk", r, v, nlohmann::json::object()));
  for (const StanceValidation& s : v.stances) {
    ASSERT_TRUE(s.moments_3d && s.moments_3d->knee_adduction);
    char cell[40];
    std::snprintf(cell, sizeof cell, s.cop_reference_suspect ? "<td>[%.1f]</td>" : "<td>%.1f</td>",
                  s.moments_3d->knee_adduction->rrmse_percent);
    EXPECT_EQ(s.cop_reference_suspect, s.plate == "FP1");
    EXPECT_NE(html.find(cell), std::string::npos) << s.plate << ": " << cell;
    // The COP's RMSE in mm and in % of the foot's length (issue 29), bracketed likewise.
    ASSERT_TRUE(s.metrics.cop && s.foot_length_m > 0);
    char mm[80];
    std::snprintf(mm, sizeof mm, s.cop_reference_suspect ? "<td>[%.1f (%.1f %%)]</td>" : "<td>%.1f (%.1f %%)</td>", 1000 * s.metrics.cop->rmse,
                  100 * s.metrics.cop->rmse / s.foot_length_m);
    EXPECT_NE(html.find(mm), std::string::npos) << s.plate << ": " << mm;
  }
}

// Both reports tabulate the stance parameters: the estimate's a row per stance of its summary, the
// validation's a row for kin2grf and one for the plate per plate stance.
TEST(Report, StanceParametersAreTabulatedInBothReports) {
  const Trial walk = make_example_walk();
  const EstimateResult e = estimate(walk, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  const auto rows_of = [](const std::string& html) {
    const auto from = html.find("<h3>Stance parameters</h3>");
    if (from == std::string::npos) return -1;
    const std::string table = html.substr(from, html.find("</table>", from) - from);
    int n = 0;
    for (auto at = table.find("<tr><td"); at != std::string::npos; at = table.find("<tr><td", at + 1)) ++n;
    return n;
  };
  const nlohmann::json summary = results_summary(e, nlohmann::json::object());
  const int stances = static_cast<int>(summary["stance_parameters"]["right"].size() + summary["stance_parameters"]["left"].size());
  ASSERT_GE(stances, 4);
  EXPECT_EQ(rows_of(estimate_report_html("example", e, summary)), stances);
  const ValidationResult v = validate(e, *walk.plates);
  ASSERT_FALSE(v.stances.empty());
  const std::string html = validation_report_html("example", e, v, validation_json("example", e, v, nlohmann::json::object()));
  EXPECT_EQ(rows_of(html), 2 * static_cast<int>(v.stances.size()));
  EXPECT_NE(html.find("<td class=l>plate</td>"), std::string::npos);
  // The joint torques: a row per compared stance, and a figure per joint of each leg with one.
  const auto torques = html.find("<h3>Joint torques</h3>");
  ASSERT_NE(torques, std::string::npos);
  const std::string table = html.substr(torques, html.find("</table>", torques) - torques);
  int rows = 0;
  for (auto at = table.find("<tr><td"); at != std::string::npos; at = table.find("<tr><td", at + 1)) ++rows;
  EXPECT_EQ(rows, static_cast<int>(v.stances.size()));
  EXPECT_NE(html.find("right knee: sagittal joint torque"), std::string::npos);
  EXPECT_NE(html.find("left ankle: sagittal joint torque"), std::string::npos);
}
