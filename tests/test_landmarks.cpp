// Tests of markers/landmarks: marker sets, joint centres, the torso.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/json.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/kinematics/motion.hpp"
#include "kin2grf/io/marker_labels.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/workflow/settings.hpp"
#include "test_support.hpp"

using namespace kin2grf;

using kin2grf::test::run;
using kin2grf::test::synthetic_landmarks;

// A torso without trunk markers (pelvis_up) sways fore-aft by sway_gain times the hip centre's
// oscillation about its slow trend: 1 is rigid with the hip, 0 holds the shoulder on the trend.
TEST(Landmarks, UprightTorsoSwaysByItsGain) {
  SyntheticOptions so;
  so.squat_depth = 0.0;  // quiet standing, plus a 2 Hz, 2 cm fore-aft sway of the whole body
  Trial t = make_synthetic_trial(so);
  const Eigen::Index n = t.markers.frames();
  const Eigen::ArrayXd sway = 0.02 * (2.0 * M_PI * 2.0 * t.markers.time_s.array()).sin();
  for (auto& p : t.markers.positions_m) p.col(0).array() += sway;
  // Pelvis markers about the hip-centre midpoint (lab: X forward, Y left, Z up).
  const Eigen::MatrixX3d hip = 0.5 * (t.markers.positions_m[static_cast<std::size_t>(t.markers.find("RHJC"))] +
                                      t.markers.positions_m[static_cast<std::size_t>(t.markers.find("LHJC"))]);
  const std::pair<const char*, Eigen::RowVector3d> pelvis[] = {{"RASI", {0.06, -0.12, 0.08}}, {"LASI", {0.06, 0.12, 0.08}},
                                                               {"RPSI", {-0.10, -0.05, 0.10}}, {"LPSI", {-0.10, 0.05, 0.10}}};
  for (const auto& [name, offset] : pelvis) {
    t.markers.names.emplace_back(name);
    t.markers.descriptions.emplace_back();
    t.markers.positions_m.push_back(hip.rowwise() + offset);
  }
  auto shoulder_x = [&](double gain) {
    nlohmann::json j = read_json_file(std::string(KIN2GRF_SOURCE_DIR) + "/data/presets/kin2grf-example.json");
    j["landmarks"]["shoulder"] = {{"pelvis_up", 0.5}, {"sway_gain", gain},
                                  {"pelvis", {{"rasis", "RASI"}, {"lasis", "LASI"}, {"rpsis", "RPSI"}, {"lpsis", "LPSI"}}}};
    const MarkerSet set = parse_marker_set(j, "test");
    const auto e = estimate(t, nullptr, set, {});
    return Eigen::VectorXd(e.landmarks.p[kShoulder].col(0));
  };
  const Eigen::VectorXd rigid = shoulder_x(1.0), half = shoulder_x(0.5), still = shoulder_x(0.0);
  ASSERT_EQ(rigid.size(), n);
  // Away from the ends (the trend filter's edges): the rigid torso carries the whole sway, the
  // half-gain torso half of it, the zero-gain torso none.
  double worst_half = 0, worst_still = 0;
  for (Eigen::Index i = n / 5; i < n - n / 5; ++i) {
    worst_half = std::max(worst_half, std::abs((rigid[i] - half[i]) - 0.5 * sway[i]));
    worst_still = std::max(worst_still, std::abs((rigid[i] - still[i]) - sway[i]));
  }
  EXPECT_LT(worst_half, 1e-3);
  EXPECT_LT(worst_still, 2e-3);
  // A gain outside 0-1.5 is refused, naming the landmark.
  nlohmann::json bad = read_json_file(std::string(KIN2GRF_SOURCE_DIR) + "/data/presets/kin2grf-example.json");
  bad["landmarks"]["shoulder"] = {{"pelvis_up", 0.5}, {"sway_gain", 3.0}, {"pelvis", {{"rasis", "RASI"}, {"lasis", "LASI"}, {"rpsis", "RPSI"}, {"lpsis", "LPSI"}}}};
  try {
    (void)parse_marker_set(bad, "bad.json");
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sway_gain"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("shoulder"), std::string::npos) << e.what();
  }
}

// SCoRE on a synthetic knee: a thigh swinging about a moving hip and a shank flexing about a
// known knee axis (lateral, Y), clusters 6-9 cm off the bones. The functional centre must lie
// on the axis: its sagittal (X, Z) place within 1 mm of the true knee, whatever its place along
// the axis (a hinge does not tell it; the limb's midline is taken).
TEST(Landmarks, FunctionalKneeCentreOfAHingeIsOnItsAxis) {
  MarkerTrajectories m;
  const int n = 300;
  m.rate_hz = 100;
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0, (n - 1) / 100.0);
  m.up_axis = Axis::Z;
  const char* names[] = {"TH1", "TH2", "TH3", "TB1", "TB2", "TB3"};
  for (const char* nm : names) {
    m.names.emplace_back(nm);
    m.positions_m.emplace_back(n, 3);
  }
  const Eigen::Vector3d th_local[] = {{0.05, 0.08, 0.15}, {-0.04, 0.07, 0.22}, {0.02, 0.09, 0.30}};    // from the knee, thigh frame
  const Eigen::Vector3d tb_local[] = {{0.04, 0.07, -0.12}, {-0.03, 0.08, -0.20}, {0.03, 0.06, -0.27}};  // from the knee, shank frame
  Eigen::MatrixX3d knee(n, 3);
  auto rot_y = [](double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); };
  for (int i = 0; i < n; ++i) {
    const double t = m.time_s[i];
    const Eigen::Vector3d hip(0.8 * t, 0.0, 0.9 + 0.02 * std::sin(2 * M_PI * 1.8 * t));
    const Eigen::Matrix3d Rt = rot_y(0.4 * std::sin(2 * M_PI * 0.9 * t));           // thigh swing
    const Eigen::Matrix3d Rs = Rt * rot_y(-0.6 * (1 - std::cos(2 * M_PI * 0.9 * t)));  // knee flexion 0-69 deg
    const Eigen::Vector3d k = hip + Rt * Eigen::Vector3d(0, 0, -0.44);
    knee.row(i) = k.transpose();
    for (int j = 0; j < 3; ++j) {
      m.positions_m[static_cast<std::size_t>(j)].row(i) = (k + Rt * th_local[j]).transpose();
      m.positions_m[static_cast<std::size_t>(3 + j)].row(i) = (k + Rs * tb_local[j]).transpose();
    }
  }
  std::string msg;
  nlohmann::json rule = {{"functional", {{"proximal", {"TH1", "TH2", "TH3"}}, {"distal", {"TB1", "TB2", "TB3"}}}}};
  nlohmann::json j = {{"name", "t"}, {"landmarks", nlohmann::json::object()}};
  for (const char* id : {"shoulder", "hip", "knee_r", "ankle_r", "heel_r", "mt_r", "hallux_r", "knee_l", "ankle_l", "heel_l",
                         "mt_l", "hallux_l"})
    j["landmarks"][id] = std::string(id) == "knee_r" ? rule : nlohmann::json{{"marker", "TH1"}};
  const MarkerSet set = parse_marker_set(j, "test");
  const Landmarks3D lm = compute_landmarks(set, m, nullptr, {}, "synthetic");
  const auto& K = lm.p[landmark(kRight, kKnee)];
  for (int i = 0; i < n; i += 10) {
    EXPECT_NEAR(K(i, 0), knee(i, 0), 1e-3) << i;
    EXPECT_NEAR(K(i, 2), knee(i, 2), 1e-3) << i;
    EXPECT_LT(std::abs(K(i, 1) - knee(i, 1)), 0.15) << "on the limb, not far along the axis";
  }
  bool said = false;
  for (const auto& s : lm.messages) said = said || s.find("SCoRE") != std::string::npos;
  EXPECT_TRUE(said);
}

// A full Plug-in Gait file whose LSHO/RSHO labels exist but hold no sample (issue 10): the
// lower-body preset, which can run it, is chosen, and the reason lists both candidates.
TEST(Landmarks, PresetRecognitionLooksAtWhichMarkersHoldData) {
  MarkerTrajectories m;
  m.rate_hz = 100;
  m.time_s = Eigen::VectorXd::LinSpaced(50, 0, 0.49);
  std::vector<std::string> used;
  for (const char* set : {"plug-in-gait", "plug-in-gait-lower"}) {
    const auto u = find_marker_set(set)->motion_markers();
    used.insert(used.end(), u.begin(), u.end());
    used.insert(used.end(), find_marker_set(set)->signature.begin(), find_marker_set(set)->signature.end());
  }
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  for (const auto& name : used) {
    m.names.push_back(name);
    m.descriptions.emplace_back();
    const bool empty = name == "LSHO" || name == "RSHO";
    m.positions_m.push_back(Eigen::MatrixX3d::Constant(50, 3, empty ? std::nan("") : 0.5));
  }
  std::string why;
  const MarkerSet* s = recognise_marker_set(m, &why);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->name, "plug-in-gait-lower") << why;
  EXPECT_NE(why.find("plug-in-gait 0 frames"), std::string::npos) << why;
  // With the shoulders holding data, the full set (more markers) is taken.
  for (std::size_t k = 0; k < m.names.size(); ++k) m.positions_m[k].setConstant(0.5);
  EXPECT_EQ(recognise_marker_set(m)->name, "plug-in-gait");
}

// compute_landmarks given its markers to release (a long trial's memory, issue 10): each marker's
// samples go after the last landmark that reads it (RHJC is read by the hip and, last, by the
// left hallux here), a marker no landmark reads at once, and the landmarks are the very ones made
// without releasing. Reading a released marker would throw, not read an empty series.
TEST(Landmarks, MarkersAreReleasedAfterTheirLastLandmarkAndTheLandmarksAreTheSame) {
  MarkerTrajectories m = make_synthetic_trial({}).markers;
  m.names.push_back("EXTRA");
  m.descriptions.push_back("");
  m.positions_m.push_back(m.positions_m[0]);
  nlohmann::json j = {{"name", "t"}, {"landmarks", nlohmann::json::object()}};
  j["landmarks"]["shoulder"] = {{"mean", {"RSHO", "LSHO"}}};
  j["landmarks"]["hip"] = {{"mean", {"RHJC", "LHJC"}}};
  for (const char* side : {"r", "l"}) {
    const std::string S = side[0] == 'r' ? "R" : "L";
    j["landmarks"][std::string("knee_") + side] = {{"marker", S + "KJC"}};
    j["landmarks"][std::string("ankle_") + side] = {{"marker", S + "AJC"}};
    j["landmarks"][std::string("heel_") + side] = {{"marker", S + "HEE"}};
    j["landmarks"][std::string("mt_") + side] = {{"marker", S + "MT1"}};
    j["landmarks"][std::string("hallux_") + side] = {{"marker", S + "HLX"}};
  }
  j["landmarks"]["hallux_l"] = {{"mean", {"LHLX", "RHJC"}}};
  const MarkerSet set = parse_marker_set(j, "test");
  const Landmarks3D kept = compute_landmarks(set, m, nullptr, {}, "synthetic");
  MarkerTrajectories given = m;
  const Landmarks3D released = compute_landmarks(set, given, nullptr, {}, "synthetic", &given);
  for (int id = 0; id < kLandmarkCount; ++id)
    EXPECT_TRUE(released.p[static_cast<std::size_t>(id)].cwiseEqual(kept.p[static_cast<std::size_t>(id)]).all()) << id;
  for (std::size_t k = 0; k < given.names.size(); ++k) EXPECT_EQ(given.positions_m[k].rows(), 0) << given.names[k];
  EXPECT_EQ(given.frames(), m.frames());
}

// A trial given up is cleaned of impossible samples where it lies (no copy of every marker for
// one bad sample: a long trial's memory): the same gaps and messages as the cleaned copy.
TEST(Landmarks, OutliersRemovedInPlaceAreThoseOfTheCleanedCopy) {
  MarkerTrajectories m = make_synthetic_trial({}).markers;
  const int k = m.find("RKJC"), far = m.find("LHEE");
  m.positions_m[static_cast<std::size_t>(k)].row(40).array() += 1.0;  // a one-frame jump
  m.positions_m[static_cast<std::size_t>(far)](7, 2) = 1e300;          // outside any lab
  std::vector<std::string> copy_messages, place_messages;
  const auto cleaned = without_marker_outliers(m, {}, copy_messages);
  ASSERT_TRUE(cleaned.has_value());
  std::vector<const double*> storage;
  for (const auto& P : m.positions_m) storage.push_back(P.data());
  EXPECT_EQ(remove_marker_outliers(m, {}, place_messages), 2U);
  EXPECT_EQ(place_messages, copy_messages);
  ASSERT_EQ(place_messages.size(), 2U);
  for (std::size_t j = 0; j < m.positions_m.size(); ++j) {
    EXPECT_EQ(m.positions_m[j].data(), storage[j]) << m.names[j];
    const Eigen::ArrayX3d a = m.positions_m[j].array(), b = cleaned->positions_m[j].array();
    EXPECT_TRUE(((a == b) || (a.isNaN() && b.isNaN())).all()) << m.names[j];
  }
  EXPECT_TRUE(std::isnan(m.positions_m[static_cast<std::size_t>(k)](40, 0)));
  EXPECT_TRUE(std::isnan(m.positions_m[static_cast<std::size_t>(far)](7, 0)));
  // Only the markers asked about are checked.
  std::vector<std::string> none;
  MarkerTrajectories again = make_synthetic_trial({}).markers;
  again.positions_m[static_cast<std::size_t>(k)].row(40).array() += 1.0;
  EXPECT_EQ(remove_marker_outliers(again, {"LHEE"}, none), 0U);
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(std::isnan(again.positions_m[static_cast<std::size_t>(k)](40, 0)));
}

// Plug-in Gait takes a sacrum marker (SACR) in place of the two PSIS markers; such a file was
// "not recognised". The two Plug-in Gait trials with their PSIS markers replaced by a SACR at
// their midpoint are recognised as the SACR variants, and their landmarks are the originals'
// (Harrington's pelvis depth uses the PSIS midpoint, which SACR then is).
TEST(Landmarks, PlugInGaitWithASacrumMarkerIsRecognisedAndGivesTheSameLandmarks) {
  KIN2GRF_REQUIRE_DATA();
  for (const auto& [file, preset] : {std::pair<std::string, std::string>{"PiG_Motion-FlatFoot-Full.c3d", "plug-in-gait"},
                                     {"PiG_Motion3_FF.c3d", "plug-in-gait-lower"}}) {
    const Trial t = load_trial(test::data_dir() + "/btk_plugingait_walk/" + file);
    const MarkerSet* original = recognise_marker_set(t.markers);
    ASSERT_NE(original, nullptr);
    ASSERT_EQ(original->name, preset);
    MarkerTrajectories m = t.markers;
    const int r = m.find("RPSI"), l = m.find("LPSI");
    ASSERT_GE(r, 0);
    ASSERT_GE(l, 0);
    m.names.push_back("SACR");
    m.descriptions.emplace_back();
    m.positions_m.push_back(0.5 * (m.positions_m[static_cast<std::size_t>(r)] + m.positions_m[static_cast<std::size_t>(l)]));
    m.names[static_cast<std::size_t>(r)] = "unused1", m.names[static_cast<std::size_t>(l)] = "unused2";
    std::string why;
    const MarkerSet* sacr = recognise_marker_set(m, &why);
    ASSERT_NE(sacr, nullptr) << file << ": " << why;
    EXPECT_EQ(sacr->name, preset + "-sacr") << file << ": " << why;
    const Landmarks3D a = compute_landmarks(*original, t.markers, nullptr, {}, file);
    const Landmarks3D b = compute_landmarks(*sacr, m, nullptr, {}, file);
    for (int k = 0; k < kLandmarkCount; ++k) {
      const auto& pa = a.p[static_cast<std::size_t>(k)];
      const auto& pb = b.p[static_cast<std::size_t>(k)];
      ASSERT_EQ(pa.rows(), pb.rows());
      for (Eigen::Index i = 0; i < pa.rows(); ++i) {
        ASSERT_EQ(pa.row(i).allFinite(), pb.row(i).allFinite()) << file << " landmark " << k << " frame " << i;
        if (pa.row(i).allFinite()) {
          EXPECT_LT((pa.row(i) - pb.row(i)).norm(), 1e-9) << file << " landmark " << k << " frame " << i;
        }
      }
    }
  }
}

// Hostile and mistaken mapping files (issue 31): each refused with the file and the landmark
// named. They were accepted: a pelvis_up of -0.5 m, four identical pelvis markers, two rules in one
// landmark, an unknown landmark name (ignored).
TEST(MappingFile, MistakesAreRefusedNamingTheLandmark) {
  const nlohmann::json good = read_json_file(std::string(KIN2GRF_SOURCE_DIR) + "/data/presets/kin2grf-example.json");
  const nlohmann::json pelvis = {{"rasis", "RASI"}, {"lasis", "LASI"}, {"rpsis", "RPSI"}, {"lpsis", "LPSI"}};
  const nlohmann::json same = {{"rasis", "RASI"}, {"lasis", "RASI"}, {"rpsis", "RASI"}, {"lpsis", "RASI"}};
  const struct {
    const char* what;
    std::function<void(nlohmann::json&)> edit;
    const char* said;
  } cases[] = {
      {"negative torso", [&](auto& j) { j["landmarks"]["shoulder"] = {{"pelvis_up", -0.5}, {"pelvis", pelvis}}; }, "pelvis_up -0.5"},
      {"one marker four times", [&](auto& j) { j["landmarks"]["hip"] = {{"harrington", same}}; }, "the same marker 'RASI'"},
      {"two rules", [&](auto& j) { j["landmarks"]["knee_r"] = {{"marker", "RKJC"}, {"mean", {"RKJC", "LKJC"}}}; }, "two rules"},
      {"unknown landmark", [&](auto& j) { j["landmarks"]["kneee_r"] = {{"marker", "RKJC"}}; }, "unknown landmark 'kneee_r'"},
      {"unknown rule", [&](auto& j) { j["landmarks"]["knee_r"] = {{"markr", "RKJC"}}; }, "unknown rule"},
      {"unknown upper-body landmark", [&](auto& j) { j["upper_body"] = {{"elbw_r", {"RELB"}}}; }, "unknown upper-body landmark 'elbw_r'"},
      {"upper-body landmark of no marker", [&](auto& j) { j["upper_body"] = {{"wrist_l", nlohmann::json::array()}}; }, "'wrist_l' names no marker"},
      {"upper body not an object", [&](auto& j) { j["upper_body"] = {"RELB"}; }, "\"upper_body\" is not an object"},
  };
  EXPECT_NO_THROW((void)parse_marker_set(good, "good.json"));
  for (const auto& c : cases) {
    nlohmann::json j = good;
    c.edit(j);
    try {
      (void)parse_marker_set(j, "map.json");
      ADD_FAILURE() << c.what << ": accepted";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("map.json"), std::string::npos) << c.what << ": " << m;
      EXPECT_NE(m.find(c.said), std::string::npos) << c.what << ": " << m;
    }
  }
}

// A mapping file whose unknown rule is an array nested 100,000 deep: the message printed the rule
// with a recursive dump() and the stack overflowed (exit 139). The depth is now bounded where the
// file is read.
TEST(MappingFile, NestingDeeperThanTheLimitIsRefusedAtParse) {
  const auto dir = test::temp_dir("deep_mapping");
  const std::string path = (dir / "deep.json").string();
  std::string text = R"({"name": "deep", "landmarks": {"hip": {"oops": )";
  text += std::string(100000, '[') + std::string(100000, ']') + "}}}";
  write_file_text(path, text);
  try {
    (void)load_marker_set(path);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": JSON nested more than 64 levels deep"), std::string::npos) << e.what();
  }
  // 64 levels are read.
  const std::string ok = std::string(64, '[') + std::string(64, ']');
  EXPECT_NO_THROW((void)parse_json_text(ok, "ok"));
  EXPECT_THROW((void)parse_json_text("[" + ok + "]", "deep"), InputError);
}

namespace {
/// The example walk with its knee and ankle centres replaced by medial and lateral markers 5 cm
/// either side, each pair under one label (a Helen-Hayes file's RKNE twice, RANK twice), the
/// lateral one first when `lateral_first`.
Trial walk_with_repeated_labels(bool lateral_first) {
  Trial t = make_example_walk();
  MarkerTrajectories& m = t.markers;
  const auto& rk = m.positions_m[static_cast<std::size_t>(m.find("RKJC"))];
  const auto& lk = m.positions_m[static_cast<std::size_t>(m.find("LKJC"))];
  MarkerTrajectories out = m;
  out.names.clear(), out.positions_m.clear(), out.descriptions.clear();
  for (std::size_t k = 0; k < m.names.size(); ++k) {
    const std::string& n = m.names[k];
    if (n != "RKJC" && n != "RAJC") {
      out.names.push_back(n), out.positions_m.push_back(m.positions_m[k]), out.descriptions.push_back("");
      continue;
    }
    Eigen::MatrixX3d lateral = m.positions_m[k], medial = m.positions_m[k];
    for (Eigen::Index i = 0; i < m.frames(); ++i) {
      // The example walks along x with z up: lateral is along y, away from the left knee.
      const Eigen::Vector3d out_dir(0, rk(i, 1) > lk(i, 1) ? 1.0 : -1.0, 0);
      lateral.row(i) += 0.05 * out_dir.transpose();
      medial.row(i) -= 0.05 * out_dir.transpose();
    }
    const std::string label = n == "RKJC" ? "RKNE" : "RANK";
    for (const auto* p : lateral_first ? std::array{&lateral, &medial} : std::array{&medial, &lateral}) {
      out.names.push_back(label);
      out.positions_m.push_back(*p), out.descriptions.push_back("");
    }
  }
  UniqueLabels unique;  // as the readers name them
  for (std::size_t k = 0; k < out.names.size(); ++k) out.names[k] = unique.add(out.names[k], k, &t.warnings);
  t.markers = std::move(out);
  return t;
}
}  // namespace

// The marker-set regression of issue 31: a repeated label became NAME#k and a landmark naming NAME
// was refused, but the first occurrence could not be named at all. Now the k-th label NAME is
// NAME#k (the first also NAME#1), a mapping file can use all four markers of a file with two RKNE
// and two RANK, and a preset takes the lateral one of a medial-lateral pair, saying so.
TEST(RepeatedLabels, AMappingFileNamesEachOccurrenceAndAPresetTakesTheLateralOne) {
  const MarkerSet* example = find_marker_set("kin2grf-example");
  ASSERT_TRUE(example);
  EstimateOptions o;
  const EstimateResult reference = estimate(make_example_walk(), nullptr, *example, o);
  for (const bool lateral_first : {true, false}) {
    const Trial t = walk_with_repeated_labels(lateral_first);
    EXPECT_GE(t.markers.find("RKNE#1"), 0);
    EXPECT_EQ(t.markers.find("RKNE#1"), t.markers.find("RKNE"));
    EXPECT_EQ(t.markers.find("RKNE#2"), t.markers.find("RKNE") + 1);
    // The mapping: each centre the mean of its medial and lateral marker, all four named.
    MarkerSet mapping = *example;
    mapping.preset = false;
    mapping.rules[2] = LandmarkRule{RuleKind::Mean, {"RKNE#1", "RKNE#2"}, {}, {}, 0.0, 0.0};
    mapping.rules[3] = LandmarkRule{RuleKind::Mean, {"RANK#1", "RANK#2"}, {}, {}, 0.0, 0.0};
    ASSERT_EQ(landmark_name(2), std::string("knee_r"));
    ASSERT_EQ(landmark_name(3), std::string("ankle_r"));
    const EstimateResult r = estimate(t, nullptr, mapping, o);
    ASSERT_EQ(r.time_s.size(), reference.time_s.size());
    EXPECT_TRUE(test::matrices_near(r.landmarks.p[2], reference.landmarks.p[2], 1e-9));
    // A mapping naming the bare label is refused, naming both occurrences.
    MarkerSet bare = *example;
    bare.preset = false;
    bare.rules[2] = LandmarkRule{RuleKind::Marker, {"RKNE"}, {}, {}, 0.0, 0.0};
    bare.rules[3] = LandmarkRule{RuleKind::Mean, {"RANK#1", "RANK#2"}, {}, {}, 0.0, 0.0};
    try {
      (void)estimate(t, nullptr, bare, o);
      ADD_FAILURE() << "a repeated label taken silently";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("as RKNE#1 or RKNE#2"), std::string::npos) << e.what();
    }
    // A preset naming the bare label takes the lateral one (5 cm out) and says which.
    MarkerSet preset = bare;
    preset.preset = true;
    preset.rules[3] = LandmarkRule{RuleKind::Marker, {"RANK"}, {}, {}, 0.0, 0.0};
    std::vector<std::string> messages;
    const auto chosen = choose_repeated_markers(preset, t.markers, messages);
    ASSERT_TRUE(chosen);
    const std::string lateral = lateral_first ? "#1" : "#2";
    EXPECT_EQ(chosen->rules[2].markers[0], "RKNE" + lateral);
    EXPECT_EQ(chosen->rules[3].markers[0], "RANK" + lateral);
    ASSERT_EQ(messages.size(), 2u);
    EXPECT_NE(messages[0].find("takes RKNE" + lateral + ", the lateral one (100 mm farther"), std::string::npos) << messages[0];
    // The estimate with the preset runs and says it (in the sagittal plane the two markers are one
    // point: the landmarks are the reference's).
    const EstimateResult p = estimate(t, nullptr, preset, o);
    EXPECT_NE(std::find_if(p.messages.begin(), p.messages.end(),
                           [](const std::string& m) { return m.find("the lateral one") != std::string::npos; }),
              p.messages.end());
    EXPECT_TRUE(test::matrices_near(p.landmarks.p[2], reference.landmarks.p[2], 1e-9));
  }
}

// Two markers swapped for one frame (the heel jumps 17 cm to the MT head and back at 100 Hz, 17
// m/s, under the 30 m/s jump limit) were taken as motion. A one-frame excursion of more than
// 100 g is now a gap, named; a step of a virtual marker (the sample nearer its neighbours than
// they are to each other) is left.
TEST(MarkerOutliers, TwoMarkersSwappedForOneFrameBecomeGapsNamed) {
  Trial t = make_example_walk();
  auto& m = t.markers;
  const auto heel = static_cast<std::size_t>(m.find("RHEE")), mt = static_cast<std::size_t>(m.find("RMT1"));
  const Eigen::Index i = 120;
  const Eigen::RowVector3d a = m.positions_m[heel].row(i), b = m.positions_m[mt].row(i);
  ASSERT_GT((a - b).norm(), 0.15);
  m.positions_m[heel].row(i) = b;
  m.positions_m[mt].row(i) = a;
  std::vector<std::string> messages;
  const auto cleaned = without_marker_outliers(m, {}, messages);
  ASSERT_TRUE(cleaned);
  EXPECT_FALSE(cleaned->positions_m[heel].row(i).allFinite());
  EXPECT_FALSE(cleaned->positions_m[mt].row(i).allFinite());
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_NE(messages[0].find("RHEE: 1 sample(s) no body can produce (frame " + std::to_string(m.first_frame + i)), std::string::npos)
      << messages[0];
  // The clean walk has none, and a step (the rest of the trial moved 3 cm) is no spike.
  Trial clean = make_example_walk();
  std::vector<std::string> none;
  EXPECT_FALSE(without_marker_outliers(clean.markers, {}, none));
  auto& P = clean.markers.positions_m[heel];
  P.bottomRows(P.rows() - i).col(0).array() += 0.03;
  EXPECT_FALSE(without_marker_outliers(clean.markers, {}, none));
}

// Markers 2 cm below the floor's true place (a ground calibration error): the feet's lowest
// flat-stance landmark is 5 mm up, nearer than a marker's radius, and the message says so. The
// example's own 25 mm is not flagged.
TEST(GroundLevel, AMarkerFloorOffsetIsNamed) {
  const MarkerSet* example = find_marker_set("kin2grf-example");
  ASSERT_TRUE(example);
  auto said = [](const EstimateResult& r) {
    for (const auto& m : r.messages)
      if (m.find("may be offset") != std::string::npos) return true;
    return false;
  };
  EXPECT_FALSE(said(estimate(make_example_walk(), nullptr, *example, {})));
  Trial low = make_example_walk();
  for (auto& P : low.markers.positions_m) P.col(2).array() -= 0.02;
  EXPECT_TRUE(said(estimate(low, nullptr, *example, {})));
}

// An error of the model or the frame finders names the trial's file (it said only "segment torso
// length 5.5 m is not plausible"): markers in cm read as mm make a 16 m tall walker.
TEST(Pipeline, AModelErrorNamesTheTrialsFile) {
  const MarkerSet* example = find_marker_set("kin2grf-example");
  ASSERT_TRUE(example);
  Trial t = make_example_walk();
  t.path = "walk-in-cm.c3d";
  for (auto& P : t.markers.positions_m) P *= 10.0;
  try {
    (void)estimate(t, nullptr, *example, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("walk-in-cm.c3d: ", 0), 0u) << m;
    EXPECT_NE(m.find("units"), std::string::npos) << m;
  }
}

// A toe marker 10 mm ahead of the MT head (a marker mapped as the toe that is not on it: a toe
// segment a quarter of any measured one) cannot carry the COP's roll: the estimate takes
// virtual toes of 0.3 x the ankle-MT length instead and says so; the other foot keeps its marker.
TEST(Landmarks, AToeMarkerTooNearTheMtHeadIsReplacedByVirtualToes) {
  Trial t = make_synthetic_trial({});
  auto& mk = t.markers;
  const int mt = mk.find("RMT1"), toe = mk.find("RHLX"), ankle = mk.find("RAJC");
  ASSERT_GE(mt, 0);
  ASSERT_GE(toe, 0);
  ASSERT_GE(ankle, 0);
  const auto& M = mk.positions_m[static_cast<std::size_t>(mt)];
  const auto& A = mk.positions_m[static_cast<std::size_t>(ankle)];
  auto& T = mk.positions_m[static_cast<std::size_t>(toe)];
  for (Eigen::Index i = 0; i < T.rows(); ++i) T.row(i) = M.row(i) + 0.010 * (M.row(i) - A.row(i)).normalized();
  const auto r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  bool right = false, left = false;
  for (const auto& m : r.messages) {
    right = right || (m.rfind("hallux_r:", 0) == 0 && m.find("too near for a toe") != std::string::npos);
    left = left || m.rfind("hallux_l:", 0) == 0;
  }
  EXPECT_TRUE(right);
  EXPECT_FALSE(left);
  const auto& lm = r.landmarks;
  const Eigen::Index i = lm.frames() / 2;
  const double toe_m = (lm.p[landmark(0, kHallux)].row(i) - lm.p[landmark(0, kMt)].row(i)).norm();
  const double foot_m = (lm.p[landmark(0, kMt)].row(i) - lm.p[landmark(0, kAnkle)].row(i)).norm();
  EXPECT_NEAR(toe_m, kVirtualToeShare * foot_m, 1e-9);
}

// Virtual toes grown from a 5th-metatarsal marker ("surface": "lateral") are
// kLateralMtToeExtraShare longer: the 5th head lies behind the 2nd, so toes of the presets' share
// from it end short of the real ones (study toe-ablation: Stanford's walk's COP 4.4 % with its toe
// marker, 15.8 % with toes of 0.3, 8.6 % with 0.5). A foot whose MT landmark is on the midline
// keeps the presets' share.
TEST(Landmarks, VirtualToesFromAFifthMetatarsalMarkerStartBehindTheSecondHead) {
  const Trial t = make_synthetic_trial({});
  MarkerSet set = *find_marker_set("kin2grf-example");
  for (int side = 0; side < 2; ++side) {
    LandmarkRule& h = set.rules[static_cast<std::size_t>(landmark(side, kHallux))];
    h = LandmarkRule{};
    h.kind = RuleKind::VirtualHallux;
    h.value = kVirtualToeShare;
  }
  set.rules[static_cast<std::size_t>(landmark(0, kMt))].lateral_surface = true;  // the right foot's MT marker on the 5th head
  const auto r = estimate(t, nullptr, set, EstimateOptions{});
  const auto& lm = r.landmarks;
  const Eigen::Index i = lm.frames() / 2;
  for (int side = 0; side < 2; ++side) {
    const double toe_m = (lm.p[landmark(side, kHallux)].row(i) - lm.p[landmark(side, kMt)].row(i)).norm();
    const double foot_m = (lm.p[landmark(side, kMt)].row(i) - lm.p[landmark(side, kAnkle)].row(i)).norm();
    EXPECT_NEAR(toe_m, (kVirtualToeShare + (side == 0 ? kLateralMtToeExtraShare : 0.0)) * foot_m, 1e-9) << "side " << side;
  }
  bool said = false;
  for (const auto& m : r.messages) said = said || (m.rfind("hallux_r:", 0) == 0 && m.find("5th-metatarsal") != std::string::npos);
  EXPECT_TRUE(said);
}

// The trunk ablation (study trunk-ablation): the example set without its shoulder markers puts
// the model torso above its hip centres' mean, needs no trunk marker (a trial whose trunk
// markers are gone still runs) and says so; a hip rule it cannot stand a torso on is named.
TEST(Landmarks, WithoutTrunkMarkersTheTorsoStandsOnTheHipCentre) {
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  std::string why;
  const auto ablated = without_trunk_markers(set, why);
  ASSERT_TRUE(ablated.has_value()) << why;
  EXPECT_EQ(ablated->rules[kShoulder].kind, RuleKind::PelvisUp);
  const auto needed = ablated->motion_markers();
  EXPECT_EQ(std::count(needed.begin(), needed.end(), "RSHO"), 0);
  Trial t = make_synthetic_trial({});
  for (const char* name : {"RSHO", "LSHO"}) {
    const int k = t.markers.find(name);
    ASSERT_GE(k, 0);
    t.markers.positions_m[static_cast<std::size_t>(k)].setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  const auto r = estimate(t, nullptr, *ablated, EstimateOptions{});
  bool said = false;
  for (const auto& m : r.messages) said = said || m.find("trunk markers not used") != std::string::npos;
  EXPECT_TRUE(said);
  // The shoulder point stands 0.5 m above the hip centre (upright; it sways only fore-aft).
  const Eigen::Index i = r.landmarks.frames() / 2;
  EXPECT_NEAR(r.landmarks.p[kShoulder](i, 1) - r.landmarks.p[kHip](i, 1), 0.5, 1e-9);
  MarkerSet functional_hip = set;
  functional_hip.rules[kHip].kind = RuleKind::Functional;
  EXPECT_FALSE(without_trunk_markers(functional_hip, why).has_value());
  EXPECT_NE(why.find("'functional'"), std::string::npos);
}

// A marker set no preset knows is mapped from its labels (io/marker_labels.hpp): each label read
// as a side and a landmark word, in the spellings of Plug-in Gait, ISB/CAST, OpenSim, OpenCap and
// Visual3D. A word kin2grf does not know is left out, never guessed.
TEST(MarkerLabels, ReadsTheSpellingsOfTheFieldsMarkerSets) {
  const std::vector<std::tuple<std::string, char, std::string>> cases = {
      {"RKNE", 'r', "knee_lateral"},   {"L_FLE", 'l', "knee_lateral"},  {"R.Knee.Medial", 'r', "knee_medial"},
      {"r_mknee", 'r', "knee_medial"}, {"RLMAL", 'r', "ankle_lateral"}, {"LMMAL", 'l', "ankle_medial"},
      {"R_TAM", 'r', "ankle_medial"},  {"RMED", 'r', "ankle_medial"},   {"RFCC", 'r', "heel"},
      {"L.Heel", 'l', "heel"},         {"Heel", 0, "heel"},             {"R.Toe.Tip", 'r', "hallux"},
      {"R_Toe_Lat", 'r', "mt5"},       {"r_5meta", 'r', "mt5"},         {"RFM1", 'r', "mt1"},
      {"RTOE", 'r', "toe"},            {"C7", 0, "c7"},                 {"CLAV", 0, "clav"},
      {"SACR", 0, "sacrum"},           {"V.Sacral", 0, "sacrum"},       {"ASIS_R", 'r', "asis"},
      {"LeftASIS", 'l', "asis"},       {"RightKnee", 'r', "knee_lateral"}, {"KneeL", 'l', "knee_lateral"},
      {"RHJC", 'r', "hjc"},            {"L_KJC", 'l', "kjc"},           {"RSHO", 'r', "shoulder"},
      {"R.Acromium", 'r', "shoulder"}, {"LFHD", 'l', "head"},           {"RWRA", 'r', "wrist"},
      {"RTHI", 0, ""},                 {"LTIB", 0, ""},                 {"RTH1", 'r', "thigh_cluster"}, {"R.Shank.Upper", 'r', "shank_cluster"}, {"LTB3", 'l', "shank_cluster"},
      {"*51", 0, ""},                  {"LASI#2", 0, ""},
      // Sports and treadmill labs' sets (MapsTheSetsOfSportsAndTreadmillLabs, below).
      {"WaistLFront", 'l', "asis"},    {"WaistRBack", 'r', "psis"},     {"LFWT", 'l', "asis"},
      {"RKneeOut", 'r', "knee_lateral"}, {"LKneeIn", 'l', "knee_medial"}, {"RAnkleOut", 'r', "ankle_lateral"},
      {"RToeIn", 'r', "mt1"},          {"LToeOut", 'l', "mt5"},         {"LForefootOut", 'l', "mt5"},
      {"RFMH", 'r', "mt1"},            {"RVMH", 'r', "mt5"},            {"LD1M", 'l', "mt1"},
      {"RFMT5", 'r', "mt5"},           {"LLEK", 'l', "knee_lateral"},   {"RShoulderTop", 'r', "shoulder"},
      {"RHLE", 'r', "elbow"},            {"SJN", 0, "clav"},             {"R_MTP5", 'r', "mt5"},
      {"L_Lat_Mall", 'l', "ankle_lateral"}, {"RMTP1", 'r', "mt1"},
      {"RLHE", 0, ""},  // a lateral heel in one lab, a humerus's lateral epicondyle in another: left out
      {"LP1M", 0, ""},  // the Oxford foot model's proximal 1st metatarsal: not the MT head
  };
  for (const auto& [label, side, key] : cases) {
    const MarkerLabel l = read_marker_label(label);
    EXPECT_EQ(l.landmark, key) << label;
    EXPECT_EQ(l.side, side) << label;
  }
}

// The sets of the labs the development data do not come from, each as published: a file
// labelled so maps completely, with the rules its markers call for (before session 38, seven of
// the eight were refused for a missing pelvis, knee, MT head or heel). Qualisys's animation set and
// OptiTrack Motive's baseline with toes (the waist markers on the ASIS and PSIS, lateral knee and
// ankle, in/out forefoot markers on the 1st and 5th MT heads), the conventional gait model 2.4
// (LFMH, LSMH, LVMH), Motek's Human Body Model (GRAIL and CAREN treadmills: LLEK, LLM, LMT5 and a
// TOE on the 2nd toe), the RRIS40 set (RFMT1, RFMT5), the Oxford foot model over Plug-in Gait
// (LD1M, LD5M, LHLX), IOR-gait (Leardini et al. 2007, Gait Posture 26:560: RFM, RSM, RVM) and a
// lab's own (R1ST, R2ND, R5TH, RPHE).
TEST(MarkerLabels, MapsTheSetsOfSportsAndTreadmillLabs) {
  const auto labels = [](std::vector<std::string> both, const std::vector<std::string>& midline) {
    std::vector<std::string> out = midline;
    for (const auto& b : both)
      for (const char* s : {"L", "R"}) {
        std::string l = b;
        const auto at = l.find('@');  // the side's place: a prefix, or inside the word (WaistLFront)
        l.replace(at, 1, s);
        out.push_back(l);
      }
    return out;
  };
  struct Set {
    std::string name;
    std::vector<std::string> labels;
    std::map<std::string, nlohmann::json> expect;  // landmark (right side) -> its rule
  };
  const std::vector<Set> sets = {
      {"qualisys-animation",
       labels({"Waist@Front", "Waist@Back", "@Thigh", "@KneeOut", "@Shin", "@AnkleOut", "@HeelBack", "@ForefootIn", "@ForefootOut",
               "@ToeTip", "@ShoulderTop", "@ElbowOut", "@WristOut", "@WristIn"},
              {"Chest", "SpineTop", "HeadTop", "HeadFront"}),
       {{"hip", {{"harrington", {{"rasis", "WaistRFront"}, {"lasis", "WaistLFront"}, {"rpsis", "WaistRBack"}, {"lpsis", "WaistLBack"}}}}},
        {"knee_r", {{"marker", "RKneeOut"}, {"surface", "lateral"}}},
        {"heel_r", {{"marker", "RHeelBack"}}},
        {"mt_r", {{"mean", {"RForefootIn", "RForefootOut"}}}},
        {"hallux_r", {{"marker", "RToeTip"}}},
        {"shoulder", {{"mean", {"RShoulderTop", "LShoulderTop"}}}}}},
      {"optitrack-baseline-toes",
       labels({"Waist@Front", "Waist@Back", "@Thigh", "@KneeOut", "@Shin", "@AnkleOut", "@Heel", "@ToeIn", "@ToeOut", "@ToeTip",
               "@ShoulderTop", "@ShoulderBack", "@UArmHigh", "@ElbowOut", "@WristOut", "@WristIn"},
              {"BackTop", "BackLeft", "BackRight", "Chest", "HeadTop", "HeadFront", "HeadSide"}),
       {{"ankle_r", {{"marker", "RAnkleOut"}, {"surface", "lateral"}}}, {"mt_r", {{"mean", {"RToeIn", "RToeOut"}}}}}},
      {"cgm2.4", labels({"@ASI", "@PSI", "@THI", "@KNE", "@KNM", "@TIB", "@ANK", "@MED", "@HEE", "@FMH", "@SMH", "@VMH", "@TOE", "@SHO"}, {"C7", "CLAV"}),
       {{"mt_r", {{"mean", {"RFMH", "RSMH", "RVMH"}}}}, {"hallux_r", {{"marker", "RTOE"}}}}},
      {"human-body-model",
       labels({"@ASIS", "@PSIS", "@GTRO", "@LEK", "@LM", "@HEE", "@MT5", "@TOE", "@SHO", "@LEE", "@MEE", "@LW", "@MW"}, {"C7", "XYPH", "SACR"}),
       {{"knee_r", {{"marker", "RLEK"}, {"surface", "lateral"}}},
        {"ankle_r", {{"marker", "RLM"}, {"surface", "lateral"}}},
        {"mt_r", {{"marker", "RMT5"}, {"surface", "lateral"}}},
        {"hallux_r", {{"marker", "RTOE"}}}}},
      {"ior-gait", labels({"@IAS", "@IPS", "@GT", "@LE", "@ME", "@HF", "@TT", "@LM", "@MM", "@CA", "@FM", "@SM", "@VM"}, {}),
       {{"knee_r", {{"mean", {"RLE", "RME"}}}}, {"heel_r", {{"marker", "RCA"}}}, {"mt_r", {{"mean", {"RFM", "RSM", "RVM"}}}}}},
      {"rris40", labels({"@ASIS", "@PSIS", "@FLE", "@FME", "@TAM", "@FAL", "@FCC", "@FMT1", "@FMT5", "@ACR", "@HLE", "@HME"}, {"C7", "STER"}),
       {{"mt_r", {{"mean", {"RFMT1", "RFMT5"}}}}, {"hallux_r", {{"virtual_hallux", 0.3}}}}},
      {"oxford-foot", labels({"@ASI", "@PSI", "@KNE", "@ANK", "@MMA", "@HEE", "@TOE", "@D1M", "@D5M", "@P1M", "@P5M", "@HLX", "@SHO"}, {}),
       {{"ankle_r", {{"mean", {"RANK", "RMMA"}}}}, {"mt_r", {{"mean", {"RD1M", "RD5M"}}}}, {"hallux_r", {{"marker", "RHLX"}}}}},
      {"a-lab's-own", labels({"@ASIS", "@PSIS", "@IC", "@GT", "@LFC", "@MFC", "@LMA", "@MMA", "@PHE", "@DHE", "@LHE", "@1ST", "@2ND", "@5TH", "@TOE"}, {}),
       {{"heel_r", {{"marker", "RPHE"}}}, {"mt_r", {{"mean", {"R1ST", "R2ND", "R5TH"}}}}, {"shoulder", {{"pelvis_up", 0.5}}}}},
  };
  const auto trajectories = [](const std::vector<std::string>& names) {  // every label holding data
    MarkerTrajectories m;
    m.time_s = Eigen::VectorXd::LinSpaced(20, 0.0, 0.19);
    m.rate_hz = 100;
    for (const auto& l : names) {
      m.names.push_back(l);
      m.descriptions.emplace_back();
      m.positions_m.push_back(Eigen::MatrixX3d::Constant(20, 3, 0.01 * static_cast<double>(m.names.size())));
    }
    return m;
  };
  for (const Set& set : sets) {
    const LabelMapping lm = map_marker_labels(trajectories(set.labels));
    ASSERT_TRUE(lm.mapping) << set.name << ": " << (lm.missing.empty() ? "" : lm.missing[0]);
    const auto& L = (*lm.mapping)["landmarks"];
    for (const auto& [landmark, rule] : set.expect) {
      for (const auto& [k, v] : rule.items()) EXPECT_EQ(L[landmark][k], v) << set.name << " " << landmark << "." << k;
    }
    EXPECT_NO_THROW((void)parse_marker_set(*lm.mapping, "labels")) << set.name;
    const bool waist = set.name == "qualisys-animation" || set.name == "optitrack-baseline-toes";
    EXPECT_EQ(lm.rules[0].find("(waist markers taken as the ASIS and PSIS)") != std::string::npos, waist) << set.name << ": " << lm.rules[0];
  }
  // That lab's lateral heel (RLHE) is not taken for an elbow (the 3D model's arm segments).
  const LabelMapping lm = map_marker_labels(trajectories(sets.back().labels));
  ASSERT_TRUE(lm.mapping);
  EXPECT_FALSE(lm.mapping->contains("upper_body")) << lm.mapping->dump();
}

// A development walk under OptiTrack's labels (Camargo's circuit: its ASIS and PSIS as the
// waist markers, lateral knee and ankle, toe in/out/tip, heel) and Rajagopal's under the Human
// Body Model's: the labels' mapping makes the presets' landmarks, so the estimates are the
// presets' to the last bit.
TEST(MarkerLabels, DevelopmentWalksUnderOtherLabsLabelsAreEstimatedAsTheirPresetsAre) {
  KIN2GRF_REQUIRE_DATA();
  const std::vector<std::tuple<std::string, std::string, double, std::map<std::string, std::string>>> cases = {
      {"/gatech_camargo2021_levelground_fastwalk/levelground_ccw_fast_01_01.trc", "camargo2021", 77.8,
       {{"L_ASIS", "WaistLFront"}, {"R_ASIS", "WaistRFront"}, {"L_PSIS", "WaistLBack"}, {"R_PSIS", "WaistRBack"},
        {"L_Knee_Lat", "LKneeOut"}, {"R_Knee_Lat", "RKneeOut"}, {"L_Ankle_Lat", "LAnkleOut"}, {"R_Ankle_Lat", "RAnkleOut"},
        {"L_Heel", "LHeel"}, {"R_Heel", "RHeel"}, {"L_Toe_Lat", "LToeOut"}, {"R_Toe_Lat", "RToeOut"}, {"L_Toe_Med", "LToeIn"},
        {"R_Toe_Med", "RToeIn"}, {"L_Toe_Tip", "LToeTip"}, {"R_Toe_Tip", "RToeTip"}}},
      {"/rajagopal2016_overground_walk/markers_walk.trc", "rajagopal2016-walk", 85.27,
       {{"R.ASIS", "RASIS"}, {"L.ASIS", "LASIS"}, {"R.PSIS", "RPSIS"}, {"L.PSIS", "LPSIS"}, {"R.Knee", "RLEK"}, {"L.Knee", "LLEK"},
        {"R.Ankle", "RLM"}, {"L.Ankle", "LLM"}, {"R.Heel", "RHEE"}, {"L.Heel", "LHEE"}, {"R.MT5", "RMT5"}, {"L.MT5", "LMT5"},
        {"R.Toe", "RTOE"}, {"L.Toe", "LTOE"}, {"R.Shoulder", "RSHO"}, {"L.Shoulder", "LSHO"}}},
  };
  for (const auto& [file, preset, mass_kg, names] : cases) {
    EstimateOptions o;
    o.mass_kg = mass_kg;
    const Trial t = load_trial(test::data_dir() + file);
    const MarkerSet* set = recognise_marker_set(t.markers);
    ASSERT_NE(set, nullptr) << file;
    ASSERT_EQ(set->name, preset);
    Trial relabelled = t;
    for (auto& n : relabelled.markers.names) n = names.count(n) ? names.at(n) : "other_" + n;
    ASSERT_EQ(recognise_marker_set(relabelled.markers), nullptr) << file;
    const LabelMapping lm = map_marker_labels(relabelled.markers);
    ASSERT_TRUE(lm.mapping) << file << ": " << (lm.missing.empty() ? "" : lm.missing[0]);
    const EstimateResult a = estimate(t, nullptr, *set, o);
    const EstimateResult b = estimate(relabelled, nullptr, parse_marker_set(*lm.mapping, "labels"), o);
    for (int side = 0; side < 2; ++side) {
      ASSERT_EQ(a.feet[side].force_N.rows(), b.feet[side].force_N.rows()) << file;
      EXPECT_EQ(a.feet[side].force_N, b.feet[side].force_N) << file << " side " << side;
      const auto& ca = a.feet[side].cop_x_m.array();
      const auto& cb = b.feet[side].cop_x_m.array();
      EXPECT_TRUE((ca == cb || (ca.isNaN() && cb.isNaN())).all()) << file << " side " << side;
    }
  }
}

namespace {

/// The example walk with its markers renamed as an ISB-minded lab would name them.
Trial isb_labelled_walk() {
  Trial t = make_example_walk();
  const std::map<std::string, std::string> isb = {
      {"RSHO", "RACR"},      {"LSHO", "L_AC"},    {"RHJC", "R_HJC"},  {"LHJC", "HJC_L"}, {"RKJC", "RightKJC"},
      {"LKJC", "L.KJC"},     {"RAJC", "R_AJC"},   {"LAJC", "LAJC"},   {"RHEE", "R_FCC"}, {"LHEE", "L.Heel"},
      {"RMT1", "R_FM1"},     {"LMT1", "LMT1"},    {"RHLX", "R.Toe.Tip"}, {"LHLX", "L_Hallux"}};
  for (auto& n : t.markers.names) n = isb.at(n);
  return t;
}

}  // namespace

// The same walk under other labels: the mapping made from them gives the preset's landmarks, so
// the estimate is the preset's to the last bit; every rule taken is said.
TEST(MarkerLabels, AnISBLabelledWalkIsEstimatedAsItsPresetIs) {
  const Trial walk = make_example_walk();
  const Trial isb = isb_labelled_walk();
  EXPECT_EQ(recognise_marker_set(isb.markers), nullptr);
  Settings s;
  s.trial = "isb.c3d";
  MarkerSet custom;
  std::string why;
  const MarkerSet& set = resolve_marker_set(s, isb, custom, &why);
  EXPECT_EQ(set.name, "labels");
  EXPECT_NE(why.find("no preset recognised"), std::string::npos) << why;
  EXPECT_NE(why.find("knee_r = RightKJC (joint centre)"), std::string::npos) << why;
  EXPECT_NE(why.find("mt_r = R_FM1"), std::string::npos) << why;
  EXPECT_NE(why.find("hallux_l = L_Hallux"), std::string::npos) << why;
  const EstimateResult a = estimate(walk, nullptr, *recognise_marker_set(walk.markers), EstimateOptions{});
  const EstimateResult b = estimate(isb, nullptr, set, EstimateOptions{});
  for (int side = 0; side < 2; ++side) {
    ASSERT_EQ(a.feet[side].force_N.rows(), b.feet[side].force_N.rows());
    EXPECT_TRUE(a.feet[side].force_N.isApprox(b.feet[side].force_N, 1e-12)) << "side " << side;
  }
  // Asked for by name, the labels' mapping is made even where a preset matches.
  s.markers = "labels";
  EXPECT_EQ(resolve_marker_set(s, walk, custom).name, "labels");
}

// A landmark no label gives is named, with the spellings looked for, and the file; what was found
// is listed beside it. An empty label (a lower-body capture's trunk) does not count as present.
TEST(MarkerLabels, AMissingLandmarkIsNamedWithTheFileAndTheSpellingsLookedFor) {
  Trial isb = isb_labelled_walk();
  for (auto& n : isb.markers.names)
    if (n == "RightKJC") n = "R_knee_thing";
  const std::size_t sho = static_cast<std::size_t>(isb.markers.find("RACR"));
  isb.markers.positions_m[sho].setConstant(std::nan(""));
  const LabelMapping lm = map_marker_labels(isb.markers);
  EXPECT_FALSE(lm.mapping);
  ASSERT_EQ(lm.missing.size(), 2u);
  EXPECT_EQ(lm.missing[0].rfind("knee_r: no joint centre (kjc", 0), 0u) << lm.missing[0];
  EXPECT_EQ(lm.missing[1].rfind("shoulder: no acromion markers", 0), 0u) << lm.missing[1];
  // The acromion's label is in the file but empty: named with its count, so that the error does
  // not read as if the label were absent.
  const std::string racr = "RACR (0 of " + std::to_string(isb.markers.frames()) + " frames)";
  EXPECT_NE(std::find(lm.too_few.begin(), lm.too_few.end(), racr), lm.too_few.end());
  // The draft to complete by hand: what was found, and a placeholder naming what was not.
  EXPECT_EQ(lm.draft["landmarks"]["ankle_r"]["marker"], "R_AJC");
  EXPECT_EQ(lm.draft["landmarks"]["knee_r"]["marker"].get<std::string>().rfind("FILL IN: knee_r: no joint centre", 0), 0u);
  Settings s;
  s.trial = "isb.c3d";
  MarkerSet custom;
  try {
    (void)resolve_marker_set(s, isb, custom);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("isb.c3d"), std::string::npos) << what;
    EXPECT_NE(what.find("knee_r: no joint centre"), std::string::npos) << what;
    EXPECT_NE(what.find("ankle_r = R_AJC"), std::string::npos) << what;
    EXPECT_NE(what.find("Left out for holding samples in too few"), std::string::npos) << what;
    EXPECT_NE(what.find(racr), std::string::npos) << what;
  }
}

// The rules a biomechanist writes by hand: lateral and medial markers averaged, a lateral one
// alone marked as on the skin, the metatarsal heads averaged, a Plug-in Gait TOE on the 2nd MT
// head with virtual toes, the pelvis by Harrington from ASIS and sacrum, an upright torso when no
// trunk marker holds data; two labels for one place: the better-seen one, said.
TEST(MarkerLabels, MakesTheRulesABiomechanistWouldWrite) {
  MarkerTrajectories m;
  const Eigen::Index n = 40;
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, 0.39);
  m.rate_hz = 100;
  const auto add = [&](const std::string& name, long frames) {
    m.names.push_back(name);
    m.descriptions.emplace_back();
    Eigen::MatrixX3d p = Eigen::MatrixX3d::Constant(n, 3, 0.1 * static_cast<double>(m.names.size()));
    p.bottomRows(n - frames).setConstant(std::nan(""));
    m.positions_m.push_back(p);
  };
  for (const char* x : {"RASI", "LASI", "SACR", "RKNE", "RKNM", "LKNE", "RANK", "LANK", "LMED", "RHEE", "LHEE", "R_MT1", "R_MT5",
                        "RMT2", "LTOE", "RTOE"})
    add(x, n);
  add("R.Heel", 30);  // a second heel label, seen less
  add("RSHO", 0);     // a lower-body capture's empty trunk labels
  add("LSHO", 0);
  const LabelMapping lm = map_marker_labels(m);
  ASSERT_TRUE(lm.mapping) << (lm.missing.empty() ? "" : lm.missing[0]);
  const auto& L = (*lm.mapping)["landmarks"];
  EXPECT_EQ(L["hip"]["harrington"]["sacrum"], "SACR");
  EXPECT_EQ(L["knee_r"]["mean"], nlohmann::json({"RKNE", "RKNM"}));
  EXPECT_EQ(L["knee_l"]["surface"], "lateral");
  EXPECT_EQ(L["ankle_l"]["mean"], nlohmann::json({"LANK", "LMED"}));
  EXPECT_EQ(L["heel_r"]["marker"], "RHEE");
  EXPECT_EQ(L["mt_r"]["mean"], nlohmann::json({"R_MT1", "RMT2", "R_MT5"}));
  EXPECT_EQ(L["hallux_r"]["marker"], "RTOE");  // a toe ahead of MT markers is a toe
  EXPECT_EQ(L["mt_l"]["marker"], "LTOE");       // a toe with no MT marker is Plug-in Gait's
  EXPECT_TRUE(L["hallux_l"].contains("virtual_hallux"));
  EXPECT_EQ(L["shoulder"]["pelvis_up"], 0.5);
  ASSERT_EQ(lm.notes.size(), 1u);
  EXPECT_EQ(lm.notes[0], "heel (r): RHEE taken (most frames) over R.Heel");
  EXPECT_NO_THROW((void)parse_marker_set(*lm.mapping, "labels"));
}

// A virtual point calibrated on a static trial is carried by its cluster's least-squares pose
// (fit_cluster): with a rigid cluster it is exact, and with skin motion on every cluster marker
// (up to 6 mm, each its own way) it is the same whatever order a mapping lists the cluster in, and
// stays within the orientation error's reach of the true knee. The axes of the cluster's first two markers moved
// the knee by the order (Rajagopal's run: anterior 9.7-19.6 % over the six orders of its clusters).
TEST(Landmarks, AStaticPointIsCarriedByItsWholeClusterInAnyOrder) {
  const Eigen::Vector3d th_local[] = {{0.05, 0.08, 0.15}, {-0.04, 0.07, 0.22}, {0.02, 0.09, 0.30}, {0.06, 0.05, 0.26}};
  const auto make = [&](int n, double skin_m, bool moving) {
    MarkerTrajectories m;
    m.rate_hz = 100;
    m.time_s = Eigen::VectorXd::LinSpaced(n, 0, (n - 1) / 100.0);
    m.up_axis = Axis::Z;
    for (const char* nm : {"TH1", "TH2", "TH3", "TH4", "KLAT", "KMED"}) {
      m.names.emplace_back(nm);
      m.descriptions.emplace_back();
      m.positions_m.emplace_back(n, 3);
    }
    Eigen::MatrixX3d knee(n, 3);
    for (int i = 0; i < n; ++i) {
      const double t = m.time_s[i];
      const Eigen::Vector3d hip(moving ? 0.8 * t : 0.0, 0.0, 0.9);
      const Eigen::Matrix3d Rt =
          Eigen::AngleAxisd(moving ? 0.4 * std::sin(2 * M_PI * 0.9 * t) : 0.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
      const Eigen::Vector3d k = hip + Rt * Eigen::Vector3d(0, 0, -0.44);
      knee.row(i) = k.transpose();
      for (int j = 0; j < 4; ++j) {
        const Eigen::Vector3d skin = skin_m * std::sin(2 * M_PI * (1.3 + 0.4 * j) * t + j) * Eigen::Vector3d(1.0, 0.5 * j - 0.7, 0.3).normalized();
        m.positions_m[static_cast<std::size_t>(j)].row(i) = (k + Rt * th_local[j] + skin).transpose();
      }
      m.positions_m[4].row(i) = (k + Rt * Eigen::Vector3d(0, 0.05, 0)).transpose();
      m.positions_m[5].row(i) = (k + Rt * Eigen::Vector3d(0, -0.05, 0)).transpose();
    }
    return std::make_pair(m, knee);
  };
  const auto set_with = [](const std::vector<std::string>& cluster) {
    nlohmann::json j = {{"name", "t"}, {"landmarks", nlohmann::json::object()}};
    for (const char* id : {"shoulder", "hip", "knee_r", "ankle_r", "heel_r", "mt_r", "hallux_r", "knee_l", "ankle_l", "heel_l", "mt_l",
                           "hallux_l"})
      j["landmarks"][id] = std::string(id) == "knee_r" ? nlohmann::json{{"static", {"KLAT", "KMED"}}, {"cluster", cluster}}
                                                      : nlohmann::json{{"marker", "TH1"}};
    return parse_marker_set(j, "test");
  };
  const auto [still, unused] = make(20, 0.0, false);
  {
    // Without the static trial: an error naming what to give, and the way without one.
    const auto [walk, knee] = make(30, 0.0, true);
    try {
      (void)compute_landmarks(set_with({"TH1", "TH2", "TH3", "TH4"}), walk, nullptr, {}, "synthetic");
      ADD_FAILURE() << "no error without the static trial";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("knee_r"), std::string::npos) << what;
      EXPECT_NE(what.find("give --static STATIC (it needs markers KLAT, KMED)"), std::string::npos) << what;
      EXPECT_NE(what.find("--markers labels"), std::string::npos) << what;
    }
  }
  for (const double skin : {0.0, 0.006}) {
    const auto [walk, knee] = make(300, skin, true);
    const Landmarks3D a = compute_landmarks(set_with({"TH1", "TH2", "TH3", "TH4"}), walk, &still, {}, "synthetic");
    const Landmarks3D b = compute_landmarks(set_with({"TH3", "TH4", "TH2", "TH1"}), walk, &still, {}, "synthetic");
    const auto &Ka = a.p[landmark(kRight, kKnee)], &Kb = b.p[landmark(kRight, kKnee)];
    for (int i = 0; i < 300; i += 7) {
      EXPECT_LT((Ka.row(i) - Kb.row(i)).norm(), 1e-9) << "skin " << skin << ", frame " << i;
      // An orientation error of about skin / the cluster's size (about 0.1 m), times the knee's
      // lever from the cluster (0.15-0.3 m): up to about three times the skin motion.
      EXPECT_LT((Ka.row(i) - knee.row(i)).norm(), skin > 0 ? 3 * skin : 1e-9) << "skin " << skin << ", frame " << i;
    }
  }
}

// Where the motion trial has no joint centre and no lateral-medial pair, the labels' mapping takes
// the static trial's pair (carried by the thigh's or the shank's cluster), even over a lateral
// marker, and, without a static trial, the lateral marker or else the functional centre of the
// clusters on either side of the joint.
TEST(MarkerLabels, JointsOffTheMotionTrialComeFromTheStaticTrialOrFromTheirClusters) {
  const auto trajectories = [](const std::vector<std::string>& names) {
    MarkerTrajectories m;
    m.time_s = Eigen::VectorXd::LinSpaced(30, 0.0, 0.29);
    m.rate_hz = 100;
    for (const auto& name : names) {
      m.names.push_back(name);
      m.descriptions.emplace_back();
      m.positions_m.push_back(Eigen::MatrixX3d::Constant(30, 3, 0.1 * static_cast<double>(m.names.size())));
    }
    return m;
  };
  std::vector<std::string> motion = {"RASI", "LASI", "RPSI", "LPSI", "RACR", "LACR", "RKNE"};
  for (const char* s : {"R", "L"})
    for (const char* x : {"TH1", "TH2", "TH3", "TB1", "TB2", "TB3", "CAL", "MT1", "MT5"}) motion.push_back(std::string(s) + x);
  const MarkerTrajectories m = trajectories(motion);
  std::vector<std::string> still = motion;
  still.erase(std::find(still.begin(), still.end(), "RKNE"));  // the static trial has the epicondyles instead
  for (const char* x : {"R_FLE", "R_FME", "R_FAL", "R_TAM", "L_FLE", "L_FME", "L_FAL", "L_TAM"}) still.push_back(x);
  const MarkerTrajectories st = trajectories(still);

  const LabelMapping with = map_marker_labels(m, &st);
  ASSERT_TRUE(with.mapping) << (with.missing.empty() ? "" : with.missing[0]);
  const auto& L = (*with.mapping)["landmarks"];
  EXPECT_EQ(L["knee_r"]["static"], nlohmann::json({"R_FLE", "R_FME"}));
  EXPECT_EQ(L["knee_r"]["cluster"], nlohmann::json({"RTH1", "RTH2", "RTH3"}));
  EXPECT_EQ(L["ankle_l"]["static"], nlohmann::json({"L_FAL", "L_TAM"}));
  EXPECT_EQ(L["ankle_l"]["cluster"], nlohmann::json({"LTB1", "LTB2", "LTB3"}));

  const LabelMapping without = map_marker_labels(m);
  ASSERT_TRUE(without.mapping);
  const auto& F = (*without.mapping)["landmarks"];
  EXPECT_EQ(F["knee_r"]["marker"], "RKNE");  // a lateral marker beats a functional centre; the static pair beats both (above)
  EXPECT_EQ(F["knee_r"]["surface"], "lateral");
  EXPECT_EQ(F["knee_l"]["functional"]["distal"], nlohmann::json({"LTB1", "LTB2", "LTB3"}));
  EXPECT_EQ(F["ankle_r"]["functional"]["proximal"], nlohmann::json({"RTB1", "RTB2", "RTB3"}));
  EXPECT_EQ(F["ankle_r"]["functional"]["distal"], nlohmann::json({"RCAL", "RMT1", "RMT5"}));
  EXPECT_NO_THROW((void)parse_marker_set(*without.mapping, "labels"));
}

// Labels are the file's, so anything: empty, a lone side letter, separators only, non-ASCII
// bytes, a label of 100,000 characters. None is read as a landmark, and none throws.
TEST(MarkerLabels, ALabelOfAnyShapeIsReadWithoutGuessing) {
  for (const std::string& label : {std::string(), std::string("R"), std::string("L."), std::string("_"), std::string("..::--"),
                                   std::string("RL"), std::string("\xC5\x94KNE"), std::string("R\xFFKNE"), std::string(100000, 'R'),
                                   std::string("Right"), std::string("Left_"), std::string("R#2")}) {
    MarkerLabel l;
    EXPECT_NO_THROW(l = read_marker_label(label));
    EXPECT_TRUE(l.landmark.empty()) << label.substr(0, 20);
  }
  EXPECT_EQ(read_marker_label("R.KNE.").landmark, "knee_lateral");  // trailing separators are separators
}

// Which presets' knee points follow the bone (the thigh lag's condition, EstimateOptions::
// thigh_lag_s): a marker on an epicondyle, or a joint centre made of markers, does; a point a thigh
// cluster carries (static calibration, a functional centre) does not.
TEST(Landmarks, AKneePointFollowsTheBoneUnlessAClusterCarriesIt) {
  for (const char* name : {"plug-in-gait", "plug-in-gait-lower", "camargo2021", "rajagopal2016-walk", "opencap-lab", "fullbody-2009",
                           "kin2grf-example"}) {
    const MarkerSet* set = find_marker_set(name);
    ASSERT_NE(set, nullptr) << name;
    for (int side = 0; side < 2; ++side) EXPECT_TRUE(follows_the_bone(set->rules[landmark(side, kKnee)].kind)) << name;
  }
  for (const char* name : {"opensim-gait2354", "rajagopal2016-run", "fukuchi2017-running", "uwa-fullbody"}) {
    const MarkerSet* set = find_marker_set(name);
    ASSERT_NE(set, nullptr) << name;
    for (int side = 0; side < 2; ++side) EXPECT_FALSE(follows_the_bone(set->rules[landmark(side, kKnee)].kind)) << name;
  }
}

namespace {
// A rigid foot-like body of four markers turning and travelling (0.6 rad of pitch, 0.3 rad of yaw,
// 1 m forward over 2 s at 100 Hz), and one marker across a "joint" swinging 0.5 rad against it.
MarkerTrajectories rigid_body_walk() {
  MarkerTrajectories m;
  const Eigen::Index n = 200;
  m.rate_hz = 100.0;
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, 1.99);
  m.names = {"HEEL", "MT1", "MT5", "TOE", "SHANK"};
  m.descriptions.assign(m.names.size(), "");
  const std::vector<Eigen::Vector3d> body = {{0.0, 0.0, 0.03}, {0.18, 0.03, 0.02}, {0.16, -0.04, 0.02}, {0.24, 0.01, 0.01}};
  m.positions_m.assign(m.names.size(), Eigen::MatrixX3d(n, 3));
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = m.time_s[i];
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.3 * std::sin(2.0 * t), Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.6 * std::sin(3.0 * t), Eigen::Vector3d::UnitY()))
                                  .toRotationMatrix();
    const Eigen::Vector3d o(0.5 * t, 0.1, 0.05 + 0.04 * std::sin(5.0 * t));
    for (std::size_t k = 0; k < body.size(); ++k) m.positions_m[k].row(i) = (R * body[k] + o).transpose();
    const Eigen::Matrix3d swing = Eigen::AngleAxisd(0.5 * std::sin(4.0 * t), Eigen::Vector3d::UnitY()).toRotationMatrix();
    m.positions_m[4].row(i) = (R * (Eigen::Vector3d(0.05, 0.0, 0.1) + swing * Eigen::Vector3d(0.0, 0.0, 0.3)) + o).transpose();
  }
  return m;
}
}  // namespace

// A marker lost for 0.4 s inside the trial (a heel hidden by the other foot) is filled from the
// three markers that move rigidly with it, exactly for a rigid body, and the message names them;
// the marker swinging across the "joint" is not taken. The same gap at the trial's end (the
// subject leaving the volume: no data after it) is not filled.
TEST(Landmarks, ALongGapIsFilledFromTheMarkersThatMoveRigidlyWithIt) {
  const MarkerTrajectories truth = rigid_body_walk();
  MarkerTrajectories m = truth;
  m.positions_m[0].middleRows(80, 40).setConstant(std::numeric_limits<double>::quiet_NaN());
  m.positions_m[0].bottomRows(30).setConstant(std::numeric_limits<double>::quiet_NaN());
  ASSERT_TRUE(has_long_marker_gap(m, {"HEEL"}, 10));
  std::vector<std::string> messages;
  EXPECT_EQ(fill_marker_gaps_rigidly(m, {"HEEL"}, 10, messages), 1U);
  EXPECT_LT((m.positions_m[0].middleRows(80, 40) - truth.positions_m[0].middleRows(80, 40)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_FALSE(m.positions_m[0].bottomRows(30).allFinite());  // the end's gap stays
  ASSERT_EQ(messages.size(), 1U);
  EXPECT_NE(messages[0].find("HEEL: filled a gap of 40 frames at frames 81-120"), std::string::npos) << messages[0];
  for (const char* partner : {"MT1", "MT5", "TOE"}) EXPECT_NE(messages[0].find(partner), std::string::npos) << messages[0];
  EXPECT_EQ(messages[0].find("SHANK"), std::string::npos) << messages[0];
  // A gap no longer than the cubic fill's reach is left to it.
  MarkerTrajectories shortgap = truth;
  shortgap.positions_m[0].middleRows(80, 10).setConstant(std::numeric_limits<double>::quiet_NaN());
  EXPECT_FALSE(has_long_marker_gap(shortgap, {"HEEL"}, 10));
}

// With only two markers moving rigidly with it (the third lost with it), the gap is not guessed
// from a marker across a joint: it is left, and the markers are unchanged.
TEST(Landmarks, AGapWithoutThreeRigidPartnersIsLeft) {
  MarkerTrajectories m = rigid_body_walk();
  m.positions_m[0].middleRows(80, 40).setConstant(std::numeric_limits<double>::quiet_NaN());
  m.positions_m[3].middleRows(70, 60).setConstant(std::numeric_limits<double>::quiet_NaN());
  const MarkerTrajectories before = m;
  std::vector<std::string> messages;
  EXPECT_EQ(fill_marker_gaps_rigidly(m, {"HEEL"}, 10, messages), 0U);
  EXPECT_TRUE(messages.empty());
  EXPECT_FALSE(m.positions_m[0].middleRows(80, 40).allFinite());
  EXPECT_TRUE(m.positions_m[3].middleRows(0, 70).isApprox(before.positions_m[3].middleRows(0, 70)));
}

// Several gaps in one call (a long trial's occlusions, the markers' distances measured once for
// all of them) are filled as each would be alone, whichever marker they belong to.
TEST(Landmarks, ManyGapsAreFilledAsEachAlone) {
  const MarkerTrajectories truth = rigid_body_walk();
  MarkerTrajectories all = truth;
  const std::vector<std::pair<std::size_t, Eigen::Index>> gaps{{0, 30}, {0, 90}, {1, 60}, {3, 140}};
  for (const auto& [k, first] : gaps) all.positions_m[k].middleRows(first, 15).setConstant(std::numeric_limits<double>::quiet_NaN());
  const MarkerTrajectories given = all;
  std::vector<std::string> messages;
  ASSERT_EQ(fill_marker_gaps_rigidly(all, {}, 10, messages), gaps.size());
  for (const auto& [k, first] : gaps) {
    MarkerTrajectories one = given;
    std::vector<std::string> none;
    // The other gaps left as they are, this one alone asked for: the same partners, the same fill.
    fill_marker_gaps_rigidly(one, {truth.names[k]}, 10, none);
    EXPECT_TRUE(one.positions_m[k].middleRows(first, 15).isApprox(all.positions_m[k].middleRows(first, 15), 1e-12)) << truth.names[k];
    EXPECT_LT((all.positions_m[k].middleRows(first, 15) - truth.positions_m[k].middleRows(first, 15)).cwiseAbs().maxCoeff(), 1e-9);
  }
}
