// Tests of validation/study: parameter studies and leave-one-lab-out.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
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
#include "kin2grf/workflow/batch.hpp"
#include "kin2grf/workflow/trial_list.hpp"
#include "kin2grf/validation/metrics.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"
#include "test_support.hpp"

using namespace kin2grf;

namespace {
StudyTrialResult fake_trial(const char* name, const char* lab, double rrmse) {
  StanceValidation st;
  SeriesMetrics m;
  m.rrmse_percent = rrmse;
  st.metrics.vertical = st.metrics.anterior = st.metrics.cop = m;
  return StudyTrialResult{name, "walking", lab, {st}, std::nan(""), false};
}
}  // namespace

// The criterion's vertical force: over each plate's stance, or over the loaded span (a foot loaded
// before its plate's onset counted). Lab A's stances agree either way; lab B's "early" setting
// loads its feet early (span 9 against stance 3), so the plate-stance criterion prefers it and the
// loaded-span criterion does not.
TEST(Study, TheCriterionTakesTheVerticalOverTheLoadedSpanWhenAsked) {
  auto trial = [](const char* name, const char* lab, double vertical, double span) {
    StudyTrialResult t = fake_trial(name, lab, 5);
    SeriesMetrics v, sp;
    v.rrmse_percent = vertical, sp.rrmse_percent = span;
    t.stances[0].metrics.vertical = v;
    t.stances[0].vertical_loaded_span = sp;
    return t;
  };
  StudyResult s;
  s.kind = "test";
  s.rows = {{"early", 0, false, {}}, {"on time", 1, true, {}}};
  s.per_trial = {{trial("a1", "A", 5, 5), trial("b1", "B", 3, 9)}, {trial("a1", "A", 5, 5), trial("b1", "B", 4, 4)}};
  EXPECT_EQ(cross_validate(s).in_sample_choice, "early");
  const CrossValidation span = cross_validate(s, CrossValidation::Vertical::LoadedSpan);
  EXPECT_EQ(span.in_sample_choice, "on time");
  EXPECT_NEAR(span.default_criterion, ((5 + 5 + 5) / 3.0 + (4 + 5 + 5) / 3.0) / 2, 1e-12);
  EXPECT_NE(format_cross_validation(s, span).find("loaded span"), std::string::npos);
  EXPECT_EQ(parse_criterion("loaded-span"), CrossValidation::Vertical::LoadedSpan);
  EXPECT_EQ(parse_criterion("plate-stance"), CrossValidation::Vertical::PlateStance);
  EXPECT_THROW((void)parse_criterion("span"), InputError);
}

// Leave-one-lab-out: lab A fits setting "low", labs B and C fit "high". In-sample picks "high"
// (two labs of three); with B or C held out, the other two labs tie and the first setting is kept,
// so B and C are scored at "low" and A at "high": the held-out figure shows what a lab unlike the
// others would meet, where the in-sample one hides it.
TEST(Study, LeaveOneLabOutScoresEachLabAtTheOthersChoice) {
  StudyResult s;
  s.kind = "test";
  s.rows = {{"low", 0, false, {}}, {"high", 1, false, {}}};
  s.per_trial = {{fake_trial("a1", "A", 2), fake_trial("b1", "B", 10), fake_trial("c1", "C", 10)},
                 {fake_trial("a1", "A", 8), fake_trial("b1", "B", 4), fake_trial("c1", "C", 4)}};
  const CrossValidation cv = cross_validate(s);
  EXPECT_EQ(cv.in_sample_choice, "high");
  ASSERT_EQ(cv.lab_choice.size(), 3u);
  EXPECT_EQ(cv.lab_choice[0].second, "high");  // without A
  EXPECT_EQ(cv.lab_choice[1].second, "low");   // without B: A (2) + C (10) = 6 against A (8) + C (4) = 6: tie, first kept
  EXPECT_EQ(cv.lab_choice[2].second, "low");
  ASSERT_EQ(cv.cells.size(), 1u);
  EXPECT_NEAR(cv.cells[0].in_sample.vertical, (8 + 4 + 4) / 3.0, 1e-12);
  EXPECT_NEAR(cv.cells[0].held_out.vertical, (8 + 10 + 10) / 3.0, 1e-12);  // worse than in-sample, as it should be
  EXPECT_EQ(cv.cells[0].worst_trial, "b1");
  // The figure a default changes by: each lab's criterion at its held-out choice, the mean over
  // labs (here one stance a lab, all three components alike); no row is the default here.
  EXPECT_NEAR(cv.held_out_criterion, (8 + 10 + 10) / 3.0, 1e-12);
  EXPECT_TRUE(std::isnan(cv.default_criterion));
  s.rows[1].is_default = true;
  EXPECT_NEAR(cross_validate(s).default_criterion, (8 + 4 + 4) / 3.0, 1e-12);
  EXPECT_NE(format_cross_validation(s, cross_validate(s)).find("held-out criterion"), std::string::npos);
  // One lab only: refused with a message that says how to name labs.
  StudyResult one = s;
  for (auto& row : one.per_trial)
    for (auto& t : row) t.lab.assign(1, 'A');
  EXPECT_THROW((void)cross_validate(one), InputError);
}

// A default changes only when the figure improves: where the other labs cannot tell the settings
// apart (a split distance on trials whose feet are never side by side), the held-out lab gets
// kin2grf's default, not the lowest setting; where they can, the best setting wins, default or not.
TEST(Study, ATieKeepsTheDefaultAndABetterSettingStillWins) {
  StudyResult s;
  s.kind = "test";
  s.rows = {{"off", 0, false, {}}, {"on", 1, true, {}}};
  // Lab A is helped by "on"; labs B and C do not care.
  s.per_trial = {{fake_trial("a1", "A", 30), fake_trial("b1", "B", 5), fake_trial("c1", "C", 7)},
                 {fake_trial("a1", "A", 10), fake_trial("b1", "B", 5), fake_trial("c1", "C", 7)}};
  const CrossValidation cv = cross_validate(s);
  EXPECT_EQ(cv.in_sample_choice, "on");
  ASSERT_EQ(cv.lab_choice.size(), 3u);
  EXPECT_EQ(cv.lab_choice[0].second, "on") << "without A the labs tie, and the default stays";
  EXPECT_EQ(cv.lab_choice[1].second, "on");
  EXPECT_NEAR(cv.cells[0].held_out.vertical, (10 + 5 + 7) / 3.0, 1e-12);
  // With "off" the default, B and C still tie without A, so A is scored at "off"; with A in, "on" wins.
  s.rows[0].is_default = true, s.rows[1].is_default = false;
  const CrossValidation cv2 = cross_validate(s);
  EXPECT_EQ(cv2.in_sample_choice, "on");
  EXPECT_EQ(cv2.lab_choice[0].second, "off");
  EXPECT_NEAR(cv2.cells[0].held_out.vertical, (30 + 5 + 7) / 3.0, 1e-12);
}

// A study runs every setting on every trial, and its centre row is what validate gives with the
// default; an unknown kind is refused by name.
TEST(Study, EachSettingRunsOnEveryTrialAndTheDefaultRowIsValidates) {
  const Trial walk = make_example_walk();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  std::vector<StudyTrial> trials(2);
  for (int k = 0; k < 2; ++k) {
    trials[static_cast<std::size_t>(k)].name = k ? "walk-b" : "walk-a";
    trials[static_cast<std::size_t>(k)].activity = "walking";
    trials[static_cast<std::size_t>(k)].lab = k ? "lab-b" : "lab-a";
    trials[static_cast<std::size_t>(k)].trial = &walk;
    trials[static_cast<std::size_t>(k)].plates = &*walk.plates;
    trials[static_cast<std::size_t>(k)].marker_set = &set;
  }
  const StudyResult s = run_study("ground-shift", trials);
  ASSERT_EQ(s.rows.size(), 3u);  // -10, 0, +10 mm
  ASSERT_EQ(s.per_trial.size(), 3u);
  EXPECT_TRUE(s.failures.empty());
  EXPECT_FALSE(s.rows[0].is_default);
  EXPECT_TRUE(s.rows[1].is_default) << "0 mm is kin2grf's default";
  EXPECT_FALSE(s.rows[2].is_default);
  const auto direct = validate(estimate(walk, nullptr, set, EstimateOptions{}), *walk.plates, ValidationOptions{});
  for (const auto& r : s.per_trial[1]) {
    ASSERT_EQ(r.stances.size(), direct.stances.size()) << r.name;
    for (std::size_t k = 0; k < r.stances.size(); ++k) {
      ASSERT_TRUE(r.stances[k].metrics.vertical && direct.stances[k].metrics.vertical);
      EXPECT_DOUBLE_EQ(r.stances[k].metrics.vertical->rrmse_percent, direct.stances[k].metrics.vertical->rrmse_percent);
    }
  }
  EXPECT_THROW((void)run_study("no-such-study", trials), InputError);
}

// A study varies one setting. The speed gate's ratio was once crossed with its floor: a held-out
// lab whose trials could not tell the floors apart then had that tie broken by the grid's order
// (two non-default rows tie; neither is the default), which cost the one trial that could. The
// ratio's study keeps the floor at its default and the floor has its own study from its row.
TEST(Study, TheSpeedGateRatioAndFloorAreStudiedApart) {
  const Trial walk = make_example_walk();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  StudyTrial t;
  t.name = "walk";
  t.activity = "walking";
  t.lab = "lab";
  t.trial = &walk;
  t.plates = &*walk.plates;
  t.marker_set = &set;
  const StudyResult ratio = run_study("speed-gate-ratio", {t});
  ASSERT_EQ(ratio.rows.size(), 7u);  // the fixed 1.5 m/s and six ratios
  int defaults = 0;
  for (const auto& r : ratio.rows) {
    EXPECT_EQ(r.label.find(">="), std::string::npos) << r.label << ": the floor is not this study's";
    if (!r.is_default) continue;
    ++defaults;
    EXPECT_EQ(r.label, "0.7 x speed");
  }
  EXPECT_EQ(defaults, 1);
  const StudyResult floor = run_study("speed-gate-floor", {t});
  ASSERT_EQ(floor.rows.size(), 5u);
  for (const auto& r : floor.rows) EXPECT_EQ(r.is_default, r.label == "0.75 m/s") << r.label;
}

// The noise study pools 8 seeded draws per level (one draw measures its seed as much as the
// method): the 0 mm row is validate itself, the 2 mm row holds 8 times its stances, and the draws
// differ (the same draw eight times would repeat one stance's figure).
TEST(Study, NoiseStudyPoolsEightDistinctDraws) {
  const Trial walk = make_example_walk();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  StudyTrial t;
  t.name = "walk", t.activity = "walking", t.trial = &walk, t.plates = &*walk.plates, t.marker_set = &set;
  const StudyResult s = run_study("noise", {t});
  ASSERT_EQ(s.rows.size(), 4u);  // 0, 1, 2, 3 mm
  ASSERT_TRUE(s.failures.empty());
  const std::size_t clean = s.per_trial[0][0].stances.size();
  ASSERT_GT(clean, 0u);
  const auto& noisy = s.per_trial[2][0].stances;
  ASSERT_EQ(noisy.size(), 8 * clean);
  ASSERT_TRUE(noisy[0].metrics.vertical && noisy[clean].metrics.vertical);
  EXPECT_NE(noisy[0].metrics.vertical->rrmse_percent, noisy[clean].metrics.vertical->rrmse_percent);
}

// The marker-rate study decimates the markers (every k-th frame, each at its own time) and keeps
// the plates: the example walk's 100 Hz row is validate itself, its 50 Hz row holds the same
// stances, and each stance stays within two points of vertical rRMSE (the pipeline measures time in
// seconds: a rule counting frames would move the 50 Hz row by far more).
TEST(Study, MarkerRateStudyDecimatesTheMarkersAndKeepsThePlates) {
  const Trial walk = make_example_walk();
  ASSERT_NEAR(walk.markers.rate_hz, 100.0, 1e-9);
  const MarkerTrajectories half = decimated(walk.markers, 2);
  EXPECT_EQ(half.frames(), (walk.markers.frames() + 1) / 2);
  EXPECT_DOUBLE_EQ(half.rate_hz, 50.0);
  EXPECT_DOUBLE_EQ(half.time_s[3], walk.markers.time_s[6]);
  EXPECT_TRUE(half.positions_m[0].row(3).isApprox(walk.markers.positions_m[0].row(6)));
  EXPECT_THROW((void)decimated(walk.markers, 0), InputError);
  // Frame numbers count the slower capture's frames: a file starting at frame 101 at 100 Hz
  // starts at frame 51 at 50 Hz (the same time, 1.0 s), so row 3 is frame 54, not 104.
  MarkerTrajectories late = walk.markers;
  late.first_frame = 101;
  EXPECT_EQ(decimated(late, 2).first_frame, 51);
  EXPECT_EQ(decimated(late, 4).first_frame, 26);
  EXPECT_EQ(decimation_factor(250.0, 60.0), 4);
  EXPECT_EQ(decimation_factor(100.0, 100.0), 1);
  EXPECT_EQ(decimation_factor(60.0, 100.0), 1) << "never upsampled";

  const MarkerSet& set = *find_marker_set("kin2grf-example");
  StudyTrial t;
  t.name = "walk", t.activity = "walking", t.lab = "lab", t.trial = &walk, t.plates = &*walk.plates, t.marker_set = &set;
  const StudyResult s = run_study("marker-rate", {t});
  ASSERT_EQ(s.rows.size(), 4u);  // as recorded, about 100, 60 and 50 Hz
  ASSERT_TRUE(s.failures.empty());
  EXPECT_TRUE(s.rows[0].is_default);
  const auto& recorded = s.per_trial[0][0].stances;
  const auto& at100 = s.per_trial[1][0].stances;
  const auto& at50 = s.per_trial[3][0].stances;
  ASSERT_GT(recorded.size(), 0u);
  ASSERT_EQ(at100.size(), recorded.size());
  ASSERT_EQ(at50.size(), recorded.size());
  for (std::size_t k = 0; k < recorded.size(); ++k) {
    ASSERT_TRUE(recorded[k].metrics.vertical && at100[k].metrics.vertical && at50[k].metrics.vertical);
    EXPECT_DOUBLE_EQ(at100[k].metrics.vertical->rrmse_percent, recorded[k].metrics.vertical->rrmse_percent);
    EXPECT_NE(at50[k].metrics.vertical->rrmse_percent, recorded[k].metrics.vertical->rrmse_percent);
    EXPECT_NEAR(at50[k].metrics.vertical->rrmse_percent, recorded[k].metrics.vertical->rrmse_percent, 2.0) << "stance " << k;
  }
}

// A trial cut short (cropped, --frames, the trial-cut study): each kept frame keeps its time and
// its file frame number; a range outside the recording is refused, naming its frames. Cut to its
// plates' loaded span and 0.2-1.0 s around it, the example walk keeps every plate stance, each
// within a point of its vertical rRMSE as recorded (the ground, the foot-flat reference and the
// speed are measured again from fewer frames), while the window really starts later.
TEST(Study, TrialCutStudyCropsTheMarkersAroundThePlatesLoad) {
  const Trial walk = make_example_walk();
  const MarkerTrajectories part = cropped(walk.markers, 10, 50);
  EXPECT_EQ(part.frames(), 50);
  EXPECT_EQ(part.first_frame, walk.markers.first_frame + 10);
  EXPECT_DOUBLE_EQ(part.time_s[0], walk.markers.time_s[10]);
  EXPECT_TRUE(part.positions_m[0].row(49).isApprox(walk.markers.positions_m[0].row(59)));
  EXPECT_THROW((void)cropped(walk.markers, -1, 10), InputError);
  EXPECT_THROW((void)cropped(walk.markers, 0, 0), InputError);
  try {
    (void)cropped(walk.markers, walk.markers.frames() - 5, 10);
    ADD_FAILURE() << "a range past the recording's end was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not within the recording's frames"), std::string::npos) << e.what();
  }

  const MarkerSet& set = *find_marker_set("kin2grf-example");
  StudyTrial t;
  t.name = "walk", t.activity = "walking", t.lab = "lab", t.trial = &walk, t.plates = &*walk.plates, t.marker_set = &set;
  const StudyResult s = run_study("trial-cut", {t});
  ASSERT_EQ(s.rows.size(), 5u);  // as recorded, then +-1.0, 0.5, 0.3 and 0.2 s around the plates' load
  ASSERT_TRUE(s.failures.empty()) << s.failures.front();
  EXPECT_TRUE(s.rows[0].is_default);
  const auto& recorded = s.per_trial[0][0].stances;
  ASSERT_GT(recorded.size(), 0u);
  for (std::size_t r = 1; r < s.rows.size(); ++r) {
    const auto& cut = s.per_trial[r][0].stances;
    ASSERT_EQ(cut.size(), recorded.size()) << s.rows[r].label;
    for (std::size_t k = 0; k < cut.size(); ++k) {
      ASSERT_TRUE(cut[k].metrics.vertical && recorded[k].metrics.vertical);
      EXPECT_NEAR(cut[k].metrics.vertical->rrmse_percent, recorded[k].metrics.vertical->rrmse_percent, 1.0) << s.rows[r].label;
    }
  }
  EXPECT_LT(s.per_trial[4][0].stances.front().first, recorded.front().first) << "the 0.2 s cut starts the window later";
}

// One parser reads a whole list (issue 31: 100,000 lines took 12 s, a line of 200,000 options
// 20 s to refuse): a line's options never leak into the next, line endings may be LF, CRLF or a
// lone CR, a byte-order mark is skipped, and an overlong line is refused at once.
TEST(TrialList, EachLineHasOnlyItsOwnOptionsWhateverTheLineEndings) {
  const std::string text = "\xEF\xBB\xBF# comment\r"
                           "walking|labA|one|a.c3d --mass 70 --paper --r 500 --plates p.mot\r\n"
                           "walking|labB|two|b.c3d\r"
                           "running|labC|three|c.c3d --max-gap 4\n";
  const auto list = parse_trial_list(text, "list.txt");
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0].activity, "walking");
  EXPECT_EQ(list[0].line, 2);
  EXPECT_TRUE(list[0].settings.paper);
  EXPECT_TRUE(list[0].settings.r_given);
  EXPECT_EQ(list[0].settings.mass.value_or(0), 70);
  EXPECT_EQ(list[0].plates, "p.mot");
  const Settings defaults;
  EXPECT_EQ(list[1].settings.trial, "b.c3d");
  EXPECT_FALSE(list[1].settings.paper);
  EXPECT_FALSE(list[1].settings.r_given);
  EXPECT_EQ(list[1].settings.r, defaults.r);
  EXPECT_FALSE(list[1].settings.mass.has_value());
  EXPECT_TRUE(list[1].plates.empty());
  EXPECT_EQ(list[1].line, 3);
  EXPECT_EQ(list[2].settings.max_gap, 4);
  EXPECT_EQ(list[2].line, 4);
  // A plain path line (issue 30): named by its file, its own lab.
  const auto plain = parse_trial_list("\"data/walk one.c3d\"\ndata/run.trc --mass 60\n", "plain.txt");
  ASSERT_EQ(plain.size(), 2u);
  EXPECT_EQ(plain[0].settings.trial, "data/walk one.c3d");  // quoted: a path with a space
  EXPECT_EQ(plain[1].settings.trial, "data/run.trc");
  EXPECT_EQ(plain[1].name, "run.trc");
  EXPECT_EQ(plain[1].lab, "run.trc");
  EXPECT_EQ(plain[1].activity, "trials");
  EXPECT_EQ(plain[1].settings.mass.value_or(0), 60);
}

TEST(TrialList, AHostileLineIsRefusedAtOnceNamingTheLine) {
  std::string many = "walking|lab|x|a.c3d";
  for (int k = 0; k < 200000; ++k) many += " --r 5";
  const auto start = std::chrono::steady_clock::now();
  try {
    (void)parse_trial_list("walking|lab|ok|a.c3d\n" + many + "\n", "list.txt");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("list.txt:2: a line of"), std::string::npos) << e.what();
  }
  std::string words = "walking|lab|x|a.c3d";
  for (int k = 0; k < 1001; ++k) words += " -";
  EXPECT_THROW((void)parse_trial_list(words, "list.txt"), InputError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  EXPECT_THROW((void)parse_trial_list("\xEF\xBB\xBF\r\n# only a comment\r", "list.txt"), InputError);
}

// Studies and fits stream their trials (issue 31: 400 trials of 16 MB took 12.9 GB): a trial is
// loaded when it is used and let go before the next, once per study whatever the number of
// settings, and at most twice in a leave-one-out fit; the figures are those of trials held whole.
TEST(Study, TrialsAreLoadedOneAtATimeAndLetGo) {
  const Trial walk = make_example_walk();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  struct Counts {
    int loads = 0, alive = 0, most_alive = 0;
  };
  auto counts = std::make_shared<Counts>();
  std::vector<StudyTrial> streamed(3), held(3);
  for (std::size_t k = 0; k < 3; ++k) {
    for (auto* t : {&streamed[k], &held[k]}) {
      t->name = "walk-" + std::to_string(k);
      t->activity = "walking";
      t->lab = "lab-" + std::to_string(k);
    }
    held[k].trial = &walk, held[k].plates = &*walk.plates, held[k].marker_set = &set;
    streamed[k].load = [&walk, &set, counts] {
      struct Held {
        Trial trial;
        std::shared_ptr<Counts> c;
        ~Held() { --c->alive; }
      };
      auto h = std::make_shared<Held>();
      h->trial = walk, h->c = counts;
      ++counts->loads, ++counts->alive;
      counts->most_alive = std::max(counts->most_alive, counts->alive);
      StudyTrialData d{&h->trial, nullptr, &*h->trial.plates, &set, h};
      return d;
    };
  }
  const StudyResult s = run_study("ground-shift", streamed), reference = run_study("ground-shift", held);
  EXPECT_EQ(counts->loads, 3) << "once per trial, not once per setting";
  EXPECT_EQ(counts->most_alive, 1);
  EXPECT_EQ(counts->alive, 0);
  ASSERT_EQ(s.per_trial.size(), reference.per_trial.size());
  for (std::size_t r = 0; r < s.per_trial.size(); ++r)
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_EQ(mean_rrmse(s.per_trial[r][k].stances).vertical, mean_rrmse(reference.per_trial[r][k].stances).vertical);
  counts->loads = 0;
  (void)fit_cop_on_trials(streamed, CopFunction::paper(), 0.2, false, true);
  EXPECT_LE(counts->loads, 6);
  EXPECT_EQ(counts->most_alive, 1);
  EXPECT_EQ(counts->alive, 0);
}

// The batch CSV keeps full precision (issue 30: it rounded to 4 significant figures): each number
// reads back as the row's own double.
TEST(Batch, TheCsvKeepsFullPrecision) {
  const auto dir = test::temp_dir("batch_precision");
  const auto files = write_examples(dir.string(), 3.0, 100.0, 0.0);
  TrialListEntry e = parse_trial_list_line("walking|lab|walk|" + (dir / "example_walk.c3d").string() + " --mass 70", "list:1");
  const BatchRow row = run_batch_entry(e);
  ASSERT_TRUE(row.ok) << row.error;
  const std::string csv = batch_csv({row});
  const std::string line = csv.substr(csv.find('\n') + 1);
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
  ASSERT_GE(cells.size(), 13u);
  EXPECT_EQ(std::stod(cells[12]), row.vertical) << cells[12];  // vertical_rrmse_percent
  EXPECT_EQ(std::stod(cells[9]), row.mass_kg);
  EXPECT_GT(cells[12].size(), 6u) << "more than 4 significant figures";
}

// The batch summary gives the COP's RMSE in mm beside its rRMSE (issue 29), and with --model 3d
// the lateral force's rRMSE, the lateral COP's RMSE and the knee adduction moment's rRMSE (issue
// 28): the validation's own means, by column name; empty cells without the 3D model.
TEST(Batch, TheSummaryCarriesTheCopInMmAndThe3DFiguresByName) {
  const auto dir = test::temp_dir("batch_3d");
  const auto files = write_examples(dir.string(), 3.0, 100.0, 0.0);
  const auto cells_of = [](const BatchRow& row) {
    const std::string csv = batch_csv({row});
    std::map<std::string, std::string> out;
    const auto split = [](const std::string& text) {  // every cell, the empty last one too
      std::vector<std::string> cells(1);
      for (char c : text) {
        if (c == ',') cells.emplace_back();
        else cells.back().push_back(c);
      }
      return cells;
    };
    const auto first = csv.find('\n');
    const auto header = split(csv.substr(0, first)), line = split(csv.substr(first + 1, csv.find('\n', first + 1) - first - 1));
    EXPECT_EQ(header.size(), line.size());
    for (std::size_t k = 0; k < std::min(header.size(), line.size()); ++k) out[header[k]] = line[k];
    return out;
  };
  for (const bool three_d : {false, true}) {
    TrialListEntry e = parse_trial_list_line(
        "walking|lab|walk|" + (dir / "example_walk.c3d").string() + " --mass 70" + (three_d ? " --model 3d" : ""), "list:1");
    const BatchRow row = run_batch_entry(e);
    ASSERT_TRUE(row.ok) << row.error;
    const auto cells = cells_of(row);
    ASSERT_TRUE(std::isfinite(row.cop_mm));
    EXPECT_EQ(std::stod(cells.at("cop_rmse_mm")), row.cop_mm);
    // Each cell is the row's value, empty where it does not exist (the example's plates carry no
    // lateral force, whose rRMSE then has no range to divide by).
    for (const auto& [key, value] : {std::pair{"lateral_rrmse_percent", row.lateral}, {"cop_lateral_rmse_mm", row.cop_lateral_mm},
                                     {"knee_adduction_rrmse_percent", row.knee_adduction}}) {
      EXPECT_EQ(cells.at(key).empty(), !std::isfinite(value)) << key << ": " << cells.at(key);
      if (std::isfinite(value)) {
        EXPECT_EQ(std::stod(cells.at(key)), value) << key;
      }
    }
    // The 3D model's figures exist with it and only with it.
    EXPECT_EQ(std::isfinite(row.cop_lateral_mm), three_d);
    EXPECT_EQ(std::isfinite(row.knee_adduction), three_d);
    EXPECT_EQ(cells.at("error"), "");
  }
}

namespace {
/// A two-row robustness study (as recorded, then the condition) on the example walk with `set`:
/// its rows' stances, checked to be the same stances.
std::array<std::vector<StanceValidation>, 2> two_row_study(const char* kind, const Trial& walk, const MarkerSet& set) {
  StudyTrial t;
  t.name = "walk", t.activity = "walking", t.lab = "lab", t.trial = &walk, t.plates = &*walk.plates, t.marker_set = &set;
  const StudyResult r = run_study(kind, {t});
  EXPECT_EQ(r.rows.size(), 2u);
  EXPECT_TRUE(r.failures.empty());
  EXPECT_TRUE(!r.rows.empty() && r.rows[0].is_default);
  if (r.per_trial.size() != 2) return {};
  const auto& first = r.per_trial[0][0].stances;
  const auto& second = r.per_trial[1][0].stances;
  EXPECT_GT(first.size(), 0u);
  EXPECT_EQ(second.size(), first.size());
  return {first, second};
}
}  // namespace

// The marker-labels study runs every trial with its preset and with the mapping made from its own
// labels: on the example walk, whose labels give the preset's very landmarks, the two rows agree
// stance for stance.
TEST(Study, MarkerLabelsStudyRunsTheMappingFromTheLabelsBesideThePreset) {
  const Trial walk = make_example_walk();
  const auto [preset, labels] = two_row_study("marker-labels", walk, *find_marker_set("kin2grf-example"));
  ASSERT_GT(preset.size(), 0u);
  ASSERT_EQ(labels.size(), preset.size());
  for (std::size_t k = 0; k < preset.size(); ++k)
    EXPECT_DOUBLE_EQ(labels[k].metrics.vertical->rrmse_percent, preset[k].metrics.vertical->rrmse_percent) << "stance " << k;
}

// The toe-ablation study replaces each hallux made of a marker by the presets' virtual toes: on
// the example walk, whose toes are markers, the COP moves (model 2's place is an arc fraction of
// heel -> MT -> toe) and the forces' stances stay; a set whose toes are virtual already is the same
// in both rows. Its third row removes the trunk and arm markers too (a lower-body clinical set):
// the toes as in the second row, the whole body's motion no longer the trunk markers'. Its fourth
// places that set's MT markers 15 mm back with 2 mm of noise (8 draws, their stances pooled).
TEST(Study, ToeAblationStudyReplacesToeMarkersByVirtualToes) {
  const Trial walk = make_example_walk();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  ASSERT_EQ(set.rules[static_cast<std::size_t>(landmark(0, kHallux))].kind, RuleKind::Marker);
  MarkerSet virtual_toes = set;
  for (int side = 0; side < 2; ++side) {
    LandmarkRule& r = virtual_toes.rules[static_cast<std::size_t>(landmark(side, kHallux))];
    r = LandmarkRule{};
    r.kind = RuleKind::VirtualHallux;
    r.value = kVirtualToeShare;
  }
  for (const MarkerSet* s : std::array<const MarkerSet*, 2>{&set, &virtual_toes}) {
    StudyTrial t;
    t.name = "walk", t.activity = "walking", t.lab = "lab", t.trial = &walk, t.plates = &*walk.plates, t.marker_set = s;
    const StudyResult r = run_study("toe-ablation", {t});
    ASSERT_EQ(r.rows.size(), 4u);
    EXPECT_TRUE(r.failures.empty());
    EXPECT_TRUE(r.rows[0].is_default);
    ASSERT_EQ(r.per_trial.size(), 4u);
    const auto& recorded = r.per_trial[0][0].stances;
    const auto& ablated = r.per_trial[1][0].stances;
    const auto& lower_body = r.per_trial[2][0].stances;
    const auto& clinical = r.per_trial[3][0].stances;
    ASSERT_GT(recorded.size(), 0u);
    ASSERT_EQ(ablated.size(), recorded.size());
    ASSERT_EQ(lower_body.size(), recorded.size());
    // The clinical row pools its noise draws' stances.
    ASSERT_EQ(clinical.size(), 8 * recorded.size());
    double cop_change = 0, vertical_change = 0, clinical_cop_change = 0;
    for (std::size_t k = 0; k < recorded.size(); ++k) {
      cop_change += std::abs(ablated[k].metrics.cop->rmse - recorded[k].metrics.cop->rmse);
      vertical_change += std::abs(lower_body[k].metrics.vertical->rmse - ablated[k].metrics.vertical->rmse);
      clinical_cop_change += std::abs(clinical[k].metrics.cop->rmse - lower_body[k].metrics.cop->rmse);
    }
    if (s == &set) EXPECT_GT(cop_change, 1e-4) << "the toes' markers replaced: the COP moves";
    else EXPECT_EQ(cop_change, 0.0) << "virtual toes already: nothing to replace";
    EXPECT_GT(vertical_change, 1e-3) << "the trunk markers removed too: the whole body's motion changes";
    // Model 2 places the COP in heel -> MT lengths: MT markers 15 mm back move it.
    EXPECT_GT(clinical_cop_change, 1e-3) << "the MT markers placed back and noisy: the COP moves";
  }
}

// The plate-export study: every trial's plates through a 6 and a 10 Hz zero-lag low-pass, as a GRF
// file exported after filtering has them, the stances timed by the crossings and by validate's
// default. The estimate is the same in every row; on the example walk the filtered plates'
// crossings lead its foot strikes, so the crossings' onsets read later, more at 6 Hz than at 10;
// each stance keeps both timings whichever scores it.
TEST(Study, PlateExportStudyFiltersThePlatesNotTheEstimate) {
  const Trial walk = make_example_walk();
  StudyTrial t;
  t.name = "walk", t.activity = "walking", t.lab = "lab", t.trial = &walk, t.plates = &*walk.plates;
  t.marker_set = find_marker_set("kin2grf-example");
  const StudyResult r = run_study("plate-export", {t});
  ASSERT_EQ(r.rows.size(), 5u);
  EXPECT_TRUE(r.rows[0].is_default);
  ASSERT_TRUE(r.failures.empty()) << r.failures.front();
  const auto mean_onset = [&](std::size_t row) {
    double sum = 0;
    int n = 0;
    for (const StanceValidation& st : r.per_trial[row][0].stances)
      if (st.onset_crossing_error_ms) sum += *st.onset_crossing_error_ms, ++n;
    return n ? sum / n : std::nan("");
  };
  const double recorded = mean_onset(0), at6 = mean_onset(1), at10 = mean_onset(3);
  EXPECT_GT(at6, recorded + 5.0);
  EXPECT_GT(at6, at10);
  EXPECT_GT(at10, recorded);
  for (std::size_t row = 0; row < r.rows.size(); ++row) {
    ASSERT_EQ(r.per_trial[row][0].stances.size(), r.per_trial[0][0].stances.size()) << r.rows[row].label;
    for (const StanceValidation& st : r.per_trial[row][0].stances) {
      EXPECT_TRUE(st.onset_crossing_error_ms && st.onset_ramp_error_ms) << r.rows[row].label;
      if (row == 1 || row == 3) {  // "crossings"
        EXPECT_FALSE(st.onset_by_ramp) << r.rows[row].label;
      }
    }
  }
}

// The subject-scale study makes each trial's subject dynamically similar at 0.6, 0.8 and 1.2 of
// its size (dynamically_scaled: lengths x L, times x sqrt(L), forces x L^3, moments x L^4) and
// scales the validation's own thresholds alike: on the example walk every row keeps its stances,
// each scaled stance's vertical error in newtons is about L^3 times the recorded one's, and its
// rRMSE stays within a tenth of it (what is left is owed to the settings in absolute units).
TEST(Study, SubjectScaleStudyScalesTheSubjectItsPlatesAndTheValidation) {
  const Trial walk = make_example_walk();
  const Trial small = dynamically_scaled(walk, 0.6);
  ASSERT_TRUE(small.plates && walk.plates);
  const auto& p = walk.plates->plates[0];
  const auto& q = small.plates->plates[0];
  EXPECT_NEAR(q.force_N.cwiseAbs().maxCoeff(), 0.216 * p.force_N.cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_NEAR(q.centre_m.x(), 0.6 * p.centre_m.x(), 1e-12);
  EXPECT_NEAR(small.markers.time_s[10], std::sqrt(0.6) * walk.markers.time_s[10], 1e-12);
  EXPECT_NEAR(small.plates->rate_hz, walk.plates->rate_hz / std::sqrt(0.6), 1e-9);
  EXPECT_THROW((void)dynamically_scaled(walk, 0.0), InputError);

  StudyTrial t;
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  t.name = "walk", t.activity = "walking", t.lab = "lab", t.trial = &walk, t.plates = &*walk.plates, t.marker_set = &set;
  const StudyResult r = run_study("subject-scale", {t});
  ASSERT_EQ(r.rows.size(), 4u);
  EXPECT_TRUE(r.failures.empty());
  EXPECT_TRUE(r.rows[0].is_default);
  const auto& recorded = r.per_trial[0][0].stances;
  ASSERT_GT(recorded.size(), 0u);
  for (std::size_t k = 1; k < r.rows.size(); ++k) {
    const double L = r.rows[k].value;
    const auto& scaled = r.per_trial[k][0].stances;
    ASSERT_EQ(scaled.size(), recorded.size()) << r.rows[k].label;
    for (std::size_t s = 0; s < scaled.size(); ++s) {
      const double a = recorded[s].metrics.vertical->rrmse_percent, b = scaled[s].metrics.vertical->rrmse_percent;
      EXPECT_NEAR(b, a, 0.1 * a + 0.5) << r.rows[k].label << " stance " << s;
      EXPECT_NEAR(scaled[s].metrics.vertical->rmse / (L * L * L), recorded[s].metrics.vertical->rmse, 0.25 * recorded[s].metrics.vertical->rmse + 2.0)
          << r.rows[k].label << " stance " << s;
    }
  }
}

// The marker-placement study puts each foot's heel or MT markers 15 mm further back or forward
// along the foot: the moved markers go exactly that far along the heel -> MT line and no other
// marker moves; on the example walk every row keeps its stances and model 2's COP, placed in
// lengths between the heel and MT landmarks, moves in each.
TEST(Study, MarkerPlacementStudyMovesTheHeelOrMtMarkersAlongTheFoot) {
  const Trial walk = make_example_walk();
  const MarkerSet& set = *find_marker_set("kin2grf-example");
  for (const LegLandmark which : {kHeel, kMt}) {
    MarkerTrajectories moved = walk.markers;
    shift_markers_along_foot(moved, set, which, -0.015);
    std::vector<int> expected;
    for (int side = 0; side < 2; ++side)
      for (const std::string& name : set.rules[static_cast<std::size_t>(landmark(side, which))].markers) expected.push_back(moved.find(name));
    ASSERT_EQ(expected.size(), 2u);
    for (std::size_t k = 0; k < moved.names.size(); ++k) {
      const Eigen::MatrixX3d d = moved.positions_m[k] - walk.markers.positions_m[k];
      const bool is_moved = std::find(expected.begin(), expected.end(), static_cast<int>(k)) != expected.end();
      if (!is_moved) {
        EXPECT_EQ(d.cwiseAbs().maxCoeff(), 0.0) << moved.names[k];
        continue;
      }
      const int side = k == static_cast<std::size_t>(expected[0]) ? 0 : 1;
      const int heel = walk.markers.find(set.rules[static_cast<std::size_t>(landmark(side, kHeel))].markers[0]);
      const int mt = walk.markers.find(set.rules[static_cast<std::size_t>(landmark(side, kMt))].markers[0]);
      for (Eigen::Index i = 0; i < d.rows(); i += 25) {
        const Eigen::RowVector3d u = (walk.markers.positions_m[static_cast<std::size_t>(mt)].row(i) -
                                      walk.markers.positions_m[static_cast<std::size_t>(heel)].row(i)).normalized();
        EXPECT_NEAR(d.row(i).norm(), 0.015, 1e-12) << moved.names[k] << " frame " << i;
        EXPECT_NEAR(d.row(i).dot(u), -0.015, 1e-12) << "back along the heel -> MT line";
      }
    }
  }
  StudyTrial t;
  t.name = "walk", t.activity = "walking", t.lab = "lab", t.trial = &walk, t.plates = &*walk.plates, t.marker_set = &set;
  const StudyResult r = run_study("marker-placement", {t});
  ASSERT_EQ(r.rows.size(), 5u);
  ASSERT_TRUE(r.failures.empty()) << r.failures.front();
  EXPECT_TRUE(r.rows[0].is_default);
  const auto& recorded = r.per_trial[0][0].stances;
  ASSERT_GT(recorded.size(), 0u);
  for (std::size_t row = 1; row < r.rows.size(); ++row) {
    const auto& placed = r.per_trial[row][0].stances;
    ASSERT_EQ(placed.size(), recorded.size()) << r.rows[row].label;
    double cop_change = 0;
    for (std::size_t k = 0; k < placed.size(); ++k) cop_change += std::abs(placed[k].metrics.cop->rmse - recorded[k].metrics.cop->rmse);
    EXPECT_GT(cop_change, 1e-4) << r.rows[row].label << ": the COP's lengths are the markers' distances";
  }
}
