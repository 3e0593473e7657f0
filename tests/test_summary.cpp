// Tests of io/summary: what `kin2grf info` says of a recording.
#include <gtest/gtest.h>

#include <cmath>

#include "kin2grf/io/summary.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

// A plate's loaded intervals: runs above the threshold, dips under 10 ms bridged, blips under
// 10 ms dropped, each with its peak.
TEST(Summary, LoadedIntervalsBridgeDipsAndDropBlips) {
  ForcePlateRecording rec;
  rec.rate_hz = 1000;
  rec.up_axis = Axis::Z;
  const Eigen::Index n = 1000;
  rec.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, 0.999);
  ForcePlate p;
  p.force_N = Eigen::MatrixX3d::Zero(n, 3);
  for (Eigen::Index i = 100; i < 400; ++i) p.force_N(i, 2) = 700 + (i == 250 ? 300 : 0);
  for (Eigen::Index i = 200; i < 205; ++i) p.force_N(i, 2) = 5;   // a 5 ms dip: bridged
  for (Eigen::Index i = 600; i < 605; ++i) p.force_N(i, 2) = 500;  // a 5 ms blip: dropped
  for (Eigen::Index i = 700; i < 900; ++i) p.force_N(i, 2) = 600;
  p.force_N(800, 2) = std::nan("");                                    // a missing sample splits nothing long
  rec.plates.push_back(p);
  const auto iv = loaded_intervals(rec, rec.plates[0], 20.0);
  ASSERT_EQ(iv.size(), 2u);
  EXPECT_EQ(iv[0].first_sample, 100);
  EXPECT_EQ(iv[0].last_sample, 399);
  EXPECT_DOUBLE_EQ(iv[0].peak_vertical_N, 1000.0);
  EXPECT_NEAR(iv[1].start_s, 0.700, 1e-9);
  EXPECT_NEAR(iv[1].end_s, 0.899, 1e-9);
}

// The summary of the bundled example walk: its markers, its mass and one stance on each plate.
TEST(Summary, ExampleWalkIsDescribed) {
  const Trial t = make_example_walk();
  const nlohmann::json s = trial_summary(t, 20.0);
  const std::string text = format_summary(s);
  EXPECT_NE(text.find("Hz"), std::string::npos) << text;
  ASSERT_TRUE(t.plates.has_value());
  ASSERT_EQ(t.plates->plates.size(), 2u);
  for (const auto& p : t.plates->plates) EXPECT_EQ(loaded_intervals(*t.plates, p, 20.0).size(), 1u) << p.name;
}

// info says which marker set estimate would take: the preset it recognises, else the mapping made
// from the labels (its rules), else what no label gives.
TEST(Summary, InfoSaysWhichMarkerSetEstimateWouldTake) {
  Trial t = make_example_walk();
  EXPECT_EQ(trial_summary(t)["marker_set"]["preset"], "kin2grf-example");
  for (auto& n : t.markers.names)
    if (n.size() == 4) n = n.substr(0, 1) + "_" + n.substr(1);  // RKJC -> R_KJC: no preset knows it
  const nlohmann::json s = trial_summary(t);
  EXPECT_TRUE(s["marker_set"]["preset"].is_null());
  EXPECT_TRUE(s["marker_set"]["missing"].empty()) << s["marker_set"].dump();
  const std::string text = format_summary(s);
  EXPECT_NE(text.find("no preset recognised; made from the labels"), std::string::npos) << text;
  EXPECT_NE(text.find("knee_r = R_KJC (joint centre)"), std::string::npos) << text;
  for (auto& n : t.markers.names)
    if (n == "R_KJC") n = "R_XYZ";
  const std::string missing = format_summary(trial_summary(t));
  EXPECT_NE(missing.find("missing knee_r: no joint centre"), std::string::npos) << missing;
  // A label in the file but empty is named as such, not only as a landmark no label gives.
  const int ankle = t.markers.find("R_AJC");
  ASSERT_GE(ankle, 0);
  t.markers.positions_m[static_cast<std::size_t>(ankle)].setConstant(std::nan(""));
  const nlohmann::json empty = trial_summary(t);
  ASSERT_EQ(empty["marker_set"]["too_few_samples"].size(), 1u) << empty["marker_set"].dump();
  EXPECT_EQ(empty["marker_set"]["too_few_samples"][0].get<std::string>().rfind("R_AJC (0 of ", 0), 0u);
  EXPECT_NE(format_summary(empty).find("left out, samples in too few frames: R_AJC (0 of"), std::string::npos);
}
