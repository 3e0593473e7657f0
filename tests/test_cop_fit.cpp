// Tests of validation/cop_fit: the COP function fitted to plate COPs.
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
#include "kin2grf/io/text.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/cop_fit.hpp"
#include "kin2grf/validation/metrics.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"
#include "test_support.hpp"

using namespace kin2grf;

TEST(CopFit, RecoversTheEventPositionsOfNoiseFreeSamples) {
  CopFunction truth = CopFunction::paper();
  truth.s_hs = 0.1, truth.s_ho = 0.35, truth.s_mo = 0.7, truth.s_to = 0.95;
  CopSamples smp;
  for (int k = 0; k <= 200; ++k) {
    const double th = -0.5 + 1.7 * k / 200.0;
    smp.theta_rad.push_back(th);
    smp.fraction.push_back(truth.fraction(th));
  }
  const auto fit = fit_cop_function(smp, CopFunction::paper());
  EXPECT_NEAR(fit.function.s_hs, 0.1, 1e-5);
  EXPECT_NEAR(fit.function.s_ho, 0.35, 1e-5);
  EXPECT_NEAR(fit.function.s_mo, 0.7, 1e-5);
  EXPECT_NEAR(fit.function.s_to, 0.95, 1e-5);
  EXPECT_LT(fit.rms_fraction, 1e-6);
  CopSamples few;
  few.theta_rad = {0.0};
  few.fraction = {0.5};
  EXPECT_THROW(fit_cop_function(few, CopFunction::paper()), InputError);
}

// The centre-of-mass term: samples whose COP follows the body over the foot at a known gain,
// the body at varied places for one angle (a foot-flat in which the body rolls on). Fitted with
// the term, the gain and the positions come back; the angle alone cannot tell those samples apart
// and leaves an error of the term's own size.
TEST(CopFit, RecoversTheCentreOfMassGainOfSamplesThatFollowTheBody) {
  CopFunction truth = CopFunction::paper();
  truth.s_hs = 0.1, truth.s_ho = 0.35, truth.s_mo = 0.7, truth.s_to = 0.95, truth.com_gain = 0.12;
  CopSamples smp;
  for (int k = 0; k <= 200; ++k)
    for (double com : {-0.5, 0.0, 0.5, 1.5}) {  // within the sole: no clamp
      const double th = -0.5 + 1.7 * k / 200.0;
      smp.theta_rad.push_back(th);
      smp.com_place.push_back(com);
      smp.fraction.push_back(truth.fraction(th, com));
    }
  const auto fit = fit_cop_function(smp, CopFunction::paper(), true);
  EXPECT_NEAR(fit.function.com_gain, 0.12, 1e-5);
  EXPECT_NEAR(fit.function.s_ho, 0.35, 1e-5);
  EXPECT_NEAR(fit.function.s_mo, 0.7, 1e-5);
  EXPECT_LT(fit.rms_fraction, 1e-6);
  const auto alone = fit_cop_function(smp, CopFunction::paper());
  EXPECT_EQ(alone.function.com_gain, 0.0);
  EXPECT_GT(alone.rms_fraction, 0.05);  // 0.12 x the places' spread (SD 0.74): about 0.09
  // A COP that rolls back as the body moves on (a negative gain) is not a function a file may
  // hold (0..1): the fit keeps the gain at 0 and fits the positions for it.
  CopSamples back = smp;
  for (std::size_t k = 0; k < back.fraction.size(); ++k) back.fraction[k] = CopFunction::paper().fraction(back.theta_rad[k]) - 0.05 * back.com_place[k];
  const auto bounded = fit_cop_function(back, CopFunction::paper(), true);
  EXPECT_EQ(bounded.function.com_gain, 0.0);
  EXPECT_NO_THROW((void)cop_function_from_json(cop_function_json(bounded.function), "fit.json"));
  // Samples without the body's place cannot fit the term.
  CopSamples bare = smp;
  bare.com_place.clear();
  EXPECT_THROW((void)fit_cop_function(bare, CopFunction::paper(), true), InputError);
}

// The fit keeps the COP rolling forward (s_HS <= s_HO <= s_MO <= s_TO). Samples whose COP falls
// back between heel strike and heel-off (a heel-strike transient) would pull an unconstrained
// least squares to s_HS > s_HO; the fit ties the two at their joint least-squares value instead
// and leaves the ordered positions as they fit.
TEST(CopFit, ThePositionsNeverMoveTheCopBackwards) {
  const CopFunction start = CopFunction::paper();  // HS -0.3, HO 0, MO 0.15, TO 1.0 rad
  CopSamples smp;
  auto add = [&](double th, double s, int n) {
    for (int k = 0; k < n; ++k) smp.theta_rad.push_back(th), smp.fraction.push_back(s), smp.com_place.push_back(0.0);
  };
  add(-0.4, 0.40, 30);  // at and before heel strike: weight on s_HS alone
  add(0.0, 0.30, 10);   // at heel-off: s_HO alone
  add(0.15, 0.70, 20);  // mid-stance to toe-off, in order
  add(1.0, 0.95, 20);
  const auto fit = fit_cop_function(smp, start);
  const CopFunction& f = fit.function;
  EXPECT_LE(f.s_hs, f.s_ho);
  EXPECT_LE(f.s_ho, f.s_mo);
  EXPECT_LE(f.s_mo, f.s_to);
  // Tied: the mean of the two groups' fractions weighted by their counts, (30 x 0.40 + 10 x 0.30) / 40.
  EXPECT_NEAR(f.s_hs, 0.375, 1e-5);
  EXPECT_NEAR(f.s_ho, 0.375, 1e-5);
  EXPECT_NEAR(f.s_mo, 0.70, 1e-5);
  EXPECT_NEAR(f.s_to, 0.95, 1e-5);
  // Fitted with the centre-of-mass gain, the gain's column stays free and the tie still holds.
  const auto with_com = fit_cop_function(smp, start, true);
  EXPECT_NEAR(with_com.function.s_hs, with_com.function.s_ho, 1e-9);
  EXPECT_LE(with_com.function.s_mo, with_com.function.s_to);
  // The event-angle search fits positions the same way.
  const auto searched = fit_cop_function_and_angles(smp, start);
  EXPECT_LE(searched.function.s_hs, searched.function.s_ho);
  EXPECT_LE(searched.function.s_ho, searched.function.s_mo);
  EXPECT_LE(searched.function.s_mo, searched.function.s_to);
}

// The term's arithmetic: added to the angle's fraction, kept within the sole's 0..1.25, and off
// (the paper's function exactly) at a gain of 0.
TEST(CopFit, TheCentreOfMassTermAddsToTheAnglesFractionWithinTheSole) {
  CopFunction f = CopFunction::paper();
  EXPECT_DOUBLE_EQ(f.fraction(0.05, 3.0), f.fraction(0.05));
  f.com_gain = 0.1;
  EXPECT_NEAR(f.fraction(0.05, 0.8) - f.fraction(0.05, 0.0), 0.08, 1e-12);
  EXPECT_DOUBLE_EQ(f.fraction(-1.0, -5.0), 0.0);   // the body far behind the heel: at the heel
  EXPECT_DOUBLE_EQ(f.fraction(2.0, 10.0), 1.25);   // far ahead: the sole's end
}

TEST(CopFit, JsonRoundTripAndFieldErrors) {
  const CopFunction f = CopFunction::paper();
  const CopFunction g = cop_function_from_json(cop_function_json(f), "x.json");
  EXPECT_DOUBLE_EQ(g.s_mo, f.s_mo);
  EXPECT_DOUBLE_EQ(g.delta_to, f.delta_to);
  auto j = cop_function_json(f);
  j.erase("s_ho");
  try {
    (void)cop_function_from_json(j, "cop.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cop.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("s_ho"), std::string::npos);
  }
  j = cop_function_json(f);
  j["delta_mo"] = 2.0;  // after delta_to
  EXPECT_THROW((void)cop_function_from_json(j, "cop.json"), InputError);
  // The centre-of-mass gain: kept through a round trip; absent, 0 (a file of the angle alone keeps
  // its meaning, whatever the built-in function's gain); outside 0..1 refused, naming the field.
  CopFunction h = CopFunction::paper();
  h.com_gain = 0.13;
  EXPECT_DOUBLE_EQ(cop_function_from_json(cop_function_json(h), "x.json").com_gain, 0.13);
  EXPECT_FALSE(cop_function_json(f).contains("com_gain"));
  EXPECT_EQ(cop_function_from_json(cop_function_json(f), "x.json").com_gain, 0.0);
  for (double bad : {-0.1, 1.5}) {
    j = cop_function_json(h);
    j["com_gain"] = bad;
    try {
      (void)cop_function_from_json(j, "cop.json");
      FAIL() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("com_gain"), std::string::npos) << e.what();
    }
  }
}

// The length the fractions count in: kept through a round trip; absent, "sole" (every file written
// before the heel-MT length, and the paper's form); anything else refused, naming the field.
TEST(CopFit, TheFunctionsLengthRoundTripsAndAnOldFileCountsInSoleLengths) {
  for (const CopFunction& f : {CopFunction{}, CopFunction::paper()})
    EXPECT_EQ(cop_function_from_json(cop_function_json(f), "x.json").length, f.length);
  auto j = cop_function_json(CopFunction{});
  EXPECT_EQ(j["length"], "heel-mt");
  j.erase("length");
  EXPECT_EQ(cop_function_from_json(j, "x.json").length, CopLength::Sole);
  j["length"] = "toe";
  try {
    (void)cop_function_from_json(j, "cop.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cop.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'length'"), std::string::npos) << e.what();
  }
}

TEST(CopFit, BuiltInDefaultIsTheCommittedFit) {
  // The built-in COP function (contact.hpp) is the fit stored with its provenance.
  const CopFunction f = read_cop_function(std::string(KIN2GRF_SOURCE_DIR) + "/data/cop-function/walking-fitted.json");
  const CopFunction d;
  for (auto [a, b] : {std::pair{f.delta_hs, d.delta_hs}, {f.delta_ho, d.delta_ho}, {f.delta_mo, d.delta_mo}, {f.delta_to, d.delta_to},
                      {f.s_hs, d.s_hs}, {f.s_ho, d.s_ho}, {f.s_mo, d.s_mo}, {f.s_to, d.s_to}, {f.com_gain, d.com_gain}})
    EXPECT_NEAR(a, b, 5e-4);
  EXPECT_EQ(f.length, d.length);
  EXPECT_EQ(d.length, CopLength::HeelMt);
  EXPECT_GT(d.com_gain, 0.0);
  // The running function likewise (the angle alone).
  EXPECT_EQ(CopFunction::running().com_gain, 0.0);
  EXPECT_EQ(CopFunction::paper().com_gain, 0.0);
  const CopFunction fr = read_cop_function(std::string(KIN2GRF_SOURCE_DIR) + "/data/cop-function/running-fitted.json");
  const CopFunction dr = CopFunction::running();
  for (auto [a, b] : {std::pair{fr.delta_hs, dr.delta_hs}, {fr.delta_ho, dr.delta_ho}, {fr.delta_mo, dr.delta_mo},
                      {fr.delta_to, dr.delta_to}, {fr.s_hs, dr.s_hs}, {fr.s_ho, dr.s_ho}, {fr.s_mo, dr.s_mo}, {fr.s_to, dr.s_to}})
    EXPECT_NEAR(a, b, 5e-4);
  EXPECT_EQ(fr.length, CopLength::Sole);
  EXPECT_EQ(dr.length, CopLength::Sole);
  EXPECT_EQ(CopFunction::paper().length, CopLength::Sole);
}

// fit-cop's leave-one-lab-out table: per trial the starting function's COP error, the built-in
// function's (what kin2grf runs by default, on every frame), the pooled fit's and a fit without
// the trial's lab; two labs here, so each held-out fit comes from the other lab alone.
TEST(CopFit, LeaveOneLabOutReportsTheBuiltInFunctionBesideTheRefits) {
  const Trial walk = make_example_walk();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  std::vector<StudyTrial> trials(2);
  for (std::size_t k = 0; k < 2; ++k) {
    trials[k].name = k ? "walk-b" : "walk-a";
    trials[k].activity = "walking";
    trials[k].lab = k ? "lab-b" : "lab-a";
    trials[k].trial = &walk;
    trials[k].plates = &*walk.plates;
    trials[k].marker_set = &set;
  }
  const CopFitOnTrials res = fit_cop_on_trials(trials, CopFunction::paper(), 0.2, false, true);
  ASSERT_EQ(res.leave_one_out.size(), 2u);
  EstimateOptions o;
  o.contact.running_cop.reset();
  const double builtin = mean_rrmse(validate(estimate(walk, nullptr, set, o), *walk.plates).stances).cop;
  for (const auto& l : res.leave_one_out) {
    EXPECT_DOUBLE_EQ(l.builtin, builtin) << l.trial;
    EXPECT_NE(l.start, l.builtin) << l.trial;  // the paper's function is not the built-in one
    EXPECT_TRUE(std::isfinite(l.others)) << l.trial;
  }
  // Beside the COP, the forces and the GRM the held-out fit gives the trial: here both labs hold
  // the same walk, so the fit without one lab is the pooled fit (to round-off: one copy of the
  // samples against two), and the figures are its run's.
  EstimateOptions with_fit = o;
  with_fit.contact.cop = res.fit.function;
  const ValidationResult v = validate(estimate(walk, nullptr, set, with_fit), *walk.plates);
  const MeanMetrics m = mean_rrmse(v.stances);
  ASSERT_TRUE(v.total && v.total->metrics.moment);
  for (const auto& l : res.leave_one_out) {
    EXPECT_NEAR(l.others, m.cop, 1e-9) << l.trial;
    EXPECT_NEAR(l.others_vertical, m.vertical, 1e-9) << l.trial;
    EXPECT_NEAR(l.others_anterior, m.anterior, 1e-9) << l.trial;
    EXPECT_NEAR(l.others_grm, v.total->metrics.moment->rrmse_percent, 1e-9) << l.trial;
    EXPECT_NEAR(l.others_cop_mm, m.cop_rmse_mm, 1e-9) << l.trial;
  }
  // The COP's mm: the mean of the stances' RMSE along progression.
  double mm = 0;
  int n = 0;
  for (const auto& s : v.stances)
    if (s.metrics.cop && !s.cop_reference_suspect) mm += 1000 * s.metrics.cop->rmse, ++n;
  ASSERT_GT(n, 0);
  EXPECT_NEAR(m.cop_rmse_mm, mm / n, 1e-9);
  EXPECT_GT(m.cop_rmse_mm, 0.0);
  const auto j = cop_fit_json(res, trials, CopFunction::paper(), CopFitProvenance{});
  EXPECT_TRUE(j["provenance"]["leave_one_lab_out_cop_rrmse_percent"][0].contains("other_labs_vertical"));
  EXPECT_TRUE(j["provenance"]["leave_one_lab_out_cop_rrmse_percent"][0].contains("other_labs_cop_rmse_mm"));
}
