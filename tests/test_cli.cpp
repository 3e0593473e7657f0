// Command-line tests on bad input and bad options (issue 10): each gets a clear error that names
// the file, the setting or the stream, a non-zero exit, and no input is ever overwritten. The
// trial is the project's own synthetic example (make-example), so no shared data is needed.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/workflow/batch.hpp"
#include "kin2grf/workflow/trial_list.hpp"
#include "test_support.hpp"

namespace {

struct CliRun {
  int status = -1;
  std::string out;  ///< stdout and stderr together
};

/// `redirect`: the shell redirections (default: stderr with stdout into the pipe).
CliRun run(const std::string& args, const std::string& redirect = "2>&1") {
  const std::string cmd = std::string(KIN2GRF_CLI) + " " + args + " " + redirect;
  CliRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) r.out += buf;
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// The synthetic example, made once per test binary.
const std::filesystem::path& example_dir() {
  static const std::filesystem::path dir = [] {
    const auto d = kin2grf::test::temp_dir("cli_example");
    run("make-example --out-dir " + d.string());
    return d;
  }();
  return dir;
}

std::string example_trc() { return (example_dir() / "example_squat.trc").string(); }

}  // namespace

TEST(CliInput, TheOverviewListsEverySubcommandAndEachSubcommandHasItsOwnHelp) {
  // The program builds only the subcommand asked for; without one (or with a wrong one) all.
  const auto overview = run("--help");
  EXPECT_EQ(overview.status, 0);
  for (const char* c : {"info", "estimate", "validate", "study", "fit-cop", "batch", "make-example"})
    EXPECT_NE(overview.out.find(std::string("  ") + c + " "), std::string::npos) << c << "\n" << overview.out;
  const auto typo = run("estimat x.trc");
  EXPECT_NE(typo.status, 0);
  const auto help = run("validate --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("--plates"), std::string::npos);
  EXPECT_NE(run("estimate").out.find("TRIAL is required"), std::string::npos);
}

TEST(CliInput, EveryBadNumericOptionIsRefusedNamingTheSetting) {
  const std::string trc = example_trc();
  ASSERT_TRUE(std::filesystem::exists(trc));
  const struct {
    const char* option;
    const char* named;
  } cases[] = {
      {"--kinematic-cutoff nan", "kinematic cut-off"}, {"--kinematic-cutoff 0", "kinematic cut-off"},
      {"--kinematic-cutoff -1", "kinematic cut-off"},  {"--post-cutoff -1", "post-filter cut-off"},
      {"--post-cutoff nan", "post-filter cut-off"},    {"--r nan", "activation parameter r"},
      {"--r 0", "activation parameter r"},             {"--r -1", "activation parameter r"},
      {"--ground-shift inf", "ground shift"},          {"--ground-level nan", "ground level"},
      {"--max-gap -5", "longest gap"},                 {"--mass -70", "body mass"},
      {"--mass 0.5", "body mass"},                     {"--mass nan", "body mass"},
      {"--torso-lag -0.01", "torso-lag"},              {"--torso-lag 1", "torso-lag"},
      {"--post-cutoff-cycles -1", "post-filter cycles"}, {"--post-cutoff-cycles nan", "post-filter cycles"},
      {"--post-cutoff-cycles 60", "post-filter cycles"}, {"--post-cutoff 8 --post-cutoff-cycles 4", "give one of them"},
      {"--double-support-sta -0.1", "double-support-sta"}, {"--double-support-sta 2", "double-support-sta"},
      {"--double-support-sta nan", "double-support"},  {"--double-support-angle 1.5", "double-support-angle"},
      {"--min-kinematic-cycles -1", "min-kinematic-cycles"}, {"--min-kinematic-cycles 30", "min-kinematic-cycles"},
      {"--min-kinematic-cycles nan", "kinematic cycles"},
  };
  for (const auto& c : cases) {
    const CliRun r = run("estimate " + trc + " --mass 70 " + c.option);
    EXPECT_NE(r.status, 0) << c.option << ": " << r.out;
    // The library names the setting; the command-line parser (for text it cannot read as a
    // number, such as "nan" for some options) names the option.
    const std::string flag = std::string(c.option).substr(0, std::string(c.option).find(' '));
    EXPECT_TRUE(r.out.find(c.named) != std::string::npos || r.out.find(flag) != std::string::npos) << c.option << ": " << r.out;
  }
  // An unusual mass is taken when asked for.
  EXPECT_EQ(run("estimate " + trc + " --mass 15 --force-mass --json " + (example_dir() / "m.json").string()).status, 0);
  const CliRun v = run("validate " + (example_dir() / "example_squat.c3d").string() + " --threshold nan");
  EXPECT_EQ(v.status, 2) << v.out;
  EXPECT_NE(v.out.find("setting threshold (N) = nan"), std::string::npos) << v.out;  // the setting, as the library names it
  EXPECT_EQ(run("make-example --seconds -1 --out-dir " + (example_dir() / "x").string()).status, 2);
}

TEST(CliInput, AnOutputNeverOverwritesAnInput) {
  const auto dir = kin2grf::test::temp_dir("cli_clobber");
  const auto trc = dir / "trial.trc";
  std::filesystem::copy_file(example_trc(), trc);
  const auto before = std::filesystem::file_size(trc);
  for (const char* flag : {"-o", "--csv", "--json"}) {
    const CliRun r = run("estimate " + trc.string() + " --mass 70 " + flag + " " + trc.string());
    EXPECT_EQ(r.status, 2) << flag << ": " << r.out;
    EXPECT_NE(r.out.find("is an input of this run"), std::string::npos) << r.out;
  }
  // The same file by another name, too.
  const CliRun r = run("estimate " + trc.string() + " --mass 70 --csv " + (dir / "." / "trial.trc").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(std::filesystem::file_size(trc), before);
  // No temporary file is left behind by a successful run either.
  ASSERT_EQ(run("estimate " + trc.string() + " --mass 70 --csv " + (dir / "out.csv").string()).status, 0);
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find("kin2grf-tmp"), std::string::npos) << e.path();
}

TEST(CliInput, DevicesPipesAndLostStandardOutputAreErrors) {
  const CliRun z = run("info /dev/zero");
  EXPECT_EQ(z.status, 2) << z.out;
  const auto dir = kin2grf::test::temp_dir("cli_fifo");
  const auto fifo = dir / "pipe.c3d";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const CliRun f = run("info " + fifo.string());  // must not wait for a writer
  EXPECT_EQ(f.status, 2) << f.out;
  EXPECT_NE(f.out.find("not a regular file"), std::string::npos) << f.out;
  const CliRun full = run("info " + example_trc(), "2>&1 >/dev/full");
  EXPECT_EQ(full.status, 2) << full.out;
  EXPECT_NE(full.out.find("standard output"), std::string::npos) << full.out;
}

TEST(CliInput, InvalidUtf8InALabelIsWrittenAsJson) {
  // A marker label with a byte that is not UTF-8: --json replaces it instead of failing.
  const auto dir = kin2grf::test::temp_dir("cli_utf8");
  std::string text = kin2grf::read_file_text(example_trc());
  const auto at = text.find("RSHO");
  ASSERT_NE(at, std::string::npos);
  text[at + 3] = static_cast<char>(0xFF);
  const auto bad = dir / "utf8.trc";
  kin2grf::write_file_text(bad.string(), text);
  const CliRun r = run("info --json " + bad.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("\"markers\""), std::string::npos);
}

TEST(CliInput, JsonNumbersOutOfRangeNameTheFile) {
  const auto dir = kin2grf::test::temp_dir("cli_json");
  const auto cop = dir / "cop.json";
  kin2grf::write_file_text(cop.string(), "{\"delta_hs\": 1e400}");
  const CliRun r = run("estimate " + example_trc() + " --mass 70 --cop-function " + cop.string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find(cop.string()), std::string::npos) << r.out;
}

TEST(CliInput, AMarkerNeededTwiceIsAnErrorNotAGuess) {
  const auto dir = kin2grf::test::temp_dir("cli_dup");
  std::string text = kin2grf::read_file_text(example_trc());
  const auto at = text.find("RMT1");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 4, "RHEE");  // now two RHEE columns: which is the heel?
  const auto dup = dir / "dup.trc";
  kin2grf::write_file_text(dup.string(), text);
  const CliRun r = run("estimate " + dup.string() + " --mass 70 --markers kin2grf-example");
  EXPECT_EQ(r.status, 2) << r.out;
  // A heel and a toe under one label are no medial-lateral pair: nothing is guessed.
  EXPECT_NE(r.out.find("appears 2 times in the file: name the one meant in a mapping file (--markers) as RHEE#1 or RHEE#2"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("repeated"), std::string::npos) << "the reader's warning is printed too: " << r.out;
}

// Every development trial of scripts/trials.txt runs as listed, with no hand edits, and every
// number it writes is finite (issue 10).
TEST(CliShared, EveryListedTrialRunsAndWritesFiniteNumbers) {
  KIN2GRF_REQUIRE_DATA();
  std::ifstream list(std::string(KIN2GRF_SOURCE_DIR) + "/scripts/trials.txt");
  ASSERT_TRUE(list);
  const auto dir = kin2grf::test::temp_dir("cli_all");
  std::string line;
  int trials = 0;
  while (std::getline(list, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::size_t bar = 0;
    for (int k = 0; k < 3; ++k) bar = line.find('|', bar) + 1;
    std::string args = line.substr(bar);
    for (std::size_t p; (p = args.find("DATA")) != std::string::npos;) args.replace(p, 4, kin2grf::test::data_dir());
    if (const auto p = args.find("--plates "); p != std::string::npos) {
      const auto e = args.find(' ', p + 9);
      args.erase(p, e == std::string::npos ? std::string::npos : e - p);
    }
    const auto csv = dir / ("t" + std::to_string(trials) + ".csv");
    const CliRun r = run("estimate " + args + " --csv " + csv.string(), "2>&1 >/dev/null");
    ++trials;
    ASSERT_EQ(r.status, 0) << line << "\n" << r.out;
    const std::string text = kin2grf::read_file_text(csv.string());
    for (const char* bad : {"nan", "inf"}) EXPECT_EQ(text.find(bad), std::string::npos) << line << ": " << bad << " in the CSV";
  }
  EXPECT_GE(trials, 14);
}

// The OpenSim export (issue 12): the ExternalLoads XML names the .mot beside it and identifiers
// that are its columns; the .mot covers every marker frame of the trial with the TRC's times, Y
// up, finite everywhere, the body weight carried on the vertical axis.
TEST(CliExport, ExternalLoadsMatchTheMotColumnsAndTimes) {
  const auto dir = kin2grf::test::temp_dir("cli_opensim");
  const std::string c3d = (example_dir() / "example_squat.c3d").string();
  const CliRun r = run("estimate " + c3d + " --opensim " + (dir / "os").string() + " --opensim-bodies foot_r foot_l", "2>&1");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string xml = kin2grf::read_file_text((dir / "os" / "example_squat_external_loads.xml").string());
  auto tag = [&](const std::string& name, std::size_t from = 0) {
    const auto a = xml.find("<" + name + ">", from);
    const auto b = xml.find("</" + name + ">", a);
    return a == std::string::npos || b == std::string::npos ? std::string() : xml.substr(a + name.size() + 2, b - a - name.size() - 2);
  };
  const std::string datafile = tag("datafile");
  ASSERT_EQ(datafile, "example_squat_grf.mot");
  EXPECT_EQ(tag("applied_to_body"), "foot_r");
  EXPECT_NE(xml.find("<applied_to_body>foot_l</applied_to_body>"), std::string::npos);
  const kin2grf::Table mot = kin2grf::read_sto((dir / "os" / datafile).string());
  // Every identifier of both forces names three columns of the .mot.
  int identifiers = 0;
  for (const char* id : {"force_identifier", "point_identifier", "torque_identifier"})
    for (std::size_t from = 0; (from = xml.find(std::string("<") + id + ">", from)) != std::string::npos; ++from, ++identifiers) {
      const std::string prefix = tag(id, from);
      for (const char axis : {'x', 'y', 'z'}) EXPECT_GE(mot.column(prefix + axis), 0) << prefix << axis;
    }
  EXPECT_EQ(identifiers, 6);
  const kin2grf::Trial trc = kin2grf::load_trial((dir / "os" / "example_squat_markers.trc").string());
  const kin2grf::Trial orig = kin2grf::load_trial(c3d);
  ASSERT_EQ(mot.data.rows(), orig.markers.frames()) << "the whole trial, not only the processed window";
  ASSERT_EQ(trc.markers.frames(), orig.markers.frames());
  for (Eigen::Index i = 0; i < mot.data.rows(); ++i) EXPECT_NEAR(mot.data(i, 0), trc.markers.time_s[i], 1e-6);
  EXPECT_TRUE(mot.data.allFinite());
  EXPECT_EQ(trc.markers.up_axis, kin2grf::Axis::Y);
  // Quiet-standing frames carry the body weight on Y (the model's own squat: 70 kg).
  const int vy = mot.column("ground_force_vy"), vy1 = mot.column("1_ground_force_vy");
  const double mid = mot.data(mot.data.rows() / 2, vy) + mot.data(mot.data.rows() / 2, vy1);
  EXPECT_GT(mid, 0.5 * 70 * 9.81);
  EXPECT_NEAR(mot.data.col(mot.column("ground_force_vz")).cwiseAbs().maxCoeff(), 0.0, 1e-9) << "no mediolateral force";
}

namespace {
/// A CSV's lines with the timing columns (seconds, frames_per_s) blanked.
std::vector<std::string> batch_lines_without_timing(const std::string& csv) {
  std::vector<std::string> out;
  std::istringstream in(csv);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::string cellv;
    std::istringstream ls(line);
    while (std::getline(ls, cellv, ',')) cells.push_back(cellv);
    if (cells.size() > 8) cells[7] = cells[8] = "";
    std::string joined;
    for (const auto& c : cells) joined += c + ",";
    out.push_back(joined);
  }
  return out;
}
}  // namespace

// batch (issue 12): every trial of a list, past a failing one (its error in its row, exit 1),
// validated where it has plates, outputs per trial, the same table whatever --jobs.
TEST(CliBatch, RunsEveryTrialPastAFailureAndTheTableDoesNotDependOnJobs) {
  const auto dir = kin2grf::test::temp_dir("cli_batch");
  const std::string c3d = (example_dir() / "example_walk.c3d").string();
  {
    std::ofstream list(dir / "list.txt");
    list << "# a comment\n"
         << "walking|own|with-plates|" << c3d << "\n"
         << "squat|own|missing|" << (dir / "no-such-trial.trc").string() << " --mass 70\n"
         << "squat|own|markers-only|" << example_trc() << " --mass 70 --paper\n";
  }
  const std::string list = (dir / "list.txt").string();
  const CliRun r2 = run("batch " + list + " --jobs 2 --csv " + (dir / "b2.csv").string() + " --json " +
                        (dir / "b2.json").string() + " --out-dir " + (dir / "out").string());
  EXPECT_EQ(r2.status, 1) << r2.out;  // one trial failed
  EXPECT_NE(r2.out.find("3 trials, 1 failed"), std::string::npos) << r2.out;
  const CliRun r1 = run("batch " + list + " --jobs 1 --csv " + (dir / "b1.csv").string());
  EXPECT_EQ(r1.status, 1) << r1.out;

  const std::string csv2 = kin2grf::read_file_text((dir / "b2.csv").string());
  const auto lines = batch_lines_without_timing(csv2);
  ASSERT_EQ(lines.size(), 4u) << csv2;
  EXPECT_EQ(lines, batch_lines_without_timing(kin2grf::read_file_text((dir / "b1.csv").string())));
  // Rows in the list's order; the failure names its file.
  EXPECT_EQ(lines[1].rfind("walking,own,with-plates,", 0), 0u) << lines[1];
  EXPECT_NE(lines[2].find(",0,0,"), std::string::npos) << lines[2];
  EXPECT_NE(lines[2].find("no-such-trial.trc"), std::string::npos) << lines[2];

  const auto j = nlohmann::json::parse(kin2grf::read_file_text((dir / "b2.json").string()));
  ASSERT_EQ(j["trials"].size(), 3u);
  EXPECT_TRUE(j["trials"][0]["ok"].get<bool>());
  EXPECT_TRUE(j["trials"][0]["validated"].get<bool>());
  EXPECT_GT(j["trials"][0]["stances"].get<int>(), 0);
  EXPECT_TRUE(j["trials"][0]["vertical_rrmse_percent"].is_number());
  EXPECT_FALSE(j["trials"][1]["ok"].get<bool>());
  EXPECT_TRUE(j["trials"][2]["ok"].get<bool>());
  EXPECT_FALSE(j["trials"][2]["validated"].get<bool>());  // a TRC has no plates
  EXPECT_TRUE(j["trials"][2]["vertical_rrmse_percent"].is_null());
  for (const char* f : {"with-plates.csv", "with-plates_grf.mot", "with-plates.json", "with-plates_markers.trc",
                        "with-plates_external_loads.xml", "with-plates_stances.csv", "with-plates_stance_curves.csv", "markers-only.csv",
                        "markers-only_stances.csv", "markers-only_stance_curves.csv"})
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  // The batch's GRF is the OpenSim set's (one convention everywhere).
  EXPECT_NE(kin2grf::read_file_text((dir / "out" / "with-plates_grf.mot").string()).find("kin2grf_frame=OpenSim ground"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "missing.csv"));
}

// Two trials whose output names meet (trial "a" writes a_stances.csv, trial "a_stances" its own
// a_stances.csv) are refused before anything runs, naming the file (the command line's output
// check; run_batch's own, for the library and Python, names both trials too).
TEST(CliBatch, TwoTrialsThatWouldWriteOneFileAreRefused) {
  const auto dir = kin2grf::test::temp_dir("cli_batch_clash");
  {
    std::ofstream list(dir / "list.txt");
    list << "squat|own|a|" << example_trc() << " --mass 70\n"
         << "squat|own|a_stances|" << example_trc() << " --mass 70\n";
  }
  const CliRun r = run("batch " + (dir / "list.txt").string() + " --out-dir " + (dir / "out").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("a_stances.csv"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "a.csv"));
  kin2grf::BatchOptions o;
  o.out_dir = (dir / "out").string();
  try {
    kin2grf::run_batch(kin2grf::read_trial_list((dir / "list.txt").string()), o);
    ADD_FAILURE() << "the clash was not refused";
  } catch (const kin2grf::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("trials 'a' and 'a_stances'"), std::string::npos) << e.what();
  }
}

TEST(CliBatch, ABadLineNamesTheListAndTheLine) {
  const auto dir = kin2grf::test::temp_dir("cli_batch_bad");
  {
    std::ofstream list(dir / "list.txt");
    list << "squat|own|ok|" << example_trc() << " --mass 70\n"
         << "squat|own|bad|" << example_trc() << " --no-such-option 3\n";
  }
  const CliRun r = run("batch " + (dir / "list.txt").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("list.txt:2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--no-such-option"), std::string::npos) << r.out;
}

// The bundled example's TRC and GRF .mot are OpenSim's files, Y up as OpenSim and kin2grf's
// readers take them: read with no up-axis warning, and validated together they give the C3D's
// figures (a Z-up pair was read with the plates' COP 1.7 m from the feet: nothing compared).
TEST(CliExample, ItsOpenSimMarkerAndForceFilesAreYUpAndValidateLikeItsCaptureFile) {
  const auto dir = example_dir();
  const CliRun info = run("info " + (dir / "example_walk.trc").string());
  ASSERT_EQ(info.status, 0) << info.out;
  EXPECT_EQ(info.out.find("up axis: the file's convention"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("up axis Y"), std::string::npos) << info.out;
  const CliRun c3d = run("validate " + (dir / "example_walk.c3d").string());
  const CliRun trc = run("validate " + (dir / "example_walk.trc").string() + " --plates " + (dir / "example_walk_grf.mot").string() +
                         " --mass 70");
  ASSERT_EQ(c3d.status, 0) << c3d.out;
  ASSERT_EQ(trc.status, 0) << trc.out;
  const auto row = [](const std::string& out, const std::string& key) {
    const auto k = out.find(key);
    return k == std::string::npos ? std::string() : out.substr(k, out.find('\n', k) - k);
  };
  // Vertical, anterior and COP; the moment is about the plate centre for the C3D's plates and
  // about the mean COP for a .mot's, which has no geometry.
  const auto first_three = [](const std::string& line) {
    std::istringstream in(line.substr(std::min(line.size(), line.find("n = ") + 6)));
    std::string v, x, a_, y, c, z;
    in >> v >> x >> a_ >> y >> c >> z;
    return v + " " + a_ + " " + c;
  };
  const std::string a = row(c3d.out, "per foot, mean"), b = row(trc.out, "per foot, mean");
  ASSERT_FALSE(a.empty()) << c3d.out;
  ASSERT_FALSE(b.empty()) << trc.out;
  EXPECT_EQ(first_three(a), first_three(b)) << a << "\n" << b;
}

// kin2grf's GRF .mot from a Z-up C3D in that lab's frame (-o --lab-frame; OpenSim's convention is
// Y up). Read back as plates, its vertical is found from the forces (a ground reaction is mostly
// vertical), with a warning, and the estimate compared with itself is exact. Taken as Y up, its
// COPs were all dropped as unloaded and nothing could be compared.
TEST(CliExample, AGrfMotWrittenInAZUpFrameIsReadBackWithItsVertical) {
  const auto dir = example_dir();
  const std::string c3d = (dir / "example_walk.c3d").string(), mot = (dir / "roundtrip_grf.mot").string();
  const CliRun e = run("estimate " + c3d + " -o " + mot + " --lab-frame");
  ASSERT_EQ(e.status, 0) << e.out;
  EXPECT_NE(kin2grf::read_file_text(mot).find("kin2grf_frame=lab"), std::string::npos);
  const CliRun info = run("info " + mot);
  EXPECT_NE(info.out.find("the forces are largest along Z"), std::string::npos) << info.out;
  const CliRun v = run("validate " + c3d + " --plates " + mot);
  ASSERT_EQ(v.status, 0) << v.out;
  EXPECT_NE(v.out.find("per foot, mean (SD), n = 4     0.0 (0.0)   0.0 (0.0)   0.0 (0.0)"), std::string::npos) << v.out;
}

// make-example --marker-noise: a walk as real capture records it, on which the noise rule lowers
// the kinematic cut-off and the stance floor raises the dynamics' again (both in the JSON and
// the messages); out of range, the option is named.
TEST(CliExample, AWalkWithMarkerNoiseShowsBothCutoffs) {
  const auto dir = kin2grf::test::temp_dir("cli_noisy_example");
  ASSERT_EQ(run("make-example --seconds 6 --marker-noise 3 --out-dir " + dir.string()).status, 0);
  // 3.5 cycles (kin2grf's default before session 25): on this walk the default 3.0 cycles' floor
  // lies within a few tenths of a hertz of the lowered cut-off, and the two cut-offs are what is shown.
  const CliRun r = run("estimate " + (dir / "example_walk.c3d").string() + " --min-kinematic-cycles 3.5 --json " + (dir / "e.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("lowered from 6.0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("raised to"), std::string::npos) << r.out;
  std::ifstream in(dir / "e.json");
  const auto j = nlohmann::json::parse(in);
  const double dynamics = j["kinematic_cutoff_hz"], positions = j["position_cutoff_hz"];
  EXPECT_LT(positions, 4.5);
  EXPECT_GT(dynamics, positions + 0.3);
  EXPECT_LE(dynamics, 6.0);
  EXPECT_EQ(j["settings"]["min_kinematic_cycles"], 3.5);
  // The same walk without noise: one cut-off, 6 Hz, for both.
  const CliRun c = run("estimate " + (example_dir() / "example_walk.c3d").string() + " --json " + (dir / "c.json").string());
  ASSERT_EQ(c.status, 0) << c.out;
  std::ifstream cin_(dir / "c.json");
  const auto k = nlohmann::json::parse(cin_);
  EXPECT_EQ(k["kinematic_cutoff_hz"], 6.0);
  EXPECT_EQ(k["position_cutoff_hz"], 6.0);
  const CliRun bad = run("make-example --marker-noise 20 --out-dir " + (dir / "x").string());
  EXPECT_EQ(bad.status, 2) << bad.out;
  EXPECT_NE(bad.out.find("--marker-noise"), std::string::npos) << bad.out;
}

// ---------------------------------------------------------------------------------------------
// What a run writes (issue 31): never onto an input of the run (every trial of a list, its static
// and plates files, every other trial's outputs), never onto two outputs at once, devices and
// FIFOs written in place, nothing left behind by a failed or killed run, one exit code (2) for
// usage errors.

namespace {
/// A trial list of the example walk and squat, the squat validated against the walk's GRF file.
std::filesystem::path example_list(const std::filesystem::path& dir) {
  const auto list = dir / "list.txt";
  const std::string walk = (example_dir() / "example_walk.c3d").string();
  const std::string squat = (example_dir() / "example_squat.c3d").string();
  kin2grf::write_file_text(list.string(), "walking|lab|walk|" + walk + " --mass 70\n" + "squat|lab|other|" + squat +
                                              " --mass 70 --plates " + (dir / "walk_grf.mot").string() + "\n");
  return list;
}
}  // namespace

TEST(CliFiles, BatchStudyAndFitCopNeverWriteOntoAListedTrial) {
  const auto dir = kin2grf::test::temp_dir("cli_list_clobber");
  const auto trial = dir / "in.c3d";
  std::filesystem::copy_file(example_dir() / "example_walk.c3d", trial);
  const auto before = kin2grf::read_file_text(trial.string());
  const auto list = dir / "list.txt";
  kin2grf::write_file_text(list.string(), "walking|lab|walk|" + trial.string() + " --mass 70\n");
  for (const std::string& cmd : {"batch " + list.string() + " --json ", "batch " + list.string() + " --csv ",
                                "study r --trial-list " + list.string() + " --json ",
                                "fit-cop --trial-list " + list.string() + " -o "}) {
    const CliRun r = run(cmd + trial.string());
    EXPECT_EQ(r.status, 2) << cmd << r.out;
    EXPECT_NE(r.out.find("is an input of this run"), std::string::npos) << cmd << r.out;
  }
  EXPECT_EQ(kin2grf::read_file_text(trial.string()), before);
}

// Trial "walk" would write OUT/walk_grf.mot, which is trial "other"'s --plates file: refused
// before anything runs (it ran, and "other" was validated against the new file).
TEST(CliFiles, ABatchTrialsOutputIsNeverAnotherTrialsInput) {
  const auto dir = kin2grf::test::temp_dir("cli_batch_cross");
  const auto list = example_list(dir);
  std::filesystem::copy_file(example_dir() / "example_walk_grf.mot", dir / "walk_grf.mot");
  const auto before = kin2grf::read_file_text((dir / "walk_grf.mot").string());
  const CliRun r = run("batch " + list.string() + " --jobs 1 --out-dir " + dir.string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("walk_grf.mot: is an input of this run"), std::string::npos) << r.out;
  EXPECT_EQ(kin2grf::read_file_text((dir / "walk_grf.mot").string()), before);
  EXPECT_FALSE(std::filesystem::exists(dir / "walk.csv"));
}

TEST(CliFiles, OneFileGivenAsTwoOutputsIsRefusedNamingBoth) {
  const auto dir = kin2grf::test::temp_dir("cli_two_outputs");
  const auto x = (dir / "x.csv").string();
  const CliRun r = run("estimate " + example_trc() + " --mass 70 --csv " + x + " --json " + x);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("given twice as an output (--csv"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(x));
}

// --stance-curves (estimate and validate) is checked as every output: never the trial, not even
// through a symlink to it, never another output of the run; /dev/stdout prints it.
TEST(CliFiles, TheStanceCurvesOutputIsCheckedAsEveryOutput) {
  const auto dir = kin2grf::test::temp_dir("cli_stance_curves");
  const auto trial = dir / "walk.c3d";
  std::filesystem::copy_file(example_dir() / "example_walk.c3d", trial);
  std::filesystem::create_symlink(trial, dir / "link.csv");
  const auto before = kin2grf::read_file_text(trial.string());
  for (const char* cmd : {"estimate ", "validate "})
    for (const auto& target : {trial, dir / "link.csv"}) {
      const CliRun r = run(cmd + trial.string() + " --mass 70 --stance-curves " + target.string());
      EXPECT_EQ(r.status, 2) << cmd << r.out;
      EXPECT_NE(r.out.find("is an input of this run"), std::string::npos) << cmd << r.out;
    }
  EXPECT_EQ(kin2grf::read_file_text(trial.string()), before);
  const auto x = (dir / "x.csv").string();
  const CliRun twice = run("estimate " + trial.string() + " --mass 70 --csv " + x + " --stance-curves " + x);
  EXPECT_EQ(twice.status, 2) << twice.out;
  EXPECT_NE(twice.out.find("given twice as an output"), std::string::npos) << twice.out;
  EXPECT_FALSE(std::filesystem::exists(x));
  const CliRun out = run("validate " + trial.string() + " --mass 70 --stance-curves /dev/stdout", "2>/dev/null");
  EXPECT_EQ(out.status, 0) << out.out;
  EXPECT_NE(out.out.find("side,plate,frame_first,start_s,duration_s,percent,"), std::string::npos) << out.out.substr(0, 300);
}

// A device stays a device, a FIFO gets the file through it, /dev/stdout prints it.
TEST(CliFiles, DevicesFifosAndStandardOutputAreWrittenInPlace) {
  const auto dir = kin2grf::test::temp_dir("cli_devices");
  EXPECT_EQ(run("estimate " + example_trc() + " --mass 70 -o /dev/null --csv /dev/null").status, 2)
      << "the same device twice is still two outputs onto one file";
  const CliRun null = run("estimate " + example_trc() + " --mass 70 -o /dev/null");
  EXPECT_EQ(null.status, 0) << null.out;
  struct stat st {};
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  const CliRun out = run("estimate " + example_trc() + " --mass 70 --csv /dev/stdout", "2>/dev/null");
  EXPECT_EQ(out.status, 0);
  EXPECT_NE(out.out.find("frame,time_s"), std::string::npos) << out.out.substr(0, 300);
  // A character device made with mknod (the issue's recipe; root only): still one after --csv.
  const auto dev = dir / "null-device";
  if (::mknod(dev.c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0) {
    EXPECT_EQ(run("estimate " + example_trc() + " --mass 70 --csv " + dev.string()).status, 0);
    ASSERT_EQ(::stat(dev.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
  }
  const auto fifo = dir / "pipe.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const CliRun piped = run("estimate " + example_trc() + " --mass 70 --csv " + fifo.string() + " & cat " + fifo.string() +
                           " | head -c 200; wait", "2>/dev/null");
  EXPECT_NE(piped.out.find("frame,time_s"), std::string::npos) << piped.out;
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

// A later output that cannot be written fails the run, and the earlier outputs are not left:
// -o was placed before --csv failed on a full disk.
TEST(CliFiles, AFailedRunLeavesNoneOfItsOutputs) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const auto dir = kin2grf::test::temp_dir("cli_failed_run");
  const auto mot = dir / "grf.mot";
  const CliRun r = run("estimate " + example_trc() + " --mass 70 -o " + mot.string() + " --csv /dev/full");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("/dev/full"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::is_empty(dir)) << "left: " << std::filesystem::directory_iterator(dir)->path();
}

// SIGTERM while the outputs are being written: their temporary files are removed. The run is held
// on a FIFO no one reads (--csv), after -o's file is written and waits for the commit.
TEST(CliFiles, ASignalRemovesTheTemporaryFiles) {
  const auto dir = kin2grf::test::temp_dir("cli_sigterm");
  const auto fifo = dir / "held.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string cmd = std::string(KIN2GRF_CLI) + " estimate " + example_trc() + " --mass 70 -o " + (dir / "grf.mot").string() +
                          " --csv " + fifo.string() + " >/dev/null 2>&1 & echo $!";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_TRUE(p);
  long pid = 0;
  ASSERT_EQ(std::fscanf(p, "%ld", &pid), 1);
  pclose(p);
  auto temps = [&] {
    int n = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) n += e.path().string().find("kin2grf-tmp") != std::string::npos;
    return n;
  };
  for (int i = 0; i < 200 && temps() == 0; ++i) usleep(50000);
  ASSERT_EQ(temps(), 1) << "the -o temporary file never appeared";
  ASSERT_EQ(::kill(static_cast<pid_t>(pid), SIGTERM), 0);
  for (int i = 0; i < 100 && ::kill(static_cast<pid_t>(pid), 0) == 0; ++i) usleep(50000);
  EXPECT_EQ(temps(), 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "grf.mot"));
}

TEST(CliFiles, UsageErrorsExitTwoAndAClosedPipeIsNotACrash) {
  EXPECT_EQ(run("estimate " + example_trc() + " --mas 64.9").status, 2);
  EXPECT_EQ(run("estimat " + example_trc()).status, 2);
  EXPECT_EQ(run("estimate").status, 2);
  EXPECT_EQ(run("--help").status, 0);
  EXPECT_EQ(run("--version").status, 0);
  // `| head -1` with the reader gone before kin2grf writes: its own status, not a death by
  // SIGPIPE (141).
  const auto rc = kin2grf::test::temp_dir("cli_sigpipe") / "rc";
  const std::string cmd = "{ " + std::string(KIN2GRF_CLI) + " info " + example_trc() + " 2>/dev/null; echo $? > " + rc.string() +
                          "; } | true";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(kin2grf::read_file_text(rc.string()), "0\n");
}

// The issue's recipe: a long TRC (and C3D) truncated to 4 KB 20 ms after `estimate` starts. Each
// run ends with a result (the read had finished) or an error naming the file; never a signal.
TEST(CliFiles, AnInputTruncatedWhileReadIsNeverASignal) {
  const auto dir = kin2grf::test::temp_dir("cli_truncated");
  ASSERT_EQ(run("make-example --seconds 120 --out-dir " + dir.string()).status, 0);
  int errors = 0;
  for (const char* ext : {"trc", "c3d"}) {
    const auto original = dir / (std::string("example_walk.") + ext);
    for (int k = 0; k < 6; ++k) {
      const auto copy = dir / (std::string("cut.") + ext);
      std::filesystem::copy_file(original, copy, std::filesystem::copy_options::overwrite_existing);
      const CliRun r = run("estimate " + copy.string() + " --mass 70 & (sleep 0.00" + std::to_string(5 + k % 3 * 2) + "; truncate -s 4096 " +
                           copy.string() + "); wait $!");
      EXPECT_TRUE(r.status == 0 || r.status == 2) << ext << " try " << k << ": status " << r.status << "\n" << r.out;
      errors += r.status == 2;
    }
  }
  RecordProperty("runs_ending_in_an_error", errors);
}

// A user's mistakes that ended in "internal error" (exit 3) now end in an error naming the file
// or the option (exit 2), or are read as meant (a Time column in milliseconds).
TEST(CliFiles, MistakesThatWereInternalErrorsAreNamed) {
  const auto dir = kin2grf::test::temp_dir("cli_mistakes");
  const std::string trc = example_trc();
  // The zero-lag filter's limit at 100 Hz is 40.1 Hz (Nyquist x 0.802), not 50.
  for (const std::string& opt : std::vector<std::string>{"--kinematic-cutoff 49.9", "--post-cutoff 49.99", "--kinematic-cutoff 40.2"}) {
    const CliRun r = run("estimate " + trc + " --mass 70 " + opt);
    EXPECT_EQ(r.status, 2) << opt << r.out;
    EXPECT_NE(r.out.find(opt.substr(0, opt.find(' '))), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("below 40.11 Hz"), std::string::npos) << r.out;
  }
  EXPECT_EQ(run("estimate " + trc + " --mass 70 --kinematic-cutoff 40").status, 0);
  // A TRC whose Time column is in ms: read as seconds it was a 0.1 Hz trial.
  std::istringstream in(kin2grf::read_file_text(trc));
  std::string text, line;
  for (int k = 0; std::getline(in, line); ++k) {
    if (k >= 5 && !line.empty()) {
      const auto a = line.find('\t'), b = line.find('\t', a + 1);
      line = line.substr(0, a + 1) + std::to_string(std::stod(line.substr(a + 1, b - a - 1)) * 1000.0) + line.substr(b);
    }
    text += line + "\n";
  }
  const auto ms = dir / "ms.trc";
  kin2grf::write_file_text(ms.string(), text);
  const CliRun info = run("info " + ms.string());
  EXPECT_EQ(info.status, 0) << info.out;
  EXPECT_NE(info.out.find("100 Hz"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("milliseconds"), std::string::npos) << info.out;
  EXPECT_EQ(run("estimate " + ms.string() + " --mass 70").status, 0);
  // A C3D whose POINT:RATE is 1e-30.
  auto t = kin2grf::load_trial((example_dir() / "example_walk.c3d").string());
  t.markers.rate_hz = 1e-30;
  t.plates.reset();
  const auto slow = dir / "slow.c3d";
  kin2grf::write_c3d(slow.string(), t);
  const CliRun c = run("estimate " + slow.string() + " --mass 70");
  EXPECT_EQ(c.status, 2) << c.out;
  EXPECT_NE(c.out.find("POINT:RATE is 1e-30 Hz"), std::string::npos) << c.out;
  // An output folder that is a file.
  const auto file = dir / "a-file";
  kin2grf::write_file_text(file.string(), "x");
  const CliRun m = run("make-example --out-dir " + file.string());
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(file.string() + ": is a file, not a folder"), std::string::npos) << m.out;
  const auto list = dir / "list.txt";
  kin2grf::write_file_text(list.string(), "walking|lab|walk|" + trc + " --mass 70\n");
  const CliRun b = run("batch " + list.string() + " --out-dir " + file.string());
  EXPECT_EQ(b.status, 2) << b.out;
  EXPECT_NE(b.out.find(file.string() + ": is a file, not a folder"), std::string::npos) << b.out;
}

// Smaller slips of issue 31: a TRC with a byte-order mark or lone-CR lines was "not a TRC file"; a
// folder or /dev/zero given as the trial was "unknown file type '.'".
TEST(CliFiles, ABomOrCrOnlyTrcIsReadAndAFolderIsNamedAsOne) {
  const auto dir = kin2grf::test::temp_dir("cli_bom_cr");
  const std::string text = kin2grf::read_file_text(example_trc());
  std::string cr = text;
  std::replace(cr.begin(), cr.end(), '\n', '\r');
  kin2grf::write_file_text((dir / "bom.trc").string(), "\xEF\xBB\xBF" + text);
  kin2grf::write_file_text((dir / "cr.trc").string(), cr);
  const auto reference = kin2grf::load_trial(example_trc());
  for (const char* name : {"bom.trc", "cr.trc"}) {
    const auto t = kin2grf::load_trial((dir / name).string());
    EXPECT_EQ(t.markers.names, reference.markers.names) << name;
    ASSERT_EQ(t.markers.frames(), reference.markers.frames()) << name;
    EXPECT_TRUE(kin2grf::test::matrices_near(t.markers.positions_m[3], reference.markers.positions_m[3], 0)) << name;
  }
  const CliRun folder = run("estimate " + dir.string() + " --mass 70");
  EXPECT_EQ(folder.status, 2);
  EXPECT_NE(folder.out.find(dir.string() + ": is a directory"), std::string::npos) << folder.out;
  const CliRun zero = run("estimate /dev/zero --mass 70");
  EXPECT_EQ(zero.status, 2);
  EXPECT_NE(zero.out.find("/dev/zero: is not a regular file"), std::string::npos) << zero.out;
}

// Errors that suggest (issue 30, item 6): a misspelt option, subcommand or preset gets a "did you
// mean", the mass messages name their flags, and a GRF file given as the trial is named as one.
TEST(CliSuggest, SlipsGetASuggestionOrTheFlagToUse) {
  const std::string trc = example_trc();
  const CliRun option = run("estimate " + trc + " --mas 64.9");
  EXPECT_EQ(option.status, 2);
  EXPECT_NE(option.out.find("unknown option '--mas'; did you mean --mass?"), std::string::npos) << option.out;
  const CliRun command = run("estimat " + trc);
  EXPECT_EQ(command.status, 2);
  EXPECT_NE(command.out.find("did you mean 'estimate'?"), std::string::npos) << command.out;
  const CliRun preset = run("estimate " + trc + " --mass 70 --markers plug-in-gat");
  EXPECT_EQ(preset.status, 2);
  EXPECT_NE(preset.out.find("did you mean plug-in-gait?"), std::string::npos) << preset.out;
  EXPECT_NE(preset.out.find("presets: "), std::string::npos) << preset.out;
  const CliRun mass = run("estimate " + trc);
  EXPECT_EQ(mass.status, 2);
  EXPECT_NE(mass.out.find("--mass KG"), std::string::npos) << mass.out;
  const CliRun unusual = run("estimate " + trc + " --mass 15");
  EXPECT_EQ(unusual.status, 2);
  EXPECT_NE(unusual.out.find("--force-mass"), std::string::npos) << unusual.out;
  const CliRun grf = run("estimate " + (example_dir() / "example_walk_grf.mot").string() + " --mass 70");
  EXPECT_EQ(grf.status, 2);
  EXPECT_NE(grf.out.find("a force file"), std::string::npos) << grf.out;
  EXPECT_NE(grf.out.find("--plates"), std::string::npos) << grf.out;
  EXPECT_EQ(kin2grf::closest_match("xyzzy", {"estimate", "validate"}), "");
}

// The demo's recorded walk (data/example, bundled with its licence and source): validate gives
// the figures the README quotes, from the project's own files (no shared data needed).
TEST(CliExample, TheBundledRecordedWalkValidatesAsTheReadmeSays) {
  KIN2GRF_REQUIRE_CLI();
  const std::filesystem::path dir = std::filesystem::path(KIN2GRF_SOURCE_DIR) / "data" / "example";
  ASSERT_TRUE(std::filesystem::exists(dir / "LICENSE-Apache-2.0.txt"));
  ASSERT_TRUE(std::filesystem::exists(dir / "README.md"));
  const CliRun v = run("validate " + (dir / "walking2.c3d").string() + " --mass 64.9");
  ASSERT_EQ(v.status, 0) << v.out;
  const auto k = v.out.find("right foot on FP1");
  ASSERT_NE(k, std::string::npos) << v.out;
  std::istringstream in(v.out.substr(k + std::string("right foot on FP1").size()));
  double vertical = 0, anterior = 0, cop = 0;
  in >> vertical >> anterior >> cop;
  EXPECT_NEAR(vertical, 3.1, 0.15) << v.out;  // README: 3.1 / 7.2 / 4.2
  EXPECT_NEAR(anterior, 7.2, 0.15) << v.out;
  EXPECT_NEAR(cop, 4.2, 0.15) << v.out;
  EXPECT_NE(v.out.find("left foot is partly off the plate"), std::string::npos) << v.out;
}

// --frames FIRST:LAST processes the file's own frames FIRST-LAST as if the trial were cut there:
// the window says so, the settings record it, and a range the file does not hold is an error
// naming the file and its frames.
TEST(CliExample, FramesCutTheTrialToTheFilesOwnFrameNumbers) {
  KIN2GRF_REQUIRE_CLI();
  const std::string walk = (std::filesystem::path(KIN2GRF_SOURCE_DIR) / "data" / "example" / "walking2.c3d").string();
  const auto dir = kin2grf::test::temp_dir("cli_frames");
  const CliRun v = run("estimate " + walk + " --mass 64.9 --frames 600:900 --json " + (dir / "e.json").string());
  ASSERT_EQ(v.status, 0) << v.out;
  EXPECT_NE(v.out.find("processing frames 600-837 of 600-900"), std::string::npos) << v.out;
  EXPECT_NE(kin2grf::read_file_text((dir / "e.json").string()).find("\"frames\": \"600:900\""), std::string::npos);
  const CliRun open_end = run("estimate " + walk + " --mass 64.9 --frames 700:");
  ASSERT_EQ(open_end.status, 0) << open_end.out;
  EXPECT_NE(open_end.out.find("of 700-1249"), std::string::npos) << open_end.out;
  for (const auto& [range, says] : std::vector<std::pair<std::string, std::string>>{
           {"0:900", "not within the recording's frames 1-1249"}, {"900:600", "comes after its last"}, {"600", "give FIRST:LAST"}}) {
    const CliRun bad = run("estimate " + walk + " --mass 64.9 --frames " + range);
    EXPECT_EQ(bad.status, 2) << range << ": " << bad.out;
    EXPECT_NE(bad.out.find(says), std::string::npos) << bad.out;
    EXPECT_NE(bad.out.find("walking2.c3d"), std::string::npos) << bad.out;
  }
  // Frames the subject is not seen in (walking2's markers hold samples in frames 207-1230): the
  // error says so, not that no marker set matches the labels or that the walker does not travel.
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"--frames 1:100", "no marker holds a sample in frames 1-100 (the markers hold samples in frames 207-1230)"},
           {"--frames 300:400 --markers fullbody-2009",
            "landmark shoulder is undefined in every one of the trial's frames 300-400: its markers C7, CLAV never all hold a sample there"},
           {"--frames 100:300 --markers labels", "Left out for holding samples in too few of the trial's 201 frames"},
           {"--frames 100:300 --markers labels", "RASI (0 of 201 frames)"}}) {
    const CliRun bad = run("estimate " + walk + " --mass 64.9 " + args);
    EXPECT_EQ(bad.status, 2) << args << ": " << bad.out;
    EXPECT_NE(bad.out.find(says), std::string::npos) << args << ": " << bad.out;
  }
}

// One GRF convention (issue 30, item 2): -o writes what --opensim's STEM_grf.mot holds (OpenSim's
// frame, Y up, every frame of the trial) and its header names the frame; --lab-frame is asked for.
TEST(CliExample, TheGrfMotIsInOpenSimsFrameLikeTheOpenSimSet) {
  KIN2GRF_REQUIRE_CLI();
  const auto dir = kin2grf::test::temp_dir("cli_one_convention");
  const std::string c3d = (example_dir() / "example_walk.c3d").string(), mot = (dir / "o.mot").string();
  const CliRun e = run("estimate " + c3d + " -o " + mot + " --opensim " + (dir / "set").string());
  ASSERT_EQ(e.status, 0) << e.out;
  const std::string o = kin2grf::read_file_text(mot), set = kin2grf::read_file_text((dir / "set" / "example_walk_grf.mot").string());
  EXPECT_NE(o.find("kin2grf_frame=OpenSim ground"), std::string::npos);
  EXPECT_EQ(o, set);  // the same file
  // Y up: the vertical force is in ground_force_vy, and the rows cover the trial's every frame.
  const auto table = kin2grf::read_sto(mot);
  const int vy = table.column("ground_force_vy"), vz = table.column("ground_force_vz");
  ASSERT_GE(vy, 0);
  ASSERT_GE(vz, 0);
  EXPECT_GT(table.data.col(vy).maxCoeff(), 500.0);
  EXPECT_LT(table.data.col(vz).cwiseAbs().maxCoeff(), 1e-9);  // the sagittal model: no mediolateral force
  const kin2grf::Trial t = kin2grf::load_trial(c3d);
  EXPECT_EQ(table.data.rows(), t.markers.frames());
}

// A marker set no preset knows (the example walk's labels written the CAST way, R_KJC): estimate
// takes the mapping made from its labels and says so, and info --write-mapping writes that mapping
// as a file to edit, which estimate then reads as any mapping file, to the same forces.
TEST(CliFiles, AnUnknownMarkerSetIsMappedFromItsLabelsAndInfoWritesTheMapping) {
  const auto dir = kin2grf::test::temp_dir("cli_labels");
  std::ifstream in(example_dir() / "example_walk.trc");
  std::ostringstream text;
  text << in.rdbuf();
  std::string trc = text.str();
  for (const char* name : {"SHO", "HJC", "KJC", "AJC", "HEE", "MT1", "HLX"})
    for (const char* side : {"R", "L"}) {
      const std::string from = std::string("\t") + side + name + "\t", to = std::string("\t") + side + "_" + name + "\t";
      const auto at = trc.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      trc.replace(at, from.size(), to);
    }
  const auto renamed = dir / "cast.trc";
  std::ofstream(renamed) << trc;
  const CliRun r = run("estimate " + renamed.string() + " --mass 70 --csv " + (dir / "a.csv").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("made from the file's labels (no preset recognised"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("knee_r = R_KJC (joint centre)"), std::string::npos) << r.out;
  const auto mapping = dir / "mapping.json";
  ASSERT_EQ(run("info " + renamed.string() + " --write-mapping " + mapping.string()).status, 0);
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(mapping));
  EXPECT_EQ(j["landmarks"]["knee_r"]["marker"], "R_KJC");
  ASSERT_EQ(run("estimate " + renamed.string() + " --mass 70 --markers " + mapping.string() + " --csv " + (dir / "b.csv").string()).status, 0);
  std::ifstream a(dir / "a.csv"), b(dir / "b.csv");
  std::ostringstream sa, sb;
  sa << a.rdbuf(), sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
}

// info --write-mapping is an output like any other: never the recording itself, by name or through a link.
TEST(CliInput, WriteMappingNeverOverwritesTheRecording) {
  const auto dir = kin2grf::test::temp_dir("cli_mapping_clobber");
  const auto trc = dir / "trial.trc";
  std::filesystem::copy_file(example_trc(), trc);
  std::filesystem::create_symlink(trc, dir / "link.json");
  const auto before = std::filesystem::file_size(trc);
  for (const auto& out : {trc, dir / "link.json"}) {
    const CliRun r = run("info " + trc.string() + " --write-mapping " + out.string());
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find("is an input of this run"), std::string::npos) << r.out;
  }
  EXPECT_EQ(std::filesystem::file_size(trc), before);
}

// estimate --c3d writes the trial with the estimated platforms, reported as written; an output
// path that is the input is refused before any work, and the input is left as it was.
TEST(CliExport, EstimateWritesTheC3dWithTheEstimatedPlatforms) {
  KIN2GRF_REQUIRE_CLI();
  const auto dir = kin2grf::test::temp_dir("cli_c3d_export");
  const std::string c3d = (example_dir() / "example_walk.c3d").string(), out = (dir / "estimated.c3d").string();
  const CliRun r = run("estimate " + c3d + " --c3d " + out, "2>&1");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("wrote " + out + " (C3D"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("foot strike and foot off events added"), std::string::npos) << r.out;
  const kin2grf::Trial back = kin2grf::load_trial(out);
  ASSERT_TRUE(back.plates.has_value());
  EXPECT_EQ(back.plates->plates.size(), 2u);
  EXPECT_FALSE(back.events.empty());
  const std::string before = kin2grf::read_file_text(c3d);
  const CliRun same = run("estimate " + c3d + " --c3d " + c3d, "2>&1");
  EXPECT_NE(same.status, 0);
  EXPECT_NE(same.out.find("is an input of this run"), std::string::npos) << same.out;
  EXPECT_EQ(kin2grf::read_file_text(c3d), before);
}

// batch --c3d writes NAME.c3d beside each trial's other outputs; without --out-dir it is refused.
TEST(CliExport, BatchWritesEachTrialsC3dIntoTheOutputFolder) {
  KIN2GRF_REQUIRE_CLI();
  const auto dir = kin2grf::test::temp_dir("cli_batch_c3d");
  const auto list = dir / "list.txt";
  kin2grf::write_file_text(list.string(), "walking|lab|walk|" + (example_dir() / "example_walk.c3d").string() + " --mass 70\n");
  const CliRun r = run("batch " + list.string() + " --jobs 1 --c3d --out-dir " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.out;
  const kin2grf::Trial back = kin2grf::load_trial((dir / "out" / "walk.c3d").string());
  ASSERT_TRUE(back.plates.has_value());
  EXPECT_EQ(back.plates->plates.size(), 2u);
  EXPECT_NE(run("batch " + list.string() + " --c3d").status, 0);
}
