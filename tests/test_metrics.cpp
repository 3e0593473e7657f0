// Tests of validation/metrics: rRMSE, RMSE, threshold crossings.
#include <gtest/gtest.h>

#include <algorithm>
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
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/cop_fit.hpp"
#include "kin2grf/validation/metrics.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"
#include "test_support.hpp"

using namespace kin2grf;

TEST(Metrics, RmseAndRrmseOfHandMadeSeries) {
  // est - meas = (1, -1, 1, -1): RMSE 1. Ranges: est 0..10 -> 10... by construction below.
  Eigen::VectorXd meas(4), est(4);
  meas << 0, 4, 8, 10;
  est << 1, 3, 9, 9;
  const auto m = compare_series(est, meas);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->samples, 4);
  EXPECT_DOUBLE_EQ(m->rmse, 1.0);
  // range(est) = 8, range(meas) = 10 -> mean range 9 -> rRMSE = 100/9 %.
  EXPECT_NEAR(m->rrmse_percent, 100.0 / 9.0, 1e-12);
  EXPECT_DOUBLE_EQ(m->max_abs_error, 1.0);
  EXPECT_DOUBLE_EQ(m->peak_difference, -1.0);
  EXPECT_GT(m->pearson_r, 0.95);
  EXPECT_LT(m->pearson_r, 1.0);
  // NaN pairs are left out; identical series give zero error and r = 1.
  Eigen::VectorXd a(5), b(5);
  a << 1, 2, NAN, 4, 8;
  b << 1, 2, 3, NAN, 8;
  const auto z = compare_series(a, b);
  ASSERT_TRUE(z);
  EXPECT_EQ(z->samples, 3);
  EXPECT_DOUBLE_EQ(z->rmse, 0.0);
  EXPECT_DOUBLE_EQ(z->rrmse_percent, 0.0);
  EXPECT_NEAR(z->pearson_r, 1.0, 1e-12);
  EXPECT_FALSE(compare_series(Eigen::VectorXd::Constant(3, NAN), Eigen::VectorXd::Zero(3)));
}

TEST(Metrics, ThresholdCrossingsAreInterpolated) {
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(6, 0.0, 0.05), v(6);
  v << 0, 10, 30, 50, 30, 0;
  EXPECT_NEAR(*rising_crossing(v, t, 20.0, 0, 5), 0.015, 1e-12);
  EXPECT_NEAR(*falling_crossing(v, t, 20.0, 0, 5), 0.04 + 0.01 * 10.0 / 30.0, 1e-12);
  EXPECT_FALSE(rising_crossing(v, t, 60.0, 0, 5));
}

// A filtered export's threshold crossing leads the foot's contact (and lags its lift-off) by the
// filter's spread; the loading ramp's zero intercept (20-80 % of the peak) moves by less: a zero-lag
// filter leaves a ramp's straight part where it was and spreads only its corners. A stance as a
// plate sees it: nothing until 0.30 s, a ramp to 800 N, a plateau, a ramp down to nothing at 0.90 s;
// then through a 6 Hz zero-lag low-pass, as Rajagopal's and subject01's GRF .mot files were (their
// onsets creep 25-28 ms). A 50 ms ramp's crossing moves 22 ms, its intercept 14; a 90 ms ramp's 14
// and 4.
TEST(Metrics, TheLoadingRampsInterceptMovesLessThanAThresholdCrossingUnderAZeroLagFilter) {
  const double rate = 1000.0, on = 0.30, off = 0.90;
  const Eigen::Index n = 1200, mid = 600;
  Eigen::VectorXd t(n), raw(n);
  for (double ramp : {0.05, 0.09}) {
    for (Eigen::Index i = 0; i < n; ++i) {
      t[i] = static_cast<double>(i) / rate;
      raw[i] = 800.0 * std::clamp(std::min(t[i] - on, off - t[i]) / ramp, 0.0, 1.0);
    }
    const Eigen::VectorXd filtered = butterworth_filtfilt(raw, rate, 6.0);
    // The raw ramps' intercepts are the contact and the lift-off.
    EXPECT_NEAR(*loading_ramp_onset(raw, t, 0, mid, n - 1), on, 1e-3);
    EXPECT_NEAR(*unloading_ramp_offset(raw, t, 0, mid, n - 1), off, 1e-3);
    // Filtered: the 20 N crossings move by more than 10 ms, the intercepts by under 0.7 of that.
    const double crossing_lead = on - *rising_crossing(filtered, t, 20.0, 0, n - 1);
    const double crossing_lag = *falling_crossing(filtered, t, 20.0, 0, n - 1) - off;
    EXPECT_GT(crossing_lead, 0.010);
    EXPECT_GT(crossing_lag, 0.010);
    EXPECT_LT(std::abs(*loading_ramp_onset(filtered, t, 0, mid, n - 1) - on), 0.7 * crossing_lead) << ramp;
    EXPECT_LT(std::abs(*unloading_ramp_offset(filtered, t, 0, mid, n - 1) - off), 0.7 * crossing_lag) << ramp;
  }
  // Nothing to time: no load, or no rise in the span.
  EXPECT_FALSE(loading_ramp_onset(Eigen::VectorXd::Zero(n), t, 0, mid, n - 1));
  EXPECT_FALSE(loading_ramp_onset(raw, t, mid, mid + 10, n - 1));
}
