// OpenSim TRC and MOT/STO tests: shared files, round trips, and malformed headers.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/synth/example.hpp"
#include "test_support.hpp"

using namespace kin2grf;

TEST(Trc, RoundTripKeepsValuesAndGaps) {
  MarkerTrajectories m;
  m.rate_hz = 60;
  m.first_frame = 1;
  m.time_s = Eigen::VectorXd::LinSpaced(5, 0, 4 / 60.0);
  m.names = {"A", "B.Heel"};
  m.descriptions = {"", ""};
  m.up_axis = Axis::Y;
  for (int k = 0; k < 2; ++k) m.positions_m.push_back(Eigen::MatrixX3d::Random(5, 3));
  m.positions_m[1].row(2).setConstant(std::nan(""));
  const auto r = parse_trc(format_trc(m, "x.trc"), "x.trc");
  ASSERT_EQ(r.names, m.names);
  EXPECT_DOUBLE_EQ(r.rate_hz, 60);
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 5; ++i)
      for (int a = 0; a < 3; ++a) {
        if (std::isnan(m.positions_m[k](i, a))) EXPECT_TRUE(std::isnan(r.positions_m[k](i, a)));
        else EXPECT_NEAR(r.positions_m[k](i, a), m.positions_m[k](i, a), 1e-7);  // 8 digits in mm
      }
}

// A gap some exporters write as zeros: a marker at exactly (0, 0, 0) is read as missing, with a
// warning that counts them, as C3D points at the origin are; a single zero coordinate is a place.
TEST(Trc, AMarkerAtExactlyTheOriginIsAGap) {
  MarkerTrajectories m;
  m.rate_hz = 100;
  m.first_frame = 1;
  m.time_s = Eigen::VectorXd::LinSpaced(6, 0, 0.05);
  m.names = {"RHEE", "RTOE"};
  m.descriptions = {"", ""};
  m.up_axis = Axis::Y;
  for (int k = 0; k < 2; ++k) m.positions_m.push_back(Eigen::MatrixX3d::Constant(6, 3, 0.3 + k));
  m.positions_m[0].row(2).setZero();
  m.positions_m[0].row(3).setZero();
  m.positions_m[1].row(4) << 0.0, 0.05, 0.0;  // on two axes' zero: a place, kept
  std::vector<std::string> warnings;
  const auto r = parse_trc(format_trc(m, "zeros.trc"), "zeros.trc", &warnings);
  EXPECT_TRUE(r.positions_m[0].row(2).array().isNaN().all());
  EXPECT_TRUE(r.positions_m[0].row(3).array().isNaN().all());
  EXPECT_TRUE(r.positions_m[0].row(1).allFinite());
  EXPECT_NEAR(r.positions_m[1](4, 1), 0.05, 1e-9);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2 marker samples at exactly (0, 0, 0) are read as missing"), std::string::npos) << warnings[0];
}

TEST(Trc, MalformedFilesNameTheLineAndField) {
  const std::string head =
      "PathFileType\t4\t(X/Y/Z)\tx.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n";
  auto err = [&](const std::string& text) {
    try {
      (void)parse_trc(text, "bad.trc");
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.trc"), std::string::npos);
      return std::string(e.what());
    }
    ADD_FAILURE() << "no error for:\n" << text;
    return std::string();
  };
  EXPECT_NE(err(head + "60\t60\t1\t2\tmm\nFrame#\tTime\tA\t\t\n\t\tX1\tY1\tZ1\n\n1\t0\t1\t2\t3\n").find("NumMarkers"),
            std::string::npos);
  EXPECT_NE(err(head + "60\t60\t1\t1\tfeet\nFrame#\tTime\tA\t\t\n\t\tX1\tY1\tZ1\n\n1\t0\t1\t2\t3\n").find("Units"),
            std::string::npos);
  EXPECT_NE(err(head + "60\t60\t1\t1\tmm\nFrame#\tTime\tA\t\t\n\t\tX1\tY1\tZ1\n\n1\t0\t1\t2\t3\t4\t5\n").find("columns"),
            std::string::npos);
  EXPECT_NE(err(head + "60\t60\t1\t1\tmm\nFrame#\tTime\tA\t\t\n\t\tX1\tY1\tZ1\n\n1\t0\t1\tabc\t3\n").find("Y"),
            std::string::npos);
  err("hello\n");
  err(head + "abc\t60\t1\t1\tmm\nFrame#\tTime\tA\n\n");
}

TEST(Sto, VersionOneAndOldHeadersAndCountChecks) {
  const std::string v1 = "grf\nversion=1\nnRows=2\nnColumns=3\ninDegrees=no\nendheader\ntime\ta\tb\n0\t1\t2\n0.1\t3\t4\n";
  const Table t = parse_sto(v1, "v1.mot");
  EXPECT_EQ(t.labels.size(), 3u);
  EXPECT_DOUBLE_EQ(t.data(1, 2), 4);
  const std::string old = "name x\ndatacolumns 3\ndatarows 1\nrange 0 0\nendheader\ntime a b\n0 1 2\n";
  EXPECT_EQ(parse_sto(old, "old.mot").data.rows(), 1);
  const Table rt = parse_sto(format_sto(t), "rt.sto");
  EXPECT_EQ(rt.labels, t.labels);
  EXPECT_EQ(rt.data, t.data);
  // A row count that disagrees with the rows (OpenSim's own examples: datarows 901 over 601 rows)
  // is read, with a warning.
  const Table rows = parse_sto("grf\nnRows=3\nnColumns=3\nendheader\ntime\ta\tb\n0\t1\t2\n", "rows.mot");
  EXPECT_EQ(rows.data.rows(), 1);
  ASSERT_EQ(rows.warnings.size(), 1u);
  EXPECT_NE(rows.warnings[0].find("header says 3 rows but 1"), std::string::npos) << rows.warnings[0];
  EXPECT_THROW(parse_sto("grf\nnRows=1e300\nnColumns=3\nendheader\ntime\ta\tb\n0\t1\t2\n", "huge.mot"), InputError);
  EXPECT_THROW(parse_sto("grf\nnRows=1\nnColumns=9923372036854775808\nendheader\ntime\ta\tb\n0\t1\t2\n", "cols.mot"), InputError);
  EXPECT_THROW(parse_sto("grf\nnRows=1\nnColumns=4\nendheader\ntime\ta\tb\n0\t1\t2\n", "cols.mot"), InputError);
  EXPECT_THROW(parse_sto("grf\nendheader\ntime\ta\tb\n0\t1\n", "short.mot"), InputError);
  EXPECT_THROW(parse_sto("no header\n0 1 2\n", "nohdr.mot"), InputError);
}

TEST(Sto, GrfColumnsBecomePlates) {
  const std::string text =
      "grf\nversion=1\nnRows=3\nnColumns=10\ninDegrees=no\nendheader\n"
      "time\tground_force_r_vx\tground_force_r_vy\tground_force_r_vz\tground_force_r_px\tground_force_r_py\t"
      "ground_force_r_pz\tground_torque_r_x\tground_torque_r_y\tground_torque_r_z\n"
      "0\t1\t0\t0\t0.5\t0\t0.1\t0\t0\t0\n0.001\t2\t500\t0\t0.6\t0\t0.1\t0\t3\t0\n0.002\t3\t600\t0\t0.7\t0\t0.1\t0\t4\t0\n";
  std::vector<std::string> w;
  const auto rec = grf_from_table(parse_sto(text, "g.mot"), "g.mot", 10.0, w);
  ASSERT_TRUE(rec.has_value());
  ASSERT_EQ(rec->plates.size(), 1u);
  EXPECT_EQ(rec->plates[0].side_hint, Side::Right);
  EXPECT_TRUE(std::isnan(rec->plates[0].cop_m(0, 0))) << "unloaded: stale COP must not be used";
  EXPECT_DOUBLE_EQ(rec->plates[0].cop_m(2, 0), 0.7);
  EXPECT_NEAR(rec->rate_hz, 1000.0, 1e-9);
}

TEST(SharedOpenSim, TreadmillGrfRoundedTimesAreRegularised) {
  KIN2GRF_REQUIRE_DATA();
  const Trial t = load_trial(test::data_file("opensim_subject01_treadmill_walk/subject01_walk1_grf.mot"));
  ASSERT_TRUE(t.plates.has_value());
  EXPECT_EQ(t.plates->plates.size(), 2u);
  EXPECT_NEAR(t.plates->rate_hz, 600.0, 1e-6);
  EXPECT_FALSE(t.warnings.empty());
  const Trial run = load_trial(test::data_file("rajagopal2016_treadmill_run/grf_run.mot"));
  ASSERT_EQ(run.plates->plates.size(), 2u);
  EXPECT_EQ(run.plates->plates[0].side_hint, Side::Right);
  EXPECT_EQ(run.plates->plates[1].side_hint, Side::Left);
  EXPECT_GT(run.plates->plates[0].force_N.col(1).maxCoeff(), 1800.0);
}

TEST(SharedOpenSim, TrcFirstFrameAndUnits) {
  KIN2GRF_REQUIRE_DATA();
  const Trial t = load_trial(test::data_file("rajagopal2016_treadmill_run/motion_capture_run.trc"));
  EXPECT_EQ(t.markers.first_frame, 23);
  EXPECT_NEAR(t.markers.time_s[0], 0.23, 1e-9);
  EXPECT_EQ(t.markers.up_axis, Axis::Y);
  EXPECT_EQ(t.markers.frames(), 510);
  const int rcal = t.markers.find("RCAL");
  ASSERT_GE(rcal, 0);
  EXPECT_LT(std::abs(t.markers.positions_m[static_cast<std::size_t>(rcal)](0, 1)), 1.0) << "metres, not mm";
}

// Issue 10's crashes and silent errors in text files.
TEST(Sto, AHugeColumnLabelIsReadWithoutRecursion) {
  // A 30 KB label overflowed the stack of std::regex_match in grf_from_table.
  const std::string prefix(30000, 'a');
  std::string text = "grf\nendheader\ntime";
  for (const char* c : {"vx", "vy", "vz", "px", "py", "pz"}) text += "\t" + prefix + "ground_force_" + c;
  text += "\n0\t1\t700\t3\t0.1\t0\t0.2\n0.01\t1\t700\t3\t0.1\t0\t0.2\n";
  const Table t = parse_sto(text, "long.mot");
  std::vector<std::string> w;
  const auto rec = grf_from_table(t, "long.mot", 10.0, w);
  ASSERT_TRUE(rec.has_value());
  ASSERT_EQ(rec->plates.size(), 1u);
  EXPECT_DOUBLE_EQ(rec->plates[0].force_N(0, 1), 700.0);
}

TEST(Trc, DataRateThatDisagreesWithTheTimeColumnIsCorrected) {
  MarkerTrajectories m;
  m.rate_hz = 25;
  m.first_frame = 1;
  m.time_s = Eigen::VectorXd::LinSpaced(10, 0, 0.36);  // 0.04 s steps: 25 Hz
  m.names = {"A"};
  m.descriptions = {""};
  m.positions_m = {Eigen::MatrixX3d::Constant(10, 3, 0.5)};
  std::string text = format_trc(m, "rate.trc");
  const auto at = text.find("25\t25");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 2, "250");  // DataRate 250 Hz over a 25 Hz Time column
  std::vector<std::string> w;
  const auto back = parse_trc(text, "rate.trc", &w);
  EXPECT_NEAR(back.rate_hz, 25.0, 1e-9);
  bool warned = false;
  for (const auto& s : w) warned = warned || s.find("DataRate says 250") != std::string::npos;
  EXPECT_TRUE(warned);
  // A Frame# of 1e300 is refused, not cast.
  std::string bad = format_trc(m, "frame.trc");
  const auto row = bad.find("\n1\t");
  ASSERT_NE(row, std::string::npos);
  bad.replace(row + 1, 1, "1e300");
  EXPECT_THROW((void)parse_trc(bad, "frame.trc", &w), InputError);
}

TEST(Trc, ARepeatedLabelIsNamedNotSilentlyShadowed) {
  MarkerTrajectories m;
  m.rate_hz = 100;
  m.first_frame = 1;
  m.time_s = Eigen::VectorXd::LinSpaced(5, 0, 0.04);
  m.names = {"RHEE", "RBIC"};
  m.descriptions = {"", ""};
  m.positions_m = {Eigen::MatrixX3d::Constant(5, 3, 0.1), Eigen::MatrixX3d::Constant(5, 3, 1.2)};
  std::string text = format_trc(m, "dup.trc");
  const auto at = text.find("RBIC");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 4, "RHEE");
  std::vector<std::string> w;
  const auto back = parse_trc(text, "dup.trc", &w);
  ASSERT_EQ(back.names.size(), 2u);
  EXPECT_EQ(back.names[0], "RHEE");
  EXPECT_EQ(back.names[1], "RHEE#2");
  ASSERT_FALSE(w.empty());
  EXPECT_NE(w[0].find("repeated"), std::string::npos) << w[0];
}

TEST(Trc, AHeaderOfManyMarkersOverManyShortRowsIsRefusedBeforeAllocating) {
  // 20,000 markers named, 20,000 rows holding only Frame# and Time: 1.2e9 values (9.6 GB) from a
  // file of a few hundred KB.
  std::string s = "PathFileType\t4\t(X/Y/Z)\tx.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n";
  s += "100\t100\t20000\t20000\tmm\nFrame#\tTime";
  for (int k = 0; k < 20000; ++k) s += "\tM" + std::to_string(k) + "\t\t";
  s += "\n\t\n";
  for (int i = 0; i < 20000; ++i) s += std::to_string(i + 1) + "\t" + std::to_string(i) + "\n";
  try {
    (void)parse_trc(s, "big.trc");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("markers over 20000 rows"), std::string::npos) << e.what();
  }
}

// The GRF .mot and the CSV are written row by row as they are made (never held whole: issue 10's
// memory): byte for byte what the whole-table writers (grf_table + format_sto, results_table)
// give, over more than one of the writers' 64 KB buffers.
TEST(Outputs, StreamedWritersWriteWhatTheWholeTablesWould) {
  SyntheticOptions so;
  so.duration_s = 12.0;
  const EstimateResult r = test::run(so);
  const auto dir = test::temp_dir("streamed_outputs");
  const std::string mot = (dir / "e.mot").string(), csv = (dir / "e.csv").string();
  write_grf_mot(mot, r, "{\"a\":1}");
  write_results_csv(csv, r);
  const auto plates = as_lab_plates(r);
  Table t = grf_table(r.time_s, plates[0], plates[1]);
  t.name = "kin2grf_estimated_grf";
  t.header["DataType"] = "double";
  t.header["kin2grf_version"] = KIN2GRF_VERSION;
  t.header["kin2grf_settings"] = "{\"a\":1}";
  t.header["kin2grf_frame"] = kLabFrameHeader;
  const std::string mot_text = read_file_text(mot);
  EXPECT_GT(mot_text.size(), std::size_t{1} << 16);
  EXPECT_EQ(mot_text, format_sto(t));
  const std::string csv_text = read_file_text(csv);
  EXPECT_GT(csv_text.size(), std::size_t{1} << 17);
  EXPECT_EQ(csv_text, format_results_csv(r));
  // The CSV's rows are results_table's (6 significant digits).
  const ResultsTable table = results_table(r);
  const Table back = parse_sto(mot_text, "e.mot");
  ASSERT_EQ(back.data.rows(), r.time_s.size());
  EXPECT_NEAR(back.data(r.time_s.size() / 2, 2), plates[0].force_N(r.time_s.size() / 2, 1), 1e-4 * 1000);
  EXPECT_EQ(table.values.rows(), r.time_s.size());
  EXPECT_EQ(static_cast<std::size_t>(table.values.cols()), results_columns().size());
}

// read_trc maps the file and lets the rows' text go as they are parsed (issue 10's memory):
// parse_trc tells which byte ranges it is done with. They lie past the header, inside the text,
// never overlap, and the markers are those of a parse that releases nothing.
TEST(Trc, TheRowsTextIsReleasedOnlyOnceParsedAndTheMarkersAreTheSame) {
  SyntheticWalkOptions wo;
  wo.duration_s = 60.0;
  wo.rate_hz = 500.0;
  const std::string text = format_trc(make_synthetic_walk(wo).trial.markers, "walk.trc");
  ASSERT_GT(text.size(), std::size_t{8} << 20);
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  std::mutex lock;
  const MarkerTrajectories released = parse_trc(text, "walk.trc", nullptr, [&](std::size_t b, std::size_t e) {
    const std::lock_guard<std::mutex> g(lock);
    ranges.emplace_back(b, e);
  });
  const MarkerTrajectories kept = parse_trc(text, "walk.trc");
  ASSERT_FALSE(ranges.empty());
  std::sort(ranges.begin(), ranges.end());
  const std::size_t header_end = text.find("\n\n") + 2;  // the header's 5 lines and the blank one
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    EXPECT_GE(ranges[k].first, header_end);
    EXPECT_LE(ranges[k].first, ranges[k].second);
    EXPECT_LE(ranges[k].second, text.size());
    if (k) {
      EXPECT_LE(ranges[k - 1].second, ranges[k].first);
    }
  }
  ASSERT_EQ(released.names, kept.names);
  for (std::size_t k = 0; k < kept.positions_m.size(); ++k)
    EXPECT_TRUE(released.positions_m[k].cwiseEqual(kept.positions_m[k]).all()) << kept.names[k];
}

// The 10-minute fuzz run of issue 31 found a TRC header of thousands of one repeated label taking
// seconds: naming the k-th NAME#k searched NAME#2, NAME#3, ... for each. It is linear now.
TEST(Trc, ThousandsOfOneRepeatedLabelAreNamedAtOnce) {
  const int n = 20000;
  std::string text = "PathFileType\t4\t(X/Y/Z)\tx.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n100\t100\t2\t" +
                     std::to_string(n) + "\tmm\nFrame#\tTime";
  for (int k = 0; k < n; ++k) text += "\tM\t\t";
  text += "\n\t";
  for (int k = 0; k < n; ++k) text += "\tX\tY\tZ";
  text += "\n";
  for (int f = 1; f <= 2; ++f) {
    text += std::to_string(f) + "\t" + std::to_string(0.01 * (f - 1));
    for (int k = 0; k < n; ++k) text += "\t1\t2\t3";
    text += "\n";
  }
  std::vector<std::string> warnings;
  const auto start = std::chrono::steady_clock::now();
  const auto m = parse_trc(text, "x.trc", &warnings);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  ASSERT_EQ(m.names.size(), static_cast<std::size_t>(n));
  EXPECT_EQ(m.names[0], "M");
  EXPECT_EQ(m.names[1], "M#2");
  EXPECT_EQ(m.names[n - 1], "M#" + std::to_string(n));
  EXPECT_EQ(warnings.size(), 11u);  // ten named, then one for the rest
}

// ---------------------------------------------------------------------------------------------
// The TRC kin2grf writes for OpenSim, read by OpenSim's own rules (opensim-core,
// OpenSim/Common/FileAdapter.cpp and TRCFileAdapter.cpp, TRCFileAdapter::extendRead), restated
// here rather than through kin2grf's reader:
// - a line is split by FileAdapter::tokenize on the delimiters "\t\r" (data) or " \t\r" (first
//   line); a run of delimiters is one, so an empty field is no token at all;
// - getNextLine skips lines with no token;
// - line 1 starts with PathFileType; line 2 is exactly the 8 keys DataRate CameraRate NumFrames
//   NumMarkers Units OrigDataRate OrigDataStartFrame OrigNumFrames; line 3 has as many values;
// - line 4 is Frame#, Time and NumMarkers labels; line 5 is X1 Y1 Z1 X2 ...;
// - every data row has exactly 3 NumMarkers + 2 tokens (else RowLengthMismatch), each read by
//   std::stod (which takes "NaN").
namespace {
/// OpenSim's FileAdapter::tokenize: `line` split on any of `delims`, a run of them one split, so
/// an empty field is no token at all.
std::vector<std::string> opensim_tokenize(const std::string& line, const std::string& delims) {
  std::vector<std::string> tokens;
  std::string cur;
  for (const char c : line) {
    if (delims.find(c) != std::string::npos) {
      if (!cur.empty()) tokens.push_back(cur), cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) tokens.push_back(cur);
  return tokens;
}

::testing::AssertionResult opensim_reads_trc(const std::string& text) {
  const auto tokenize = opensim_tokenize;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  if (tokenize(line, " \t\r").empty() || tokenize(line, " \t\r")[0] != "PathFileType") return ::testing::AssertionFailure() << "MissingHeader";
  auto next = [&] {
    while (std::getline(in, line)) {
      auto t = tokenize(line, "\t\r");
      if (!t.empty()) return t;
    }
    return std::vector<std::string>{};
  };
  const std::vector<std::string> keys_expected = {"DataRate", "CameraRate", "NumFrames", "NumMarkers", "Units", "OrigDataRate",
                                                  "OrigDataStartFrame", "OrigNumFrames"};
  const auto keys = next();
  if (keys != keys_expected) return ::testing::AssertionFailure() << "metadata keys";
  const auto values = next();
  if (values.size() != keys.size()) return ::testing::AssertionFailure() << "MetaDataLengthMismatch";
  const std::size_t markers = std::stoul(values[3]);
  const auto labels = next();
  if (labels.size() != markers + 2 || labels[0] != "Frame#" || labels[1] != "Time")
    return ::testing::AssertionFailure() << "IncorrectNumColumnLabels: " << labels.size() << " for " << markers << " markers";
  const auto xyz = next();
  for (std::size_t k = 0; k < markers; ++k)
    for (int a = 0; a < 3; ++a)
      if (xyz.at(3 * k + static_cast<std::size_t>(a)) != std::string(1, "XYZ"[a]) + std::to_string(k + 1))
        return ::testing::AssertionFailure() << "UnexpectedColumnLabel " << xyz.at(3 * k + static_cast<std::size_t>(a));
  std::size_t rows = 0;
  for (auto row = next(); !row.empty(); row = next(), ++rows) {
    if (row.size() != 3 * markers + 2)
      return ::testing::AssertionFailure() << "RowLengthMismatch at data row " << rows + 1 << ": " << row.size() << " tokens, expected "
                                           << 3 * markers + 2;
    for (const auto& t : row) {
      std::size_t used = 0;
      (void)std::stod(t, &used);
      if (used == 0) return ::testing::AssertionFailure() << "not a number: " << t;
    }
  }
  if (rows != std::stoul(values[2])) return ::testing::AssertionFailure() << rows << " rows, NumFrames " << values[2];
  return ::testing::AssertionSuccess();
}
}  // namespace

// The .mot/.sto files kin2grf writes, read by OpenSim's own rules (opensim-core,
// OpenSim/Common/DelimFileAdapter.h, DelimFileAdapter::extendRead, with STOFileAdapter's
// delimiters; FileAdapter picks STOFileAdapter for both .sto and .mot), restated here rather than
// through kin2grf's reader:
// - header lines up to one that is "endheader" alone (spaces or tabs around it; a trailing \r
//   removed); a header line "key=value" with both non-empty is metadata, and a DataType key must
//   say "double";
// - then lines are split on the tab alone (STOFileAdapter: "\t"), a run of tabs being one, and a
//   line with no token is skipped;
// - the first such line is the labels, the first of which must be "time";
// - every row has as many values as labels (else RowLengthMismatch), each read by std::stod;
// - TimeSeriesTable takes rows in strictly increasing time only.
// `labels` receives the labels after "time".
namespace {
::testing::AssertionResult opensim_reads_sto(const std::string& text, std::vector<std::string>* labels_out = nullptr,
                                             std::vector<std::vector<double>>* rows_out = nullptr) {
  const auto tokenize = [](const std::string& line) { return opensim_tokenize(line, "\t"); };  // STOFileAdapter's delimiter
  std::istringstream in(text);
  std::string line;
  bool ended = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto a = line.find_first_not_of(" \t"), b = line.find_last_not_of(" \t");
    if (a != std::string::npos && line.substr(a, b - a + 1) == "endheader") {
      ended = true;
      break;
    }
    const auto eq = line.rfind('=');
    if (eq != std::string::npos && eq > 0 && eq + 1 < line.size()) {
      std::string key = line.substr(0, eq);
      key = key.substr(key.find_first_not_of(' '));
      key = key.substr(0, key.find_last_not_of(' ') + 1);
      if (key == "DataType" && line.substr(eq + 1) != "double") return ::testing::AssertionFailure() << "DataTypeMismatch";
    }
  }
  if (!ended) return ::testing::AssertionFailure() << "no endheader line";
  auto next = [&] {
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      auto t = tokenize(line);
      if (!t.empty()) return t;
    }
    return std::vector<std::string>{};
  };
  auto labels = next();
  if (labels.empty()) return ::testing::AssertionFailure() << "No column labels detected";
  if (labels[0] != "time") return ::testing::AssertionFailure() << "UnexpectedColumnLabel " << labels[0] << " (expected time)";
  labels.erase(labels.begin());
  double last_time = -std::numeric_limits<double>::infinity();
  std::size_t rows = 0;
  for (auto row = next(); !row.empty(); row = next(), ++rows) {
    if (row.size() != labels.size() + 1)
      return ::testing::AssertionFailure() << "RowLengthMismatch at data row " << rows + 1 << ": " << row.size() - 1 << " values for "
                                           << labels.size() << " labels";
    std::vector<double> values;
    for (const auto& t : row) {
      std::size_t used = 0;
      values.push_back(std::stod(t, &used));
      if (used != t.size()) return ::testing::AssertionFailure() << "not a number: " << t;
    }
    if (!(values[0] > last_time)) return ::testing::AssertionFailure() << "time not increasing at data row " << rows + 1;
    last_time = values[0];
    if (rows_out) rows_out->push_back(std::move(values));
  }
  if (rows == 0) return ::testing::AssertionFailure() << "no data rows";
  if (labels_out) *labels_out = labels;
  return ::testing::AssertionSuccess();
}

/// The ExternalLoads file's identifiers (force_identifier, point_identifier, torque_identifier,
/// each + x, y, z as ExternalForce reads them) among the .mot's labels.
::testing::AssertionResult external_loads_columns_exist(const std::string& xml, const std::vector<std::string>& labels) {
  for (const std::string tag : {"force_identifier", "point_identifier", "torque_identifier"}) {
    int found = 0;
    for (std::size_t p = 0; (p = xml.find("<" + tag + ">", p)) != std::string::npos; ++found) {
      const auto a = p + tag.size() + 2, b = xml.find("</" + tag + ">", a);
      const std::string id = xml.substr(a, b - a);
      for (const char c : std::string("xyz"))
        if (std::find(labels.begin(), labels.end(), id + c) == labels.end())
          return ::testing::AssertionFailure() << tag << " " << id << ": no column " << id + c;
      p = b;
    }
    if (found != 2) return ::testing::AssertionFailure() << found << " " << tag << " (two feet expected)";
  }
  return ::testing::AssertionSuccess();
}
}  // namespace

// A trial with gaps, the last marker's among them (the trailing empty fields OpenSim dropped:
// walking2.c3d's export had 835 of 1249 rows short), is read by OpenSim's rules and, by
// kin2grf's reader, back with the same gaps.
TEST(Trc, AnExportWithGapsIsReadByOpenSimsRules) {
  Trial t = make_example_walk();
  auto& m = t.markers;
  m.positions_m.back().middleRows(10, 20).setConstant(std::numeric_limits<double>::quiet_NaN());
  m.positions_m.front().middleRows(50, 5).setConstant(std::numeric_limits<double>::quiet_NaN());
  m.positions_m[3](70, 1) = std::numeric_limits<double>::quiet_NaN();
  const std::string text = format_trc(m, "gaps.trc");
  EXPECT_TRUE(opensim_reads_trc(text));
  const auto back = parse_trc(text, "gaps.trc");
  EXPECT_FALSE(back.positions_m.back().row(15).allFinite());
  EXPECT_TRUE(back.positions_m.back().row(9).allFinite());
  EXPECT_FALSE(back.positions_m.front().row(52).allFinite());
  EXPECT_TRUE(std::isnan(back.positions_m[3](70, 1)));
}

// Every development trial's OpenSim export (estimate --opensim) is read by OpenSim's rules.
TEST(SharedOpenSim, EveryExportsTrcIsReadByOpenSimsRules) {
  KIN2GRF_REQUIRE_DATA();
  KIN2GRF_REQUIRE_CLI();
  std::ifstream list(std::string(KIN2GRF_SOURCE_DIR) + "/scripts/trials.txt");
  ASSERT_TRUE(list);
  const auto dir = test::temp_dir("opensim_rules");
  int trials = 0;
  for (std::string line; std::getline(list, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::size_t bar = 0;
    for (int k = 0; k < 3; ++k) bar = line.find('|', bar) + 1;
    std::string args = line.substr(bar);
    for (std::size_t p; (p = args.find("DATA")) != std::string::npos;) args.replace(p, 4, test::data_dir());
    if (const auto p = args.find("--plates "); p != std::string::npos) args.erase(p, args.find(' ', p + 9) - p);
    const auto out = dir / std::to_string(trials++);
    const std::string cmd = std::string(KIN2GRF_CLI) + " estimate " + args + " --opensim " + out.string() + " >/dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::vector<std::string> labels;
    std::string xml;
    for (const auto& e : std::filesystem::directory_iterator(out)) {
      if (e.path().extension() == ".trc") {
        EXPECT_TRUE(opensim_reads_trc(read_file_text(e.path().string()))) << line;
      }
      if (e.path().extension() == ".mot") {
        EXPECT_TRUE(opensim_reads_sto(read_file_text(e.path().string()), &labels)) << line;
      }
      if (e.path().extension() == ".xml") xml = read_file_text(e.path().string());
    }
    EXPECT_TRUE(external_loads_columns_exist(xml, labels)) << line;
  }
  EXPECT_GE(trials, 10);
}

// The mediolateral force reaches OpenSim: the bundled recorded walk's export with --model 3d
// (--mediolateral takes the same path) carries it in the .mot's Z columns (OpenSim's lateral
// axis) and the COP's lateral place in the point's Z, read by OpenSim's rules; without it the
// force is zero, as the sagittal model's lateral force is, and the point is the foot's midpoint.
TEST(OpenSimExport, TheMediolateralForceIsInTheGrfMotsZColumns) {
  KIN2GRF_REQUIRE_CLI();
  const auto dir = test::temp_dir("opensim_ml");
  const std::string walk = std::string(KIN2GRF_SOURCE_DIR) + "/data/example/walking2.c3d";
  double largest[2] = {0, 0};
  std::vector<double> point_z[2];
  for (int with = 0; with < 2; ++with) {
    const auto out = dir / std::to_string(with);
    const std::string cmd = std::string(KIN2GRF_CLI) + " estimate " + walk + " --mass 64.9" + (with ? " --model 3d" : "") +
                            " --opensim " + out.string() + " >/dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::vector<std::string> labels;
    std::vector<std::vector<double>> rows;
    ASSERT_TRUE(opensim_reads_sto(read_file_text((out / "walking2_grf.mot").string()), &labels, &rows));
    const auto column = [&](const std::string& name) {
      const auto col = std::find(labels.begin(), labels.end(), name) - labels.begin() + 1;  // after time
      EXPECT_LT(static_cast<std::size_t>(col), labels.size() + 1) << name;
      return static_cast<std::size_t>(col);
    };
    for (const std::string name : {"ground_force_vz", "1_ground_force_vz"}) {
      const auto col = column(name);
      for (const auto& r : rows) largest[with] = std::max(largest[with], std::abs(r[col]));
    }
    const auto vy = column("ground_force_vy"), pz = column("ground_force_pz");
    for (const auto& r : rows)
      if (r[vy] > 0.5 * 64.9 * 9.81) point_z[with].push_back(r[pz]);  // the right foot under load
    // The free moment: OpenSim's torque columns are there (zero: not estimated).
    (void)column("ground_torque_y");
  }
  EXPECT_EQ(largest[0], 0.0);
  EXPECT_GT(largest[1], 10.0);                // N: a walk's lateral force peaks at 5-10 % body weight
  EXPECT_LT(largest[1], 0.3 * 64.9 * 9.81);
  // The 3D COP moves across the foot as it rolls (the heel-forefoot line); the midpoint does not
  // move across more than the foot itself does.
  ASSERT_EQ(point_z[0].size(), point_z[1].size());
  ASSERT_FALSE(point_z[1].empty());
  double moved = 0;
  for (std::size_t i = 0; i < point_z[0].size(); ++i) moved = std::max(moved, std::abs(point_z[1][i] - point_z[0][i]));
  EXPECT_GT(moved, 0.002);
  EXPECT_LT(moved, 0.05);
}

// The -o file and the plates' .mot kin2grf reads are also read by OpenSim's rules.
TEST(OpenSimExport, TheGrfMotOfEstimateIsReadByOpenSimsRules) {
  KIN2GRF_REQUIRE_CLI();
  const auto dir = test::temp_dir("opensim_o");
  const std::string walk = std::string(KIN2GRF_SOURCE_DIR) + "/data/example/walking2.c3d";
  for (const std::string extra : {"", " --lab-frame"}) {
    const auto mot = dir / ("grf" + std::to_string(extra.size()) + ".mot");
    const std::string cmd =
        std::string(KIN2GRF_CLI) + " estimate " + walk + " --mass 64.9 -o " + mot.string() + extra + " >/dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::vector<std::string> labels;
    EXPECT_TRUE(opensim_reads_sto(read_file_text(mot.string()), &labels)) << extra;
    EXPECT_EQ(labels.size(), 18u) << extra;
  }
  // The rules restated above refuse what OpenSim refuses.
  EXPECT_FALSE(opensim_reads_sto("endheader\ntime x\n0 1\n"));             // spaces: one label, not "time"
  EXPECT_FALSE(opensim_reads_sto("endheader\ntime\tx\n0\t1\n0\t2\n"));  // time not increasing
  EXPECT_FALSE(opensim_reads_sto("endheader\ntime\tx\ty\n0\t1\n"));      // a row short
  EXPECT_FALSE(opensim_reads_sto("DataType=Vec3\nendheader\ntime\tx\n0\t1\n"));
  EXPECT_TRUE(opensim_reads_sto("nRows=1\n endheader \r\n\ntime\tx\n0\t1\n"));
}
