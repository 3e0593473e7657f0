// Tests of model: the 9 bodies, their masses and inertias.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/model/anthropometry.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

using kin2grf::test::run;
using kin2grf::test::synthetic_landmarks;

TEST(Model, MassMatrixSumsToBodyMass) {
  const auto r = run({});
  double m = 0;
  for (const auto& b : r.model().bodies) m += b.mass_kg;
  EXPECT_NEAR(m, 70.0 * (0.678 + 2 * (0.100 + 0.0465 + 0.0145)), 1e-9);
  EXPECT_NEAR(r.model().mass_diagonal().sum(), 2 * m + [&] { double s = 0; for (auto& b : r.model().bodies) s += b.inertia_kgm2; return s; }(), 1e-9);
}

// The anthropometric tables: the 9 bodies' mass fractions add up to the whole body, each
// segment's COM lies inside it and its radius of gyration is a fraction of its length.
TEST(Model, AnthropometricTablesCoverTheWholeBody) {
  for (const char* name : {"winter", "de-leva"}) {
    const AnthropometricTable& t = anthropometric_table(name);
    EXPECT_EQ(t.name, name);
    const double total = t.hat.mass_fraction + 2 * (t.thigh.mass_fraction + t.shank.mass_fraction + t.foot.mass_fraction + t.toes.mass_fraction);
    EXPECT_NEAR(total, 1.0, 0.005) << name;
    for (const SegmentInertia* s : {&t.hat, &t.thigh, &t.shank, &t.foot, &t.toes}) {
      EXPECT_GT(s->mass_fraction, 0.0) << name;
      EXPECT_GT(s->com_fraction, 0.0) << name;
      EXPECT_LT(s->com_fraction, 1.0) << name;
      EXPECT_GT(s->gyration_fraction, 0.1) << name;
      EXPECT_LT(s->gyration_fraction, 0.7) << name;
    }
  }
  EXPECT_THROW((void)anthropometric_table("dempster"), InputError);
  // build_model scales them by mass and length: the thigh's inertia is m (k L)^2.
  BodyGeometry g;
  const Model m = build_model(g, 80.0, de_leva_table());
  const Body& thigh = m.bodies[segment(kLeft, kThigh)];
  EXPECT_NEAR(thigh.mass_kg, 80.0 * de_leva_table().thigh.mass_fraction, 1e-12);
  EXPECT_NEAR(thigh.inertia_kgm2, thigh.mass_kg * std::pow(de_leva_table().thigh.gyration_fraction * g.thigh[kLeft], 2), 1e-12);
  EXPECT_THROW((void)build_model(g, -1.0, de_leva_table()), InputError);
}

// A knee or ankle landmark off its joint shows in the segments' proportions (a shank 0.9-1.1 of
// its thigh, the sides within 15 % of each other): a shank of 0.71 of its thigh is named, as UWA's
// functional ankle centres from a walk give (0.67-0.72, where its runs give 0.91-0.94), and so are
// sides 29 % apart; the synthetic walk as made says nothing.
TEST(Model, AShankOutOfProportionWithItsThighIsNamed) {
  BodyGeometry g;
  EXPECT_TRUE(segment_proportion_notes(g).empty());
  const EstimateResult walk = estimate(make_example_walk(), nullptr, *find_marker_set("kin2grf-example"), {});
  for (const auto& m : walk.messages) EXPECT_EQ(m.find("seems misplaced"), std::string::npos) << m;
  g.shank[0] = 0.30;  // against 0.42 m thighs: 0.71
  const std::vector<std::string> notes = segment_proportion_notes(g);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0].rfind("shank_r is 0.300 m against its thigh's 0.420 m (0.71 of it", 0), 0u) << notes[0];
  EXPECT_EQ(notes[1].rfind("the right shank is 0.300 m and the left 0.420 m (29 % apart)", 0), 0u) << notes[1];
  g.shank = {0.40, 0.40};
  g.thigh = {0.42, 0.30};  // a left thigh short: 1.33 out, and the sides apart
  EXPECT_EQ(segment_proportion_notes(g).size(), 2u);
}
