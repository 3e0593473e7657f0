#include "kin2grf/output/c3d_export.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/force_plate.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {

namespace {

bool is_gait_event(const std::string& label) {
  const std::string l = to_lower(label);
  return l == "foot strike" || l == "foot off";
}

/// The rotation that takes `up` to +Z (the identity when it is +Z already); an axis-aligned up
/// gives a matrix of exact 0 and +-1.
Eigen::Matrix3d up_to_z(const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  if ((u - Eigen::Vector3d::UnitZ()).norm() < 1e-12) return Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(u, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Eigen::Index k = 0; k < R.size(); ++k)
    if (std::abs(R.data()[k] - std::round(R.data()[k])) < 1e-12) R.data()[k] = std::round(R.data()[k]);
  return R;
}

/// The platforms' axes on the floor, along the feet's path and to the walker's right: the
/// progression `u` (and `w`, u x w pointing down) turned by the slope of the feet's COPs across it
/// (one slope for both feet, least squares about each foot's own mean: a walk at an angle to the
/// pelvis's travel), where each foot's COPs span more than kPathSpanM along it.
std::pair<Eigen::Vector3d, Eigen::Vector3d> path_axes(const Eigen::Vector3d& u, const Eigen::Vector3d& w,
                                                      const std::array<std::vector<Eigen::Vector3d>, 2>& cops) {
  double suw = 0, suu = 0;
  for (const auto& c : cops) {
    if (c.empty()) return {u, w};
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& p : c) mean += Eigen::Vector2d(p.dot(u), p.dot(w)) / static_cast<double>(c.size());
    for (const auto& p : c) {
      const double du = p.dot(u) - mean.x(), dw = p.dot(w) - mean.y();
      suw += du * dw, suu += du * du;
      lo = std::min(lo, p.dot(u)), hi = std::max(hi, p.dot(u));
    }
    if (!(hi - lo > kPathSpanM)) return {u, w};
  }
  if (!(suu > 0)) return {u, w};
  const double b = suw / suu;
  return {(u + b * w).normalized(), (w - b * u).normalized()};
}

}  // namespace

C3dExport c3d_export(const Trial& trial, const EstimateResult& r) {
  C3dExport out;
  const MarkerTrajectories& m = trial.markers;
  const Eigen::Index N = m.frames();
  const Eigen::Matrix3d R = up_to_z(r.frame.up);
  if (!R.isIdentity()) {
    char b[200];
    std::snprintf(b, sizeof b, "C3D: the trial's up direction (%.3g, %.3g, %.3g) turned to +Z, C3D's convention (every position and force rotated alike)",
                  r.frame.up.x(), r.frame.up.y(), r.frame.up.z());
    out.messages.emplace_back(b);
  }
  out.trial.path = trial.path;
  out.trial.format = "C3D";
  out.trial.markers = R.isIdentity() ? m : rotated(m, R, Axis::Z);
  out.trial.markers.up_axis = Axis::Z;
  out.first_frame = m.first_frame >= 1 && m.first_frame <= 65535 ? m.first_frame : 1;
  if (out.first_frame != m.first_frame)
    out.messages.push_back("C3D: frame numbers start at 1 (the trial's first frame, " + std::to_string(m.first_frame) +
                           ", is outside the 1-65535 a C3D header holds)");
  out.trial.body_mass_kg = r.mass_kg;
  out.trial.height_m = trial.height_m;

  // The feet's ground reactions over the whole trial, in the output frame; zero outside contact
  // and outside the window, as the OpenSim export writes them.
  auto feet = trial_foot_plates(r, N, R);
  const double floor_m = r.ground_level_m();  // along up, which R takes to +Z
  ForcePlateRecording rec;
  rec.rate_hz = m.rate_hz;
  rec.time_s = out.trial.markers.time_s;
  rec.up_axis = Axis::Z;
  std::array<std::vector<Eigen::Vector3d>, 2> cops;  // each foot's loaded COPs, output frame
  for (int side = 0; side < 2; ++side) {
    const auto s = static_cast<std::size_t>(side);
    ForcePlate& p = feet[s];
    p.name = side ? "kin2grf left foot" : "kin2grf right foot";
    p.type = 2;
    p.moment_centre_Nm = Eigen::MatrixX3d::Constant(N, 3, std::numeric_limits<double>::quiet_NaN());
    for (Eigen::Index k = 0; k < N; ++k)
      if (p.cop_m.row(k).allFinite()) cops[s].emplace_back(p.cop_m.row(k).transpose());
    rec.plates.push_back(std::move(p));
  }
  // The platforms' axes on the floor; a turning walker's path has no one direction, so the output
  // frame's x and -y.
  const bool straight = !r.frame.turning();
  const auto [u, w] = straight ? path_axes(R * r.frame.forward, R * r.frame.lateral, cops)
                               : std::pair<Eigen::Vector3d, Eigen::Vector3d>{Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY()};
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::array<Eigen::Vector4d, 2> box;  // along u min, max; along w min, max, of each foot's COPs
  std::array<double, 2> mean_w{0.0, 0.0};
  const std::array<bool, 2> loaded{!cops[0].empty(), !cops[1].empty()};
  for (std::size_t s = 0; s < 2; ++s) {
    box[s] << inf, -inf, inf, -inf;
    for (const auto& c : cops[s]) {
      const double cu = c.dot(u), cw = c.dot(w);
      box[s] = Eigen::Vector4d(std::min(box[s][0], cu), std::max(box[s][1], cu), std::min(box[s][2], cw), std::max(box[s][3], cw));
      mean_w[s] += cw;
    }
    if (loaded[s]) mean_w[s] /= static_cast<double>(cops[s].size());
  }
  for (int side = 0; side < 2; ++side) {
    const auto s = static_cast<std::size_t>(side);
    if (loaded[s]) continue;
    // A foot never loaded: its platform (zero throughout) where the other foot's is, else about
    // the lab's origin.
    box[s] = loaded[1 - s] ? box[1 - s] : Eigen::Vector4d::Zero();
    out.messages.push_back(std::string("C3D: the ") + side_name(side) + " foot is never loaded; its platform carries zero");
  }
  std::array<Eigen::Vector4d, 2> extent;
  for (std::size_t s = 0; s < 2; ++s)
    extent[s] = box[s] + Eigen::Vector4d(-kLoadedFootMarginM, kLoadedFootMarginM, -kLoadedFootMarginM, kLoadedFootMarginM);
  // Where each foot's COPs keep to its own side of the line midway between the feet's mean paths
  // (the right foot's to the right), the platforms meet on that line instead of overlapping: the
  // other foot then never stands on a foot's platform, and a tool that assigns each platform to
  // the one foot over it (Nexus's automatic contexts, validate's own check) can.
  const double mid = 0.5 * (mean_w[0] + mean_w[1]);
  const bool apart = straight && loaded[0] && loaded[1] && box[0][2] > mid && box[1][3] < mid;
  if (apart) {
    extent[0][2] = mid;
    extent[1][3] = mid;
  } else if (loaded[0] && loaded[1]) {
    out.messages.push_back(straight ? "C3D: the feet's COP paths cross (a foot steps over the line between them); the two platforms overlap: "
                                      "assign platform 1 to the right foot and 2 to the left by hand"
                                    : "C3D: a turning walker: the two platforms are the feet's paths' bounding rectangles in the lab and "
                                      "overlap: assign platform 1 to the right foot and 2 to the left by hand");
  }
  for (int side = 0; side < 2; ++side) {
    ForcePlate& p = rec.plates[static_cast<std::size_t>(side)];
    const Eigen::Vector4d& e = extent[static_cast<std::size_t>(side)];
    const Eigen::Vector3d z = floor_m * Eigen::Vector3d::UnitZ();
    // C3D's corner order with the platform's z pointing down: c1 - c2 along u (forward), c1 - c4
    // along w (to the right), u x w = -up.
    set_plate_corners(p, {Eigen::Vector3d(e[1] * u + e[3] * w + z), Eigen::Vector3d(e[0] * u + e[3] * w + z),
                          Eigen::Vector3d(e[0] * u + e[2] * w + z), Eigen::Vector3d(e[1] * u + e[2] * w + z)});
    p.origin_m.setZero();
  }
  out.trial.plates = std::move(rec);

  // Events on the C3D's clock: row i at (first_frame - 1 + i) / rate.
  const double shift_s = N > 0 ? (out.first_frame - 1) / m.rate_hz - m.time_s[0] : 0.0;
  bool has_gait_events = false;
  for (const Event& e : trial.events) {
    out.trial.events.push_back(Event{e.label, e.side, e.time_s + shift_s});
    has_gait_events = has_gait_events || is_gait_event(e.label);
  }
  if (has_gait_events) {
    out.messages.push_back("C3D: the file's own events kept (it has foot strikes or foot offs); the estimate's are in --events");
  } else {
    const auto events = gait_events({r.feet[0].contact, r.feet[1].contact}, r.time_s, r.motion.rate_hz);
    for (const GaitEvent& e : events)
      out.trial.events.push_back(Event{e.label, e.side == kLeft ? Side::Left : Side::Right, r.time_s[e.index] + shift_s});
    out.messages.push_back("C3D: the estimate's " + std::to_string(events.size()) +
                           " foot strike and foot off events added (the file has none)");
  }
  // C3D's EVENT group holds 255 events (its TIMES is 2 x events, each dimension a byte).
  if (out.trial.events.size() > kMaxC3dEvents) {
    std::stable_sort(out.trial.events.begin(), out.trial.events.end(), [](const Event& a, const Event& b) { return a.time_s < b.time_s; });
    char b[200];
    std::snprintf(b, sizeof b, "C3D: the first %zu of %zu events written, up to %.3f s (the EVENT group holds %zu; --events writes every estimated one)",
                  kMaxC3dEvents, out.trial.events.size(), out.trial.events[kMaxC3dEvents - 1].time_s, kMaxC3dEvents);
    out.messages.emplace_back(b);
    out.trial.events.resize(kMaxC3dEvents);
  }
  return out;
}

std::vector<std::string> write_c3d_export(const std::string& path, const Trial& trial, const EstimateResult& estimate) {
  C3dExport e = c3d_export(trial, estimate);
  C3dWriteOptions o;
  o.first_frame = e.first_frame;
  write_c3d(path, e.trial, o);
  return std::move(e.messages);
}

}  // namespace kin2grf
