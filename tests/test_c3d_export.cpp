// The C3D export (estimate --c3d) read as ezc3d reads it: a decoder of the C3D format written here
// from the C3D specification (parameter section, Intel float data), and ezc3d's rules for a TYPE 2
// force platform (src/modules/ForcePlatforms.cpp of pyomeca/ezc3d: axes from the corners, x = c1 -
// c2, y = c1 - c4, z = x cross y, y again z cross x; ORIGIN negated when its z is positive; the
// moment channels plus F cross ORIGIN; COP = (-My / Fz, Mx / Fz, 0) in those axes, plus the
// corners' mean; Tz = M - F cross (-COP)). Not kin2grf's own reader.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/output/c3d_export.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/validate.hpp"
#include "test_support.hpp"

using namespace kin2grf;

namespace {

/// An Intel-float C3D, decoded from the specification alone.
struct Decoded {
  struct Param {
    int type = 0;
    std::vector<int> dims;
    std::vector<double> numbers;
    std::vector<std::string> strings;
  };
  std::map<std::string, Param> params;  ///< "GROUP:NAME"
  std::vector<Eigen::MatrixXd> points;  ///< per frame: npoints x 4 (x, y, z mm, residual)
  Eigen::MatrixXd analog;               ///< samples x channels

  [[nodiscard]] const Param& at(const std::string& key) const {
    const auto it = params.find(key);
    if (it == params.end()) throw std::runtime_error("no parameter " + key);
    return it->second;
  }
  [[nodiscard]] double number(const std::string& key, std::size_t i = 0) const { return at(key).numbers.at(i); }
};

Decoded decode_intel_float_c3d(const std::vector<std::uint8_t>& b) {
  auto i8 = [&](std::size_t p) { return static_cast<int>(static_cast<std::int8_t>(b.at(p))); };
  auto u8 = [&](std::size_t p) { return static_cast<int>(b.at(p)); };
  auto i16 = [&](std::size_t p) { return static_cast<int>(static_cast<std::int16_t>(b.at(p) | (b.at(p + 1) << 8))); };
  auto f32 = [&](std::size_t p) {
    float f;
    std::memcpy(&f, &b.at(p), 4);
    return static_cast<double>(f);
  };
  Decoded d;
  EXPECT_EQ(b.at(1), 0x50);
  const std::size_t start = (static_cast<std::size_t>(b.at(0)) - 1) * 512;
  EXPECT_EQ(b.at(start + 3), 84) << "Intel";
  std::map<int, std::string> groups;
  std::vector<std::tuple<int, std::string, Decoded::Param>> pending;
  std::size_t p = start + 4;
  while (true) {
    const int nchar = std::abs(i8(p));
    if (nchar == 0) break;
    const int id = i8(p + 1);
    const std::string name(reinterpret_cast<const char*>(&b.at(p + 2)), static_cast<std::size_t>(nchar));
    const std::size_t off_pos = p + 2 + static_cast<std::size_t>(nchar);
    const int offset = i16(off_pos);
    if (id < 0) {
      groups[-id] = name;
    } else {
      Decoded::Param q;
      std::size_t r = off_pos + 2;
      q.type = i8(r);
      const int nd = u8(r + 1);
      r += 2;
      std::size_t count = 1;
      for (int k = 0; k < nd; ++k) q.dims.push_back(u8(r + static_cast<std::size_t>(k))), count *= static_cast<std::size_t>(q.dims.back());
      r += static_cast<std::size_t>(nd);
      if (q.type == -1) {
        const std::size_t len = nd > 0 ? static_cast<std::size_t>(q.dims[0]) : 1, words = len > 0 ? count / len : 0;
        for (std::size_t w = 0; w < words; ++w) {
          std::string s(reinterpret_cast<const char*>(&b.at(r + w * len)), len);
          while (!s.empty() && s.back() == ' ') s.pop_back();
          q.strings.push_back(s);
        }
      } else {
        for (std::size_t k = 0; k < count; ++k)
          q.numbers.push_back(q.type == 4 ? f32(r + k * 4) : q.type == 2 ? i16(r + k * 2) : i8(r + k));
      }
      pending.emplace_back(id, name, std::move(q));
    }
    if (offset == 0) break;
    p = off_pos + static_cast<std::size_t>(offset);
  }
  for (auto& [id, name, q] : pending) d.params[groups.at(id) + ":" + name] = std::move(q);

  const auto npoints = static_cast<std::size_t>(d.number("POINT:USED"));
  const auto nchan = static_cast<std::size_t>(d.number("ANALOG:USED"));
  const auto spf = static_cast<std::size_t>(std::lround(d.number("ANALOG:RATE") / d.number("POINT:RATE")));
  EXPECT_LT(d.number("POINT:SCALE"), 0) << "float data";
  const long first = i16(6), last = i16(8);
  const auto frames = static_cast<std::size_t>(last - first + 1);
  std::size_t q = (static_cast<std::size_t>(d.number("POINT:DATA_START")) - 1) * 512;
  d.analog.resize(static_cast<Eigen::Index>(frames * spf), static_cast<Eigen::Index>(nchan));
  for (std::size_t f = 0; f < frames; ++f) {
    Eigen::MatrixXd pts(static_cast<Eigen::Index>(npoints), 4);
    for (std::size_t k = 0; k < npoints; ++k)
      for (int a = 0; a < 4; ++a, q += 4) pts(static_cast<Eigen::Index>(k), a) = f32(q);
    d.points.push_back(pts);
    for (std::size_t s = 0; s < spf; ++s)
      for (std::size_t c = 0; c < nchan; ++c, q += 4) d.analog(static_cast<Eigen::Index>(f * spf + s), static_cast<Eigen::Index>(c)) = f32(q);
  }
  // Analog values as ezc3d's data() gives them: (raw - OFFSET) x SCALE x GEN_SCALE.
  for (std::size_t c = 0; c < nchan; ++c)
    d.analog.col(static_cast<Eigen::Index>(c)) =
        ((d.analog.col(static_cast<Eigen::Index>(c)).array() - d.number("ANALOG:OFFSET", c)) * d.number("ANALOG:SCALE", c) *
         d.number("ANALOG:GEN_SCALE"))
            .matrix();
  return d;
}

/// One TYPE 2 platform as ezc3d's ForcePlatform computes it, per analog sample, lab frame (the
/// file's units: N, mm, N mm).
struct Ezc3dPlatform {
  Eigen::Matrix3d frame;
  Eigen::Vector3d mean_corners;
  std::vector<Eigen::Vector3d> F, M, CoP, Tz;
};

Ezc3dPlatform ezc3d_platform(const Decoded& d, std::size_t idx) {
  Ezc3dPlatform out;
  EXPECT_EQ(d.number("FORCE_PLATFORM:TYPE", idx), 2);
  std::array<Eigen::Vector3d, 4> c;
  out.mean_corners.setZero();
  for (std::size_t i = 0; i < 4; ++i) {
    for (std::size_t j = 0; j < 3; ++j) c[i](static_cast<Eigen::Index>(j)) = d.number("FORCE_PLATFORM:CORNERS", idx * 12 + i * 3 + j);
    out.mean_corners += c[i] / 4;
  }
  Eigen::Vector3d origin;
  for (std::size_t i = 0; i < 3; ++i) origin(static_cast<Eigen::Index>(i)) = d.number("FORCE_PLATFORM:ORIGIN", idx * 3 + i);
  if (origin.z() > 0) origin = -origin;
  Eigen::Vector3d x = c[0] - c[1], y = c[0] - c[3];
  const Eigen::Vector3d z = x.cross(y);
  y = z.cross(x);
  out.frame.col(0) = x.normalized(), out.frame.col(1) = y.normalized(), out.frame.col(2) = z.normalized();
  const std::size_t rows = d.at("FORCE_PLATFORM:CHANNEL").dims.at(0);
  std::array<Eigen::Index, 6> ch;
  for (std::size_t k = 0; k < 6; ++k) ch[k] = static_cast<Eigen::Index>(d.number("FORCE_PLATFORM:CHANNEL", idx * rows + k)) - 1;
  for (Eigen::Index s = 0; s < d.analog.rows(); ++s) {
    const Eigen::Vector3d f(d.analog(s, ch[0]), d.analog(s, ch[1]), d.analog(s, ch[2]));
    Eigen::Vector3d m(d.analog(s, ch[3]), d.analog(s, ch[4]), d.analog(s, ch[5]));
    m += f.cross(origin);
    const Eigen::Vector3d cop(-m.y() / f.z(), m.x() / f.z(), 0);
    out.F.push_back(out.frame * f);
    out.M.push_back(out.frame * m);
    out.CoP.push_back(out.frame * cop + out.mean_corners);
    out.Tz.push_back(out.frame * (m - f.cross(-cop)));
  }
  return out;
}

struct Exported {
  Trial trial;
  EstimateResult estimate;
  C3dExport c3d;
  Decoded file;
};

Exported export_walk(const Trial& walk, const MarkerSet* set = find_marker_set("kin2grf-example")) {
  Exported e{walk, estimate(walk, nullptr, *set, EstimateOptions{}), {}, {}};
  e.c3d = c3d_export(e.trial, e.estimate);
  C3dWriteOptions o;
  o.first_frame = e.c3d.first_frame;
  e.file = decode_intel_float_c3d(write_c3d_bytes(e.c3d.trial, o));
  return e;
}

}  // namespace

// What Nexus, Visual3D or ezc3d would take from the export: each platform's force and COP are the
// estimate's foot's (lab frame; zero force out of contact), its free moment zero, its z axis down
// into the floor, every COP inside its platform, and the markers as they were.
TEST(C3dExport, Ezc3dReadsEachFootsEstimateFromItsPlatform) {
  const Exported e = export_walk(make_example_walk());
  const Decoded& d = e.file;
  ASSERT_EQ(d.number("FORCE_PLATFORM:USED"), 2);
  ASSERT_EQ(d.analog.rows(), e.trial.markers.frames()) << "one analog sample a frame";
  const auto feet = as_lab_plates(e.estimate);
  const Eigen::Index n = e.estimate.time_s.size();
  const std::array<Ezc3dPlatform, 2> plates{ezc3d_platform(d, 0), ezc3d_platform(d, 1)};
  std::array<Eigen::Vector2d, 2> half;  // each platform's half length (x) and half width (y), mm
  for (std::size_t side = 0; side < 2; ++side) {
    std::array<Eigen::Vector3d, 4> c;
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = 0; j < 3; ++j) c[i](static_cast<Eigen::Index>(j)) = d.number("FORCE_PLATFORM:CORNERS", side * 12 + i * 3 + j);
    half[side] = Eigen::Vector2d((c[0] - c[1]).norm() / 2, (c[0] - c[3]).norm() / 2);
  }
  for (std::size_t side = 0; side < 2; ++side) {
    const Ezc3dPlatform& p = plates[side];
    EXPECT_NEAR(p.frame.col(2).dot(Eigen::Vector3d::UnitZ()), -1.0, 1e-9) << "the platform's z points down";
    int loaded = 0;
    for (Eigen::Index k = 0; k < d.analog.rows(); ++k) {
      const Eigen::Index i = k - e.estimate.first_index;
      const bool in = i >= 0 && i < n && e.estimate.feet[side].contact[static_cast<std::size_t>(i)] && feet[side].cop_m.row(i).allFinite();
      const Eigen::Vector3d F = in ? Eigen::Vector3d(feet[side].force_N.row(i).transpose()) : Eigen::Vector3d::Zero();
      ASSERT_LT((p.F[static_cast<std::size_t>(k)] - F).norm(), 0.01) << side_name(static_cast<int>(side)) << " frame " << k;
      if (!in || F.z() < 20) continue;
      ++loaded;
      const Eigen::Vector3d cop_mm = 1000.0 * Eigen::Vector3d(feet[side].cop_m.row(i).transpose());
      ASSERT_LT((p.CoP[static_cast<std::size_t>(k)] - cop_mm).norm(), 0.1) << side_name(static_cast<int>(side)) << " frame " << k;
      EXPECT_LT(p.Tz[static_cast<std::size_t>(k)].norm(), 50.0) << "no free moment (N mm)";
      // The COP, and the foot around it, on its own platform: at least the margin inside its ends
      // (along the progression, the platform's x) and its outer side; not on the other platform,
      // which meets it on the line between the feet.
      const Eigen::Vector3d q = p.frame.transpose() * (cop_mm - p.mean_corners);
      EXPECT_LE(std::abs(q.x()), half[side].x() - 1000 * kLoadedFootMarginM + 0.1);
      EXPECT_LE(std::abs(q.y()), half[side].y() + 0.1);
      const double outer = side == 0 ? half[side].y() - q.y() : half[side].y() + q.y();  // y points to the walker's right
      EXPECT_GE(outer, 1000 * kLoadedFootMarginM - 0.1) << side_name(static_cast<int>(side));
      const Ezc3dPlatform& other = plates[1 - side];
      const Eigen::Vector3d o = other.frame.transpose() * (cop_mm - other.mean_corners);
      EXPECT_TRUE(std::abs(o.x()) > half[1 - side].x() || std::abs(o.y()) >= half[1 - side].y() - 1e-6)
          << side_name(static_cast<int>(side)) << " COP on the other foot's platform, frame " << k;
    }
    EXPECT_GT(loaded, 50) << "the walk loads each foot";
  }
  // Markers in mm, a missing sample with a negative residual.
  const auto& m = e.trial.markers;
  ASSERT_EQ(d.number("POINT:USED"), static_cast<double>(m.names.size()));
  EXPECT_EQ(d.at("POINT:LABELS").strings, m.names);
  for (std::size_t k = 0; k < m.names.size(); ++k)
    for (Eigen::Index f = 0; f < m.frames(); f += 7) {
      const Eigen::RowVector4d got = d.points[static_cast<std::size_t>(f)].row(static_cast<Eigen::Index>(k));
      if (!m.positions_m[k].row(f).allFinite()) {
        EXPECT_LT(got(3), 0);
        continue;
      }
      EXPECT_LT((got.head<3>() - 1000.0 * m.positions_m[k].row(f)).norm(), 1e-2);
      EXPECT_GE(got(3), 0);
    }
  // The estimate's gait events (the synthetic walk has none of its own), on the file's clock.
  const auto events = gait_events({e.estimate.feet[0].contact, e.estimate.feet[1].contact}, e.estimate.time_s, e.estimate.motion.rate_hz);
  ASSERT_FALSE(events.empty());
  ASSERT_EQ(d.at("EVENT:LABELS").strings.size(), events.size());
  for (std::size_t k = 0; k < events.size(); ++k) {
    EXPECT_EQ(d.at("EVENT:LABELS").strings[k], events[k].label);
    EXPECT_EQ(d.at("EVENT:CONTEXTS").strings[k], events[k].side == kLeft ? "Left" : "Right");
    EXPECT_NEAR(d.number("EVENT:TIMES", 2 * k + 1), e.estimate.time_s[events[k].index], 1e-5);
  }
  EXPECT_NEAR(d.number("PROCESSING:Bodymass"), e.estimate.mass_kg, 1e-4);
}

// A trial whose lab frame has Y up (a TRC in OpenSim's frame) is written with Z up, C3D's
// convention that ezc3d's platform module assumes: the platforms' vertical force is the
// estimate's, along +Z, and each marker's height is its Y.
TEST(C3dExport, AYUpTrialIsWrittenZUp) {
  Trial walk = make_example_walk();
  Eigen::Matrix3d to_y_up;
  to_y_up << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // lab Z (up) -> Y
  walk.markers = rotated(walk.markers, to_y_up, Axis::Y);
  walk.plates.reset();
  const Exported e = export_walk(walk);
  EXPECT_TRUE(e.estimate.frame.up.isApprox(Eigen::Vector3d::UnitY(), 1e-9));
  ASSERT_FALSE(e.c3d.messages.empty());
  EXPECT_NE(e.c3d.messages.front().find("turned to +Z"), std::string::npos) << e.c3d.messages.front();
  const Eigen::Index n = e.estimate.time_s.size();
  for (std::size_t side = 0; side < 2; ++side) {
    const Ezc3dPlatform p = ezc3d_platform(e.file, side);
    EXPECT_NEAR(p.frame.col(2).z(), -1.0, 1e-9);
    double most = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index k = e.estimate.first_index + i;
      if (!e.estimate.feet[side].contact[static_cast<std::size_t>(i)]) continue;
      const Eigen::Vector2d f = e.estimate.feet[side].force_N.row(i).transpose();
      ASSERT_NEAR(p.F[static_cast<std::size_t>(k)].z(), f.y(), 0.01) << "vertical along +Z";
      most = std::max(most, f.y());
    }
    EXPECT_GT(most, 500.0);
  }
  const auto& m = walk.markers;
  for (std::size_t k = 0; k < m.names.size(); ++k) {
    const Eigen::Index f = m.frames() / 2;
    if (!m.positions_m[k].row(f).allFinite()) continue;
    EXPECT_NEAR(e.file.points[static_cast<std::size_t>(f)](static_cast<Eigen::Index>(k), 2), 1000 * m.positions_m[k](f, 1), 1e-2);
  }
}

// A recorded Plug-in Gait walk (Vicon, its frames from 710, 12 gait events, three measured
// plates): the export keeps its frame numbers, its markers and its own events (no estimated ones
// added beside them), and carries the two estimated platforms in place of the measured ones.
TEST(C3dExport, ARecordedWalkKeepsItsFramesItsEventsAndNotItsMeasuredPlates) {
  KIN2GRF_REQUIRE_DATA();
  const Trial walk = read_c3d(test::data_file("btk_plugingait_walk/PiG_Motion3_FF.c3d"));
  ASSERT_TRUE(walk.plates && walk.plates->plates.size() == 3);
  ASSERT_EQ(walk.events.size(), 12u);
  ASSERT_GT(walk.markers.first_frame, 1);
  const Exported e = export_walk(walk, recognise_marker_set(walk.markers));
  const Decoded& d = e.file;
  EXPECT_EQ(d.number("FORCE_PLATFORM:USED"), 2);
  EXPECT_EQ(d.number("ANALOG:USED"), 12);
  EXPECT_EQ(d.number("TRIAL:ACTUAL_START_FIELD", 0), walk.markers.first_frame);
  ASSERT_EQ(d.points.size(), static_cast<std::size_t>(walk.markers.frames()));
  ASSERT_EQ(d.at("EVENT:LABELS").strings.size(), walk.events.size());
  for (std::size_t k = 0; k < walk.events.size(); ++k) {
    EXPECT_EQ(d.at("EVENT:LABELS").strings[k], walk.events[k].label);
    EXPECT_NEAR(d.number("EVENT:TIMES", 2 * k + 1), walk.events[k].time_s, 1e-5);
  }
  bool said_kept = false;
  for (const auto& m : e.c3d.messages) said_kept = said_kept || m.find("own events kept") != std::string::npos;
  EXPECT_TRUE(said_kept);
  // The estimated right foot's vertical force on platform 1, as ezc3d reads it, peaks at about a
  // body weight and more.
  const Ezc3dPlatform right = ezc3d_platform(d, 0);
  double peak = 0;
  for (const auto& F : right.F) peak = std::max(peak, F.z());
  EXPECT_GT(peak, 1.0 * e.estimate.mass_kg * 9.81);
  EXPECT_LT(peak, 1.6 * e.estimate.mass_kg * 9.81);
}

// A 4-minute walk's 400 gait events, more than C3D's EVENT group holds: the first 255 are
// written and the messages say so (the writer itself refuses more: C3dRoundTrip's test).
TEST(C3dExport, EventsBeyond255AreCutWithAMessage) {
  Exported e = export_walk(make_example_walk());
  for (int k = 0; k < 400; ++k) e.trial.events.push_back(Event{k % 2 ? "Foot Off" : "Foot Strike", Side::Left, 0.01 * k});
  const C3dExport c = c3d_export(e.trial, e.estimate);
  ASSERT_EQ(c.trial.events.size(), kMaxC3dEvents);
  EXPECT_NEAR(c.trial.events.back().time_s, 2.54, 1e-9);
  bool said = false;
  for (const auto& m : c.messages) said = said || m.find("the first 255 of 400 events written") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_NO_THROW((void)write_c3d_bytes(c.trial));
}

// A TRC whose frames count from 0: the C3D's count from 1 (a C3D header holds 1-65535), said in
// the messages, and its events stay at their times (row 0 at 0 s either way).
TEST(C3dExport, FramesCountedFromZeroAreWrittenFromOne) {
  Trial walk = make_example_walk();
  walk.markers.first_frame = 0;
  const Exported e = export_walk(walk);
  EXPECT_EQ(e.c3d.first_frame, 1);
  EXPECT_EQ(e.file.number("TRIAL:ACTUAL_START_FIELD", 0), 1);
  bool said = false;
  for (const auto& m : e.c3d.messages) said = said || m.find("outside the 1-65535 a C3D header holds") != std::string::npos;
  EXPECT_TRUE(said);
  ASSERT_FALSE(e.c3d.trial.events.empty());
  const auto events = gait_events({e.estimate.feet[0].contact, e.estimate.feet[1].contact}, e.estimate.time_s, e.estimate.motion.rate_hz);
  EXPECT_NEAR(e.c3d.trial.events.front().time_s, e.estimate.time_s[events.front().index], 1e-12);
}

// The whole chain, read back as a lab would use it: the export of a straight walk read by
// kin2grf's reader and validated against its own platforms, with validate's check of which foot
// stands on which plate (what an automatic assignment of platforms to feet does). Each platform
// meets the other on the line between the feet, so no stance has the other foot on its platform,
// and the estimate from the file's markers matches its platforms.
TEST(C3dExport, EachFootAloneStandsOnItsPlatformAndTheFileValidatesAgainstItself) {
  const Exported e = export_walk(make_example_walk());
  bool said_overlap = false;
  for (const auto& m : e.c3d.messages) said_overlap = said_overlap || m.find("overlap") != std::string::npos;
  EXPECT_FALSE(said_overlap);
  C3dWriteOptions o;
  o.first_frame = e.c3d.first_frame;
  const Trial back = read_c3d_bytes(write_c3d_bytes(e.c3d.trial, o), "exported.c3d");
  ASSERT_TRUE(back.plates.has_value());
  const EstimateResult again = estimate(back, nullptr, *find_marker_set("kin2grf-example"), [] {
    EstimateOptions eo;
    eo.keep_all_series = true;
    return eo;
  }());
  const ValidationResult v = validate(again, *back.plates);
  for (const auto& x : v.excluded) EXPECT_EQ(x.find("also stands on this plate"), std::string::npos) << x;
  std::array<int, 2> kept{0, 0};
  for (const auto& s : v.stances) {
    ++kept[static_cast<std::size_t>(s.foot)];
    ASSERT_TRUE(s.metrics.vertical.has_value());
    EXPECT_LT(s.metrics.vertical->rrmse_percent, 0.5) << side_name(s.foot) << " on " << s.plate;
  }
  EXPECT_GE(kept[0], 1);
  EXPECT_GE(kept[1], 1);
}

// A walk whose feet's path runs at an angle to the pelvis's travel (walking5's, about 4 degrees):
// the feet's markers sheared across the progression by 0.07 of their distance along it. The
// platforms then run along the feet's path, so that each foot's COPs keep inside its own platform
// and off the other's, which a pair of platforms along the pelvis's travel could not give.
TEST(C3dExport, ThePlatformsFollowAFeetPathAtAnAngleToThePelvisTravel) {
  Trial walk = make_example_walk();
  auto& m = walk.markers;
  for (std::size_t k = 0; k < m.names.size(); ++k) {
    const std::string& name = m.names[k];
    const std::string part = name.substr(1);
    if (part != "AJC" && part != "HEE" && part != "MT1" && part != "HLX") continue;
    m.positions_m[k].col(1) += 0.07 * m.positions_m[k].col(0);
  }
  const Exported e = export_walk(walk);
  for (const auto& msg : e.c3d.messages) EXPECT_EQ(msg.find("overlap"), std::string::npos) << msg;
  const auto feet = as_lab_plates(e.estimate);
  const std::array<Ezc3dPlatform, 2> plates{ezc3d_platform(e.file, 0), ezc3d_platform(e.file, 1)};
  std::array<Eigen::Vector2d, 2> half;
  for (std::size_t side = 0; side < 2; ++side) {
    std::array<Eigen::Vector3d, 4> c;
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = 0; j < 3; ++j) c[i](static_cast<Eigen::Index>(j)) = e.file.number("FORCE_PLATFORM:CORNERS", side * 12 + i * 3 + j);
    half[side] = Eigen::Vector2d((c[0] - c[1]).norm() / 2, (c[0] - c[3]).norm() / 2);
    // The platform's x along the sheared path: 0.07 rad off the progression, not along it.
    const Eigen::Vector3d x = plates[side].frame.col(0);
    EXPECT_NEAR(std::abs(std::atan2(x.y(), x.x())), std::atan(0.07), 0.02) << side_name(static_cast<int>(side));
  }
  int checked = 0;
  for (std::size_t side = 0; side < 2; ++side)
    for (Eigen::Index i = 0; i < e.estimate.time_s.size(); ++i) {
      if (!e.estimate.feet[side].contact[static_cast<std::size_t>(i)] || !feet[side].cop_m.row(i).allFinite()) continue;
      const Eigen::Vector3d cop_mm = 1000.0 * Eigen::Vector3d(feet[side].cop_m.row(i).transpose());
      const Eigen::Vector3d q = plates[side].frame.transpose() * (cop_mm - plates[side].mean_corners);
      EXPECT_LE(std::abs(q.x()), half[side].x());
      EXPECT_LE(std::abs(q.y()), half[side].y() + 1e-6);
      const Eigen::Vector3d o = plates[1 - side].frame.transpose() * (cop_mm - plates[1 - side].mean_corners);
      EXPECT_TRUE(std::abs(o.x()) > half[1 - side].x() || std::abs(o.y()) >= half[1 - side].y() - 1e-6);
      ++checked;
    }
  EXPECT_GT(checked, 100);
}
