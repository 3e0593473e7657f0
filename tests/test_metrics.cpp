// Tests of validation/metrics: rRMSE, RMSE, threshold crossings.
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
