// Tests of validation/metrics: rRMSE, RMSE, threshold crossings.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>

#include "kin2grf/dynamics/stance_parameters.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/text.hpp"
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

// A stance whose force is piecewise linear, so that every parameter has an exact value: the
// vertical force rises 0 -> 800 N over frames 0-10, falls to 600 N at frame 30, rises to 900 N at
// frame 50 and falls to 0 at frame 60 (100 Hz); the anterior force 10 (i - 30.5) N, braking until
// it crosses zero between frames 30 and 31.
TEST(StanceParameters, APiecewiseLinearStancesPeaksImpulsesAndLoadingRateAreExact) {
  Eigen::MatrixX2d f(61, 2);
  for (Eigen::Index i = 0; i <= 60; ++i) {
    const double x = static_cast<double>(i);
    f(i, 0) = 10.0 * (x - 30.5);
    f(i, 1) = i <= 10 ? 80.0 * x : i <= 30 ? 800.0 - 10.0 * (x - 10) : i <= 50 ? 600.0 + 15.0 * (x - 30) : 900.0 - 90.0 * (x - 50);
  }
  const StanceParameters p = stance_parameters(f, 100.0, 0, 60);
  EXPECT_NEAR(p.duration_s, 0.61, 1e-12);
  EXPECT_NEAR(p.vertical_first_peak_N, 800.0, 1e-9);
  EXPECT_NEAR(p.vertical_valley_N, 600.0, 1e-9);
  EXPECT_NEAR(p.vertical_second_peak_N, 900.0, 1e-9);
  EXPECT_NEAR(p.vertical_peak_N, 900.0, 1e-9);
  EXPECT_NEAR(p.braking_peak_N, -305.0, 1e-9);
  EXPECT_NEAR(p.propulsive_peak_N, 295.0, 1e-9);
  // Areas: 0.1 s x 400 + 0.2 x 700 + 0.2 x 750 + 0.1 x 450 N.
  EXPECT_NEAR(p.vertical_impulse_Ns, 375.0, 1e-9);
  // The anterior line's two triangles, split where it crosses zero (30.5 frames in).
  EXPECT_NEAR(p.braking_impulse_Ns, -0.01 * 10.0 * 30.5 * 30.5 / 2, 1e-9);
  EXPECT_NEAR(p.propulsive_impulse_Ns, 0.01 * 10.0 * 29.5 * 29.5 / 2, 1e-9);
  // 20-80 % of the first peak (160 -> 640 N) on the 8000 N/s rise.
  EXPECT_NEAR(p.loading_rate_N_per_s, 8000.0, 1e-6);

  // A stance the window cuts after its rise: no loading rate (the rise is not seen), the rest of
  // its own frames'.
  const StanceParameters cut = stance_parameters(f, 100.0, 5, 60);
  EXPECT_TRUE(std::isnan(cut.loading_rate_N_per_s));
  EXPECT_NEAR(cut.vertical_first_peak_N, 800.0, 1e-9);
  // A lost sample is skipped, not read as zero; frames outside the series are refused.
  f(40, 1) = std::numeric_limits<double>::quiet_NaN();
  const StanceParameters gap = stance_parameters(f, 100.0, 0, 60);
  EXPECT_NEAR(gap.vertical_valley_N, 600.0, 1e-9);
  EXPECT_NEAR(gap.vertical_impulse_Ns, 375.0 - 0.01 * 0.5 * (735.0 + 2 * 750.0 + 765.0), 1e-9);
  EXPECT_THROW(stance_parameters(f, 100.0, 10, 61), std::invalid_argument);
  EXPECT_THROW(stance_parameters(f, 0.0, 0, 60), std::invalid_argument);
  // A foot that never brakes has a braking peak and impulse of 0.
  f.col(0).setConstant(50.0);
  EXPECT_EQ(stance_parameters(f, 100.0, 0, 60).braking_peak_N, 0.0);
  EXPECT_EQ(stance_parameters(f, 100.0, 0, 60).braking_impulse_Ns, 0.0);
}
