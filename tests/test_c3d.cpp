// C3D reader/writer tests: real files from ../shared/data (skipped when absent), round trips in
// every encoding, and corrupt files that must give a clear error, never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>

#include "kin2grf/error.hpp"
#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/force_plate.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/summary.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/workflow/batch.hpp"
#include "kin2grf/workflow/settings.hpp"
#include "test_support.hpp"

using namespace kin2grf;

namespace {

Trial small_trial() {
  Trial t;
  t.format = "C3D";
  auto& m = t.markers;
  m.rate_hz = 100.0;
  m.first_frame = 1;
  const int n = 20;
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / 100.0);
  m.names = {"RHEE", "RTOE", "LASI"};
  m.descriptions = {"heel", "", "pelvis"};
  for (int k = 0; k < 3; ++k) {
    Eigen::MatrixX3d P(n, 3);
    for (int i = 0; i < n; ++i) P.row(i) << 0.1 * k + 0.01 * i, 0.2 - 0.003 * i, 0.05 + 0.4 * k;
    m.positions_m.push_back(P);
  }
  m.positions_m[1].row(5).setConstant(std::nan(""));
  ForcePlateRecording rec;
  rec.rate_hz = 400.0;
  const int ns = n * 4;
  rec.time_s = Eigen::VectorXd::LinSpaced(ns, 0.0, (ns - 1) / 400.0);
  ForcePlate fp;
  fp.name = "FP1";
  fp.type = 2;
  fp.has_geometry = true;
  fp.corners_m = {Eigen::Vector3d(0.5, 0.6, 0), Eigen::Vector3d(0.0, 0.6, 0), Eigen::Vector3d(0.0, 0.0, 0),
                  Eigen::Vector3d(0.5, 0.0, 0)};
  fp.centre_m = Eigen::Vector3d(0.25, 0.3, 0);
  fp.origin_m = Eigen::Vector3d(0.001, -0.002, -0.04);
  Eigen::Matrix<double, 3, 4> C;
  for (int c = 0; c < 4; ++c) C.col(c) = fp.corners_m[static_cast<std::size_t>(c)];
  fp.lab_R_plate = plate_axes(C);
  fp.force_N.resize(ns, 3);
  fp.cop_m.resize(ns, 3);
  fp.free_moment_Nm.resize(ns, 3);
  fp.moment_centre_Nm = Eigen::MatrixX3d::Constant(ns, 3, std::nan(""));
  for (int i = 0; i < ns; ++i) {
    const double s = std::sin(M_PI * i / (ns - 1));
    fp.force_N.row(i) << 50 * s, -10 * s, 700 * s + 1e-9;
    fp.cop_m.row(i) << 0.2 + 0.1 * i / ns, 0.3, 0.0;
    fp.free_moment_Nm.row(i) << 0, 0, 2 * s;
  }
  rec.plates.push_back(fp);
  t.plates = rec;
  t.events = {{"Foot Strike", Side::Right, 0.05}, {"Foot Off", Side::Left, 0.12}};
  t.body_mass_kg = 71.5;
  return t;
}

std::string expect_input_error(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  try {
    (void)read_c3d_bytes(bytes, name);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << "message must name the file: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << name << ": expected an InputError";
  return "";
}

}  // namespace

TEST(C3dRoundTrip, EveryEncodingReadsBackTheSameTrial) {
  const Trial t = small_trial();
  for (auto proc : {C3dProcessor::Intel, C3dProcessor::DEC, C3dProcessor::SGI}) {
    for (bool fl : {true, false}) {
      C3dWriteOptions o;
      o.processor = proc;
      o.float_data = fl;
      o.point_scale_mm = 0.1;
      o.analog_samples_per_frame = 4;
      const auto bytes = write_c3d_bytes(t, o);
      const std::string what = "processor " + std::to_string(static_cast<int>(proc)) + (fl ? " float" : " int");
      const Trial r = read_c3d_bytes(bytes, "roundtrip.c3d");
      ASSERT_EQ(r.markers.names, t.markers.names) << what;
      EXPECT_EQ(r.markers.descriptions[0], "heel");
      const double tol = fl ? 1e-6 : 5.1e-5;  // float32 in mm, or 0.1 mm integer steps
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_TRUE(test::matrices_near(r.markers.positions_m[k], t.markers.positions_m[k], tol)) << what + " marker";
      ASSERT_TRUE(r.plates.has_value()) << what;
      ASSERT_EQ(r.plates->plates.size(), 1u);
      const auto& a = r.plates->plates[0];
      const auto& b = t.plates->plates[0];
      EXPECT_DOUBLE_EQ(r.plates->rate_hz, 400.0);
      EXPECT_TRUE(test::matrices_near(a.force_N, b.force_N, fl ? 1e-3 : 0.05)) << what + " force";
      for (Eigen::Index i = 0; i < a.force_N.rows(); ++i) {
        if (b.force_N(i, 2) < 50) continue;  // COP is ill-conditioned at tiny loads
        for (int c = 0; c < 2; ++c) EXPECT_NEAR(a.cop_m(i, c), b.cop_m(i, c), fl ? 1e-5 : 5e-4) << what << " cop " << i;
        EXPECT_NEAR(a.free_moment_Nm(i, 2), b.free_moment_Nm(i, 2), fl ? 1e-3 : 0.05) << what;
      }
      ASSERT_EQ(r.events.size(), 2u);
      EXPECT_EQ(r.events[0].label, "Foot Strike");
      EXPECT_EQ(r.events[0].side, Side::Right);
      EXPECT_NEAR(r.events[1].time_s, 0.12, 1e-6);
      ASSERT_TRUE(r.body_mass_kg.has_value());
      EXPECT_NEAR(*r.body_mass_kg, 71.5, 1e-4);
    }
  }
}

TEST(C3dCorrupt, EveryStructuralErrorNamesTheFileAndField) {
  C3dWriteOptions o;
  o.analog_samples_per_frame = 4;
  const auto good = write_c3d_bytes(small_trial(), o);
  ASSERT_NO_THROW(read_c3d_bytes(good, "good.c3d"));

  // Truncated in the data section.
  auto b = good;
  b.resize(b.size() - 700);
  EXPECT_NE(expect_input_error(b, "truncated.c3d").find("truncated"), std::string::npos);
  // Shorter than the header.
  b.assign(good.begin(), good.begin() + 100);
  expect_input_error(b, "tiny.c3d");
  // Not a C3D at all.
  b = good;
  b[1] = 0x12;
  EXPECT_NE(expect_input_error(b, "notc3d.c3d").find("0x50"), std::string::npos);
  // Parameter pointer out of range.
  b = good;
  b[0] = 200;
  expect_input_error(b, "pointer.c3d");
  // Unknown processor type.
  b = good;
  b[512 + 3] = 99;
  EXPECT_NE(expect_input_error(b, "processor.c3d").find("processor type 99"), std::string::npos);
  // Empty file.
  expect_input_error({}, "empty.c3d");
}

TEST(C3dCorrupt, NaNScaleAndAbsurdCountsAreRejected) {
  C3dWriteOptions o;
  o.analog_samples_per_frame = 4;
  Trial t = small_trial();
  auto good = write_c3d_bytes(t, o);
  // Find POINT:SCALE's float in the parameter section and set it to NaN.
  auto find = [&](const std::string& name) {
    for (std::size_t i = 512; i + name.size() < 1536; ++i)
      if (std::equal(name.begin(), name.end(), good.begin() + static_cast<long>(i))) return i;
    return std::size_t{0};
  };
  std::size_t pos = find("SCALE");
  ASSERT_GT(pos, 0u);
  auto b = good;
  const std::size_t data = pos + 5 + 2 + 2;  // name, offset, type, ndims (0 dims)
  b[data] = 0x00; b[data + 1] = 0x00; b[data + 2] = 0xC0; b[data + 3] = 0x7F;  // quiet NaN (Intel)
  EXPECT_NE(expect_input_error(b, "nanscale.c3d").find("POINT:SCALE"), std::string::npos);
  // Declared frame count far larger than the data.
  b = good;
  pos = find("ACTUAL_END_FIELD");
  ASSERT_GT(pos, 0u);
  const std::size_t end_field = pos + 16 + 2 + 1 + 1 + 1;  // name, offset, type, ndims, dim
  b[end_field] = 0xFF; b[end_field + 1] = 0x7F;              // last frame 32767
  EXPECT_NE(expect_input_error(b, "frames.c3d").find("truncated"), std::string::npos);
  // A parameter whose dimensions run past the parameter section.
  b = good;
  pos = find("LABELS");
  ASSERT_GT(pos, 0u);
  b[pos + 6 + 2 + 1 + 1] = 250;  // first dimension of POINT:LABELS
  b[pos + 6 + 2 + 1 + 2] = 250;
  expect_input_error(b, "dims.c3d");
}

TEST(C3dCorrupt, RandomByteFlipsNeverCrash) {
  C3dWriteOptions o;
  o.analog_samples_per_frame = 4;
  const auto good = write_c3d_bytes(small_trial(), o);
  std::mt19937 rng(12345);
  int errors = 0, reads = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    auto b = good;
    const int flips = 1 + static_cast<int>(rng() % 6);
    for (int f = 0; f < flips; ++f) {
      // Favour the header and parameter section, where structure lives.
      const std::size_t pos = (rng() % 4 == 0) ? rng() % b.size() : rng() % std::min<std::size_t>(b.size(), 1536);
      b[pos] = static_cast<std::uint8_t>(rng());
    }
    try {
      (void)read_c3d_bytes(b, "flip.c3d");
      ++reads;
    } catch (const InputError&) {
      ++errors;
    }
  }
  // Anything but a trial or an InputError fails the test by escaping. Both outcomes occur: a flip
  // in the structure is refused, one in a sample still reads (the flips reach both).
  EXPECT_GT(errors, 0);
  EXPECT_GT(reads, 0);
}

TEST(C3dShared, Walking2MatchesOpenSimReferenceAt2p80s) {
  KIN2GRF_REQUIRE_DATA();
  const Trial t = read_c3d(test::data_file("opensim_c3d_overground_walk/walking2.c3d"));
  ASSERT_TRUE(t.plates.has_value());
  ASSERT_EQ(t.plates->plates.size(), 2u);
  const Table ref = read_sto(test::data_file("opensim_c3d_overground_walk/std_cop_walking2_grfs.sto"));
  int row = -1;
  for (Eigen::Index r = 0; r < ref.data.rows(); ++r)
    if (std::abs(ref.data(r, 0) - 2.80) < 1e-6) row = static_cast<int>(r);
  ASSERT_GE(row, 0);
  // OpenSim's reference time 0 is the first analog sample.
  const Eigen::Index k = static_cast<Eigen::Index>(std::lround(2.80 * t.plates->rate_hz));
  for (int p = 0; p < 2; ++p) {
    const auto& fp = t.plates->plates[static_cast<std::size_t>(p)];
    const std::string pre = std::to_string(p + 1) + "_";
    for (int a = 0; a < 3; ++a) {
      const double f_ref = ref.data(row, ref.column("f" + pre + std::to_string(a + 1)));
      EXPECT_NEAR(fp.force_N(k, a), f_ref, 0.1) << "plate " << p + 1 << " force axis " << a;
    }
    if (std::abs(fp.force_N(k, 2)) < 20) continue;  // plate 2 unloaded at 2.80 s
    for (int a = 0; a < 2; ++a) {
      const double p_ref_mm = ref.data(row, ref.column("p" + pre + std::to_string(a + 1)));
      EXPECT_NEAR(fp.cop_m(k, a) * 1000.0, p_ref_mm, 0.5) << "plate " << p + 1 << " COP axis " << a;
    }
  }
  // The documented values of the data README.
  EXPECT_NEAR(t.plates->plates[0].force_N(k, 2), 948.32, 0.1);
  EXPECT_NEAR(t.plates->plates[0].cop_m(k, 0) * 1000, 781.52, 0.5);
}

TEST(C3dShared, IntelDecSgiEncodingsReadIdentically) {
  KIN2GRF_REQUIRE_DATA();
  const Trial pi = read_c3d(test::data_file("c3d_format_samples/Eb015pi.c3d"));
  const Trial sr = read_c3d(test::data_file("c3d_format_samples/Eb015sr.c3d"));
  const Trial vr = read_c3d(test::data_file("c3d_format_samples/Eb015vr.c3d"));
  EXPECT_EQ(pi.encoding, "Intel, integer");
  EXPECT_EQ(sr.encoding, "SGI/MIPS, float");
  EXPECT_EQ(vr.encoding, "DEC, float");
  for (const Trial* o : {&sr, &vr}) {
    ASSERT_EQ(o->markers.names, pi.markers.names);
    for (std::size_t k = 0; k < pi.markers.names.size(); ++k)
      EXPECT_TRUE(test::matrices_near(o->markers.positions_m[k], pi.markers.positions_m[k], 1e-6)) << pi.markers.names[k];
    ASSERT_TRUE(o->plates && pi.plates);
    for (std::size_t p = 0; p < pi.plates->plates.size(); ++p)
      EXPECT_TRUE(test::matrices_near(o->plates->plates[p].force_N, pi.plates->plates[p].force_N, 1e-3)) << "force";
  }
  // Marker 1 at frame 101 (README): (250.67, 227.25, 35.33) mm.
  EXPECT_NEAR(pi.markers.positions_m[0](100, 0) * 1000, 250.67, 0.01);
  EXPECT_NEAR(vr.markers.positions_m[0](100, 1) * 1000, 227.25, 0.01);
  EXPECT_NEAR(sr.markers.positions_m[0](100, 2) * 1000, 35.33, 0.01);
}

TEST(C3dShared, Type4CalMatrixFirstIndexFastestMatchesType2) {
  KIN2GRF_REQUIRE_DATA();
  // Assumed order: CAL_MATRIX element (row i, column j) stored at i + 6 j (first index fastest,
  // like every C3D array), loads = CAL_MATRIX * raw channels.
  const Trial t2 = read_c3d(test::data_file("c3d_format_samples/TYPE-2.C3D"));
  const Trial t4 = read_c3d(test::data_file("c3d_format_samples/TYPE-4.C3D"));
  ASSERT_EQ(t4.plates->plates[0].type, 4);
  const double peak2 = t2.plates->plates[0].force_N.col(2).maxCoeff();
  const double peak4 = t4.plates->plates[0].force_N.col(2).maxCoeff();
  EXPECT_NEAR(peak2, 398.0, 4.0);
  EXPECT_LT(std::abs(peak4 - peak2) / peak2, 0.03) << "TYPE-2 " << peak2 << " N, TYPE-4 " << peak4 << " N";
}

TEST(C3dShared, FirstFrameOtherThanOneAndEvents) {
  KIN2GRF_REQUIRE_DATA();
  const Trial t = read_c3d(test::data_file("btk_plugingait_walk/PiG_Motion-FlatFoot-Full.c3d"));
  EXPECT_EQ(t.markers.first_frame, 148);
  EXPECT_NEAR(t.markers.time_s[0], 1.47, 1e-9);
  ASSERT_TRUE(t.body_mass_kg.has_value());
  EXPECT_NEAR(*t.body_mass_kg, 47.5, 1e-4);
  EXPECT_FALSE(t.events.empty());
  EXPECT_GE(t.markers.find("RHEE"), 0);
  EXPECT_LT(t.markers.find("LKneeAngles"), 0) << "model outputs are not markers";
  // FP1 = right foot, peak 483 N (README), force on the body points up.
  const auto& fp1 = t.plates->plates[0];
  EXPECT_NEAR(fp1.force_N.col(2).maxCoeff(), 483.0, 2.0);
}

TEST(AllShared, EveryRecordingLoadsAndIsDescribed) {
  KIN2GRF_REQUIRE_DATA();
  int files = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(test::data_dir())) {
    std::string ext = e.path().extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".c3d" && ext != ".trc" && ext != ".mot" && ext != ".sto") continue;
    SCOPED_TRACE(e.path().string());
    Trial t;
    ASSERT_NO_THROW(t = load_trial(e.path().string()));
    const auto s = trial_summary(t);
    EXPECT_TRUE(s.contains("force_plates"));
    if (ext == ".c3d" || ext == ".trc") {
      EXPECT_GT(t.markers.names.size(), 0u);
    }
    ++files;
  }
  EXPECT_GE(files, 25);
}

TEST(Cli, InfoJsonOnWalking2ReportsTwoPlates) {
  KIN2GRF_REQUIRE_DATA();
  const std::string cmd = std::string(KIN2GRF_CLI) + " info --json " +
                          test::data_file("opensim_c3d_overground_walk/walking2.c3d");
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  ASSERT_TRUE(pipe);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe.get())) out += buf;
  const auto j = nlohmann::json::parse(out);
  for (const char* key : {"format", "rate_hz", "frames", "markers", "force_plates", "events"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["format"], "C3D");
  EXPECT_EQ(j["force_plates"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["rate_hz"].get<double>(), 250.0);
}

TEST(Cli, InfoOnMissingFileNamesIt) {
  const std::string cmd = std::string(KIN2GRF_CLI) + " info /nonexistent/trial.c3d 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe.get())) out += buf;
  EXPECT_NE(out.find("/nonexistent/trial.c3d"), std::string::npos) << out;
}

TEST(C3dShared, UnloadedOffsetRemovalZeroesTheIdlePlates) {
  KIN2GRF_REQUIRE_DATA();
  const std::string path = test::data_file("opensim_c3d_overground_walk/walking2.c3d");
  const Trial raw = read_c3d(path);
  C3dReadOptions o;
  o.zero_offset = ZeroOffset::Unloaded;
  const Trial zeroed = read_c3d(path, o);
  // README: unloaded plates read about -14 N (FP1) and -20 N (FP2) vertical.
  EXPECT_LT(raw.plates->plates[0].force_N(0, 2), -10.0);
  EXPECT_NEAR(zeroed.plates->plates[0].force_N(0, 2), 0.0, 2.0);
  EXPECT_NEAR(zeroed.plates->plates[1].force_N(0, 2), 0.0, 2.0);
  // The loaded peak rises by about the offset.
  const double d = zeroed.plates->plates[0].force_N.col(2).maxCoeff() - raw.plates->plates[0].force_N.col(2).maxCoeff();
  EXPECT_NEAR(d, 14.0, 3.0);
}

TEST(C3dQuirks, PointsAtTheOriginAreMissingWhateverTheResidual) {
  // Several exporters write a gap as (0, 0, 0) with a residual of 0 or 65535 instead of -1.
  Trial t = small_trial();
  t.markers.positions_m[0].row(7).setZero();
  for (const bool float_data : {true, false}) {
    C3dWriteOptions o;
    o.float_data = float_data;
    o.analog_samples_per_frame = 4;
    const Trial back = read_c3d_bytes(write_c3d_bytes(t, o), "zeros.c3d");
    EXPECT_TRUE(back.markers.positions_m[0].row(7).array().isNaN().all()) << float_data;
    EXPECT_TRUE(back.markers.positions_m[0].row(8).allFinite()) << float_data;
  }
}

TEST(C3dQuirks, ForcePlatformGroupWithoutAnalogDataGivesNoPlatesAndANote) {
  // RBDS001static.c3d: the lab's FORCE_PLATFORM description is kept in a marker-only file.
  Trial t = small_trial();
  t.plates.reset();
  t.events.clear();  // EVENT:USED would come after FORCE_PLATFORM:USED
  auto bytes = write_c3d_bytes(t, {});
  // The writer puts FORCE_PLATFORM last: patch its USED (int16 after name, offset, type, ndims).
  const std::string key = "USED";
  std::size_t at = std::string::npos;
  for (std::size_t i = 1; i + key.size() + 6 < bytes.size(); ++i)
    if (bytes[i - 1] == 4 && std::equal(key.begin(), key.end(), bytes.begin() + static_cast<long>(i) + 1)) at = i;
  ASSERT_NE(at, std::string::npos);
  const std::size_t data = at + 1 + key.size() + 2 + 1 + 1;
  ASSERT_EQ(bytes[data], 0);
  bytes[data] = 2;
  ASSERT_EQ(read_c3d_header(bytes, "fp.c3d").find("FORCE_PLATFORM:USED")->numbers.at(0), 2.0);
  const Trial back = read_c3d_bytes(bytes, "fp.c3d");
  EXPECT_FALSE(back.plates.has_value() && !back.plates->plates.empty());
  EXPECT_EQ(back.markers.names.size(), 3u);
  ASSERT_FALSE(back.warnings.empty());
  EXPECT_NE(back.warnings.back().find("FORCE_PLATFORM:USED = 2"), std::string::npos) << back.warnings.back();
}

// A plate of a type kin2grf cannot compute (here TYPE 6, Kistler's 12 channels with a 12 x 12
// calibration matrix) is left out with a warning that names the file, the plate and its type; the
// markers and the lab's other plates are read as they are. Before, the whole file was refused, so
// `estimate`, which needs no plate, could not run on it.
TEST(C3dQuirks, APlateOfAnUnsupportedTypeIsLeftOutByNameAndTheOthersAreRead) {
  Trial t = small_trial();
  ForcePlate second = t.plates->plates[0];
  second.name = "FP2";
  for (auto& c : second.corners_m) c.x() += 0.6;
  second.centre_m.x() += 0.6;
  second.force_N *= 0.5;
  t.plates->plates.push_back(second);
  C3dWriteOptions o;
  o.analog_samples_per_frame = 4;
  auto bytes = write_c3d_bytes(t, o);
  const Trial as_written = read_c3d_bytes(bytes, "lab.c3d");
  ASSERT_TRUE(as_written.plates);
  ASSERT_EQ(as_written.plates->plates.size(), 2u);
  // FORCE_PLATFORM:TYPE's first plate's byte: the name, offset (2), type (1), ndims (1), the
  // dimensions (none for one plate), then one int16 a plate.
  const auto first_type = [](const std::vector<std::uint8_t>& b) {
    const std::string key = "TYPE";
    std::size_t at = 0;
    for (std::size_t i = 1; i + key.size() + 8 < b.size(); ++i)
      if (b[i - 1] == 4 && std::equal(key.begin(), key.end(), b.begin() + static_cast<long>(i) + 1)) at = i;
    const std::size_t ndims = at + 1 + key.size() + 2 + 1;
    return ndims + 1 + b[ndims];
  };
  const std::size_t first = first_type(bytes);
  ASSERT_EQ(bytes[first], 2);
  bytes[first] = 6;
  ASSERT_EQ(read_c3d_header(bytes, "lab.c3d").find("FORCE_PLATFORM:TYPE")->numbers.at(0), 6.0);
  const Trial back = read_c3d_bytes(bytes, "lab.c3d");
  ASSERT_TRUE(back.plates);
  ASSERT_EQ(back.plates->plates.size(), 1u);
  EXPECT_EQ(back.plates->plates[0].name, "FP2");
  EXPECT_TRUE(back.plates->plates[0].force_N.isApprox(as_written.plates->plates[1].force_N));
  EXPECT_EQ(back.markers.names, as_written.markers.names);
  bool said = false;
  for (const auto& w : back.warnings)
    said = said || (w.find("lab.c3d: FP1: FORCE_PLATFORM:TYPE[1] = 6 is not supported") != std::string::npos &&
                    w.find("left out") != std::string::npos);
  EXPECT_TRUE(said) << (back.warnings.empty() ? "no warning" : back.warnings.back());
  // A file whose only plate is left out: `validate` says why it has none to validate against.
  auto one = write_c3d_bytes(small_trial(), o);
  ASSERT_EQ(one[first_type(one)], 2);
  one[first_type(one)] = 6;
  const std::string path = (test::temp_dir("plate-type") / "type6.c3d").string();
  {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(one.data()), static_cast<std::streamsize>(one.size()));
  }
  Settings st;
  st.trial = path;
  try {
    (void)validate_trial(st, "", ValidationOptions{}, "none");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("type6.c3d: no force plates to validate against"), std::string::npos) << what;
    EXPECT_NE(what.find("TYPE[1] = 6 is not supported"), std::string::npos) << what;
  }
}

// `estimate` reads the plates without their samples (C3dReadOptions::plate_samples = false):
// the same markers, the same plates with their geometry, type and rate, no samples, and no note
// that the file holds no analog data (it does). With samples, the plates are read as always.
TEST(C3dQuirks, PlatesWithoutSamplesKeepTheirGeometryAndTheMarkers) {
  C3dWriteOptions o;
  o.analog_samples_per_frame = 4;  // small_trial's plates: 400 Hz under 100 Hz markers
  const auto bytes = write_c3d_bytes(small_trial(), o);
  const Trial full = read_c3d_bytes(bytes, "fp.c3d");
  C3dReadOptions lean;
  lean.plate_samples = false;
  const Trial geometry = read_c3d_bytes(bytes, "fp.c3d", lean);
  ASSERT_TRUE(full.plates && geometry.plates);
  ASSERT_GT(full.plates->samples(), 0);
  EXPECT_EQ(geometry.plates->samples(), 0);
  EXPECT_EQ(geometry.plates->rate_hz, full.plates->rate_hz);
  ASSERT_EQ(geometry.plates->plates.size(), full.plates->plates.size());
  for (std::size_t p = 0; p < full.plates->plates.size(); ++p) {
    const ForcePlate &a = full.plates->plates[p], &b = geometry.plates->plates[p];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.type, b.type);
    EXPECT_TRUE(b.has_geometry);
    EXPECT_EQ(a.lab_R_plate, b.lab_R_plate);
    EXPECT_EQ(a.centre_m, b.centre_m);
    EXPECT_EQ(b.force_N.rows(), 0);
  }
  EXPECT_EQ(geometry.markers.names, full.markers.names);
  for (std::size_t k = 0; k < full.markers.positions_m.size(); ++k) {
    const auto &a = full.markers.positions_m[k].array(), &b = geometry.markers.positions_m[k].array();
    EXPECT_TRUE((a == b || (a.isNaN() && b.isNaN())).all()) << full.markers.names[k];
  }
  EXPECT_EQ(geometry.warnings, full.warnings);
}

namespace {
/// small_trial() in a Y-up lab: (x, y, z) -> (x, z, -y), plates included.
Trial small_trial_y_up() {
  Trial t = small_trial();
  Eigen::Matrix3d R;
  R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  for (auto& P : t.markers.positions_m) P = (P * R.transpose()).eval();
  for (auto& p : t.plates->plates) {
    for (auto& c : p.corners_m) c = R * c;
    p.centre_m = R * p.centre_m;
    Eigen::Matrix<double, 3, 4> C;
    for (int c = 0; c < 4; ++c) C.col(c) = p.corners_m[static_cast<std::size_t>(c)];
    p.lab_R_plate = plate_axes(C);
    p.force_N = (p.force_N * R.transpose()).eval();
    p.cop_m = (p.cop_m * R.transpose()).eval();
    p.free_moment_Nm = (p.free_moment_Nm * R.transpose()).eval();
  }
  return t;
}
}  // namespace

TEST(C3dQuirks, YUpLabIsFoundFromThePlatesAndItsOffsetsFromThePlateNormal) {
  // RBDS001runT35.c3d: a Y-up C3D. Before, the unloaded-offset search looked at the lab Z force
  // (lateral there), found the plate "unloaded" throughout and subtracted half the load.
  C3dWriteOptions o;
  o.analog_samples_per_frame = 4;
  const auto bytes = write_c3d_bytes(small_trial_y_up(), o);
  const std::string path = ::testing::TempDir() + "/yup.c3d";
  { std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<long>(bytes.size())); }
  LoadOptions lo;
  lo.c3d.zero_offset = ZeroOffset::Unloaded;
  const Trial t = load_trial(path, lo);
  EXPECT_EQ(t.markers.up_axis, Axis::Y);
  EXPECT_EQ(t.plates->up_axis, Axis::Y);
  EXPECT_NEAR(t.plates->plates[0].force_N.col(1).maxCoeff(), 700.0, 1.0);
  bool warned = false;
  for (const auto& w : t.warnings) warned = warned || w.find("up axis") != std::string::npos;
  EXPECT_TRUE(warned);
  std::remove(path.c_str());
}

TEST(UpAxis, MarkersTellTheVerticalWhereTheFileDoesNot) {
  // A standing body: 1.0-1.7 m tall, 0.4 m wide, 0.3 m deep; the file claims Y up.
  Trial t;
  t.markers.rate_hz = 100;
  t.markers.time_s = Eigen::VectorXd::LinSpaced(50, 0, 0.49);
  t.markers.up_axis = Axis::Y;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int k = 0; k < 12; ++k) {
    const Eigen::RowVector3d p(0.3 * u(rng), 0.4 * u(rng) - 0.2, 0.05 + 1.5 * k / 11.0);
    t.markers.names.emplace_back(1, static_cast<char>('A' + k));
    t.markers.positions_m.push_back(p.replicate(50, 1));
  }
  std::string why;
  ASSERT_EQ(up_axis_from_data(t, &why), Axis::Z);
  EXPECT_NE(why.find("spread"), std::string::npos);
  // Too few markers or a cloud with no dominant axis: no verdict, the file's axis stays.
  for (auto& P : t.markers.positions_m) P.col(0) *= 6.0;
  EXPECT_FALSE(up_axis_from_data(t).has_value());
}

TEST(C3dCorrupt, AFrameCountNoDataJustifiesIsRefusedBeforeAllocating) {
  // TRIAL:ACTUAL_END_FIELD claiming 2^30 frames: before, a file with no points took 23 s and 8 GB.
  for (const int high : {0x3F, 0x20})  // about 2^30 frames; 2 million (under the 50-million cap)
  for (const bool with_markers : {false, true}) {
    Trial t = small_trial();
    t.plates.reset();
    t.events.clear();
    if (!with_markers) t.markers.names.clear(), t.markers.descriptions.clear(), t.markers.positions_m.clear();
    auto bytes = write_c3d_bytes(t, {});
    const std::string key = "ACTUAL_END_FIELD";
    auto it = std::search(bytes.begin(), bytes.end(), key.begin(), key.end());
    ASSERT_NE(it, bytes.end());
    // name, offset (2), type (1), ndims (1), dim (1), then two int16: patch the high word.
    const std::size_t hi = static_cast<std::size_t>(it - bytes.begin()) + key.size() + 2 + 1 + 1 + 1 + 2;
    bytes[hi] = 0x00;
    bytes[hi + 1] = static_cast<std::uint8_t>(high);  // x 65536 frames (2^30 and above are ignored as implausible)
    const auto t0 = std::chrono::steady_clock::now();
    const std::string msg = expect_input_error(bytes, "frames.c3d");
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
    EXPECT_TRUE(msg.find("frame") != std::string::npos || msg.find("truncated") != std::string::npos) << msg;
  }
}

// tests/corpus (scripts/make_corpus.py): one damaged file per reader failure of issue 10. Each is
// read, with the warning that says what was wrong, or refused with a message naming the file;
// never a crash, a hang or an allocation the file cannot justify (this test also runs under ASan).
TEST(CorruptCorpus, EachFileIsReadWithAWarningOrRefusedByName) {
  const std::filesystem::path dir = std::filesystem::path(KIN2GRF_SOURCE_DIR) / "tests" / "corpus";
  // name -> the warning it must give when read; absent: it must be refused.
  const std::map<std::string, std::string> read_with = {
      {"mot_rows_mismatch.mot", "header says"},          {"trc_cut_row.trc", "rows end early"},
      {"trc_duplicate_label.trc", "repeated"},           {"trc_rate_mismatch.trc", "DataRate says"},
      {"trc_rate_1e300.trc", "DataRate says"},
  };
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string path = e.path().string(), name = e.path().filename().string();
    SCOPED_TRACE(name);
    ++files;
    try {
      if (e.path().extension() == ".json") {
        (void)read_cop_function(path);
      } else {
        const Trial t = load_trial(path);
        const auto it = read_with.find(name);
        ASSERT_NE(it, read_with.end()) << "read without complaint";
        bool warned = false;
        for (const auto& w : t.warnings) warned = warned || w.find(it->second) != std::string::npos;
        EXPECT_TRUE(warned) << "no warning '" << it->second << "'";
        continue;
      }
      ADD_FAILURE() << "read without complaint";
    } catch (const InputError& err) {
      EXPECT_EQ(read_with.count(name), 0u) << err.what();
      EXPECT_NE(std::string(err.what()).find(name), std::string::npos) << "the message must name the file: " << err.what();
    }
  }
  EXPECT_GE(files, 13);
}

// A long capture (10 minutes at 2 kHz: 1.2 million frames) has more frames than the header's
// 16-bit frame numbers hold: the writer stores them in TRIAL:ACTUAL_START/END_FIELD (two 16-bit
// words each), as Vicon does, and every frame reads back, the numbers past 65535 too.
// A parameter's dimension is a byte: 300 markers are written as POINT:LABELS (255) and
// POINT:LABELS2 (45), as Vicon, ezc3d and BTK write them, and read back by name (they came back
// as 44 names and *n placeholders before); more than 255 events, which the EVENT group cannot
// hold, are refused rather than written wrapped.
TEST(C3dRoundTrip, MoreThan255LabelsGoToLabels2AndMoreThan255EventsAreRefused) {
  Trial t;
  auto& m = t.markers;
  m.rate_hz = 100, m.first_frame = 1, m.time_s = Eigen::VectorXd::LinSpaced(10, 0, 0.09);
  for (int k = 0; k < 300; ++k) {
    char name[16];
    std::snprintf(name, sizeof name, "M%d", k);  // ("M" + std::to_string(k) trips GCC 12's -Wstringop-overflow at -O3)
    m.names.emplace_back(name);
    m.descriptions.emplace_back();
    m.positions_m.push_back(Eigen::MatrixX3d::Constant(10, 3, 0.001 * k));
  }
  const auto bytes = write_c3d_bytes(t);
  const C3dFile f = read_c3d_header(bytes, "many.c3d");
  ASSERT_NE(f.find("POINT:LABELS2"), nullptr);
  EXPECT_EQ(f.find("POINT:LABELS")->strings.size(), 255u);
  EXPECT_EQ(f.find("POINT:LABELS2")->strings.size(), 45u);
  const Trial back = read_c3d_bytes(bytes, "many.c3d");
  EXPECT_EQ(back.markers.names, m.names);
  EXPECT_NEAR(back.markers.positions_m[299](0, 0), 0.299, 1e-6);
  for (int k = 0; k < 256; ++k) t.events.push_back(Event{"Foot Strike", Side::Right, 0.001 * k});
  EXPECT_THROW((void)write_c3d_bytes(t), InputError);
  t.events.pop_back();
  EXPECT_EQ(read_c3d_bytes(write_c3d_bytes(t), "events.c3d").events.size(), 255u);
}

TEST(C3dRoundTrip, MoreThan65535FramesKeepEveryFrameAndTheirNumbers) {
  Trial t;
  t.path = "long.c3d";
  auto& m = t.markers;
  const Eigen::Index n = 70000;
  m.rate_hz = 1000.0;
  m.first_frame = 1;
  m.names = {"A"};
  m.descriptions = {""};
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1) / m.rate_hz);
  m.positions_m.emplace_back(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) m.positions_m[0].row(i) << 0.001 * static_cast<double>(i % 1000), 0.5, 0.9;
  for (const int first : {1, 65000}) {
    C3dWriteOptions o;
    o.first_frame = first;
    const Trial r = read_c3d_bytes(write_c3d_bytes(t, o), "long.c3d");
    ASSERT_EQ(r.markers.frames(), n) << first;
    EXPECT_EQ(r.markers.first_frame, first);
    EXPECT_TRUE(test::matrices_near(r.markers.positions_m[0], m.positions_m[0], 1e-6));
  }
}

// read_c3d maps the file and releases each block of frames once read (issue 10's memory); the
// plates' samples are read after the markers, from pages released already. Over several blocks,
// the trial must be the very one read_c3d_bytes makes of the file read into memory. The example
// walk at 1 kHz markers and 5 kHz analog: 20,000 frames, 9 MB.
TEST(C3dRoundTrip, AMappedFileReleasedAsItIsReadGivesTheSameTrial) {
  // The walk alone at 1 kHz, 2.2 MB: hundreds of pages released block by block. (The examples'
  // 20 s at 1 kHz with the squat's two estimates took 249 s under the sanitizers.)
  const auto dir = test::temp_dir("mapped_c3d");
  SyntheticWalkOptions wo;
  wo.rate_hz = 1000, wo.duration_s = 8;
  const std::string path = (dir / "example_walk.c3d").string();
  write_c3d(path, make_example_walk(wo));
  const Trial mapped = read_c3d(path);
  const Trial whole = read_c3d_bytes(read_file_bytes(path), path);
  ASSERT_GT(read_file_bytes(path).size(), std::size_t{2} << 20);
  ASSERT_EQ(mapped.markers.names, whole.markers.names);
  for (std::size_t k = 0; k < whole.markers.positions_m.size(); ++k)
    EXPECT_TRUE(mapped.markers.positions_m[k].cwiseEqual(whole.markers.positions_m[k]).all()) << whole.markers.names[k];
  ASSERT_TRUE(mapped.plates && whole.plates);
  EXPECT_EQ(mapped.plates->rate_hz, 1000.0);
  for (std::size_t p = 0; p < whole.plates->plates.size(); ++p)
    EXPECT_TRUE(mapped.plates->plates[p].force_N.cwiseEqual(whole.plates->plates[p].force_N).all()) << p;
}

// Vicon Nexus labels a subject's markers "Subject:LASI" (issue 10's "real files from other labs
// run as they are"): the presets name markers alone, so such a file was "not recognised". The
// common prefix is removed with a warning, the unlabelled "*n" kept, and the prefixed names still
// find their markers (a mapping file written for the file's labels).
TEST(C3dQuirks, ASubjectPrefixOnTheLabelsIsRemovedAndThePresetRecognised) {
  Trial t = make_example_walk();
  const std::vector<std::string> plain = t.markers.names;
  for (auto& n : t.markers.names) n = "Sim01:" + n;
  t.markers.names.push_back("*99");  // an unlabelled marker: no prefix in Nexus either
  t.markers.descriptions.emplace_back();
  t.markers.positions_m.push_back(t.markers.positions_m.front());
  const auto dir = test::temp_dir("c3d_prefix");
  const std::string path = (dir / "prefixed.c3d").string();
  write_c3d(path, t);
  const Trial r = load_trial(path);
  ASSERT_EQ(r.markers.names.size(), plain.size() + 1);
  EXPECT_TRUE(std::equal(plain.begin(), plain.end(), r.markers.names.begin()));
  EXPECT_EQ(r.markers.names.back(), "*99");
  EXPECT_EQ(r.markers.label_prefix, "Sim01:");
  EXPECT_EQ(r.markers.find("Sim01:" + plain[2]), 2);
  EXPECT_EQ(r.markers.find(plain[2]), 2);
  EXPECT_EQ(r.markers.find("Other:" + plain[2]), -1);
  EXPECT_TRUE(std::any_of(r.warnings.begin(), r.warnings.end(),
                          [](const std::string& w) { return w.find("subject prefix 'Sim01:'") != std::string::npos; }));
  const MarkerSet* set = recognise_marker_set(r.markers);
  ASSERT_NE(set, nullptr);
  EXPECT_EQ(set->name, "kin2grf-example");
}

TEST(C3dQuirks, TwoSubjectsOrAClashKeepTheLabelsAsTheyAre) {
  MarkerTrajectories m;
  m.names = {"A:LASI", "B:LASI", "C7"};
  std::vector<std::string> warnings;
  remove_subject_prefix(m, warnings);
  EXPECT_EQ(m.names, (std::vector<std::string>{"A:LASI", "B:LASI", "C7"}));
  EXPECT_TRUE(m.label_prefix.empty());
  EXPECT_TRUE(warnings.empty());
  m.names = {"A:LASI", "LASI"};  // without the prefix, two markers would be "LASI"
  remove_subject_prefix(m, warnings);
  EXPECT_EQ(m.names, (std::vector<std::string>{"A:LASI", "LASI"}));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("kept"), std::string::npos) << warnings[0];
  EXPECT_EQ(m.find("A:LASI"), 0);
  EXPECT_EQ(m.find("LASI"), 1);
}

// Plate data that were accepted without a word (issue 31): a type-4 plate with a NaN or all-zero
// CAL_MATRIX became "never loaded" (validate blamed the clock), a 3e38 matrix gave 6.9e42 N, NaN
// samples split a stance unseen, a .mot whose vertical was negated made its plate "never loaded".
namespace {
struct TwoPlates {
  AnalogData analog;
  std::vector<PlateDescription> plates;
};
/// Two type-4 plates side by side, identity calibration, 700 N on each from 0.2 to 0.8 s.
TwoPlates two_type4_plates() {
  TwoPlates t;
  t.analog.rate_hz = 1000;
  t.analog.values = Eigen::MatrixXd::Zero(1000, 12);
  for (int c = 0; c < 12; ++c) t.analog.labels.push_back("ch" + std::to_string(c)), t.analog.units.push_back(c % 6 < 3 ? "N" : "Nmm");
  t.analog.values.block(200, 2, 600, 1).setConstant(700.0);
  t.analog.values.block(200, 8, 600, 1).setConstant(700.0);
  for (int p = 0; p < 2; ++p) {
    PlateDescription d;
    d.name = "FP" + std::to_string(p + 1);
    d.type = 4;
    const double x0 = 0.6 * p;
    d.corners << x0 + 0.6, x0, x0, x0 + 0.6,  //
        0.4, 0.4, 0, 0,                         //
        0, 0, 0, 0;
    d.origin = Eigen::Vector3d(0, 0, -0.04);
    for (int c = 0; c < 6; ++c) d.channels.push_back(6 * p + c);
    t.plates.push_back(d);
  }
  return t;
}
bool said(const std::vector<std::string>& w, const std::string& a, const std::string& b) {
  for (const auto& m : w)
    if (m.find(a) != std::string::npos && m.find(b) != std::string::npos) return true;
  return false;
}
}  // namespace

TEST(PlateData, ABrokenCalibrationOrAnAbsurdForceLeavesThePlateOutWithItsName) {
  {
    auto t = two_type4_plates();
    std::vector<std::string> w;
    const auto rec = compute_plates(t.analog, t.plates, {}, "lab.c3d", w);
    ASSERT_EQ(rec.plates.size(), 2u);
    EXPECT_TRUE(w.empty());
  }
  const struct {
    double value;
    bool whole;
    const char* said;
  } cases[] = {{std::numeric_limits<double>::quiet_NaN(), false, "not finite"}, {0.0, true, "all zero"}, {3e38, false, "is no ground reaction"}};
  for (const auto& c : cases) {
    auto t = two_type4_plates();
    if (c.whole) t.plates[1].cal_matrix.setConstant(c.value);
    else t.plates[1].cal_matrix(2, 2) = c.value;
    std::vector<std::string> w;
    const auto rec = compute_plates(t.analog, t.plates, {}, "lab.c3d", w);
    ASSERT_EQ(rec.plates.size(), 1u) << c.said;
    EXPECT_EQ(rec.plates[0].name, "FP1");
    EXPECT_TRUE(said(w, "lab.c3d: FP2", c.said)) << c.said << ": " << (w.empty() ? "" : w[0]);
  }
}

TEST(PlateData, NonFiniteSamplesAreNamedWithTheirTimes) {
  auto t = two_type4_plates();
  t.analog.values(500, 2) = std::numeric_limits<double>::quiet_NaN();
  t.analog.values(510, 3) = std::numeric_limits<double>::infinity();
  std::vector<std::string> w;
  const auto rec = compute_plates(t.analog, t.plates, {}, "lab.c3d", w);
  ASSERT_EQ(rec.plates.size(), 2u);
  EXPECT_TRUE(said(w, "FP1: 2 analog samples are NaN or infinite", "0.5 s to 0.51 s")) << (w.empty() ? "" : w[0]);
}

TEST(PlateData, AGrfFileWhoseVerticalPointsDownIsReadNegatedWithAWarning) {
  Table t;
  t.labels = grf_labels();
  t.data = Eigen::MatrixXd::Zero(100, static_cast<Eigen::Index>(t.labels.size()));
  for (Eigen::Index i = 0; i < 100; ++i) {
    t.data(i, 0) = 0.01 * static_cast<double>(i);
    if (i >= 20 && i < 80) t.data(i, 2) = -700, t.data(i, 1) = 50;  // right foot: force on the plate
    if (i >= 50) t.data(i, 8) = 700;                                // left foot: on the body
  }
  std::vector<std::string> w;
  const auto rec = grf_from_table(t, "grf.mot", 10, w);
  ASSERT_TRUE(rec);
  ASSERT_EQ(rec->plates.size(), 2u);
  EXPECT_EQ(rec->plates[0].force_N(30, 1), 700);
  EXPECT_EQ(rec->plates[0].force_N(30, 0), -50);
  EXPECT_EQ(rec->plates[1].force_N(60, 1), 700);
  EXPECT_TRUE(said(w, "grf.mot: ground_force: its vertical force points down", "0.2 to 0.79 s")) << (w.empty() ? "" : w.back());
  EXPECT_FALSE(said(w, "1_ground_force", "points down"));
}
