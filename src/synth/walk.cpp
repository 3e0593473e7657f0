// A synthetic level walk of the project's own making: the bundled example's gait and the tests'.
//
// Kinematics (x forward, y up, m; both legs share the sagittal plane, laterally 0.1 m apart):
// - Hips move forward at the walking speed v, slowest and highest at each mid-stance
//   (h0 + A cos(4 pi (t/T - 0.3))), as the body vaults over the stance leg.
// - Each foot is a rigid body whose stance follows the three rockers: heel rocker about the heel's
//   ground point from phi_hs (toes up) to flat over 8 % of the cycle, flat to 35 %, then the
//   forefoot rocker about the MT ground point to -phi_to at toe-off (60 %: 10 % double supports),
//   speeding up so that the foot leaves the ground rotating. The swing carries the foot from its
//   toe-off pose and velocity to rest at the next heel strike one stride ahead (minimum jerk plus
//   a quintic term for the initial velocity), with a heel lift of `clearance_m`; with
//   `heel_strike_descent_mps` it lands descending at that speed and stops at the heel strike.
// - Knees from the two-link inverse kinematics of hip and ankle (knee forward); the torso leans
//   forward by 0.05 rad over the hips.
// - In 3D (issue 28): the feet's lines `step_width_m` apart; the hips and shoulders (0.1 m either
//   side of the midline) sway toward the stance foot, lat(t) = -+A cos(2 pi (t/T - 0.3)),
//   furthest over each foot at its mid-stance; each foot turned outward by `toe_out_rad` about
//   the vertical through its stance's heel ground point (in swing the pivot travels with the
//   heel). The knee solves the sagittal two-link problem; its lateral place is the hip's and the
//   ankle's blended by the thigh's share of the leg.
// Ground reactions ("measured"): the model's own totals from these kinematics (sum m (a + g) and
// the moment, as estimate() computes them) are shared between the feet in contact by a rule
// that is not the method's: the trailing foot hands its share to the leading one by a cosine over
// each double support, each foot's COP starts at a nominal point (the heel during the heel
// rocker, moving to the MT head over the flat foot, the MT head in the forefoot rocker), and one
// common shift of the COPs makes the moment exact. In 3D the lateral total is shared by the same
// rule and each COP lies on its foot's long axis on the floor. So the plates agree with the kinematics
// exactly, and the method's per-foot split and COP are tested against an independent rule.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "kin2grf/io/output_file.hpp"
#include "kin2grf/error.hpp"
#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/force_plate.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/markers/landmarks.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/io/marker_presets.hpp"

namespace kin2grf {

namespace {

constexpr double kStanceEnd = 0.6, kHeelRockerEnd = 0.08, kFlatEnd = 0.35;
// Foot points relative to the heel's ground point with the foot flat (x forward, y up), m.
const Eigen::Vector2d kAnkleMarker(0.05, 0.08), kHeelMarker(0.0, 0.035), kMtMarker(0.18, 0.025), kHalluxMarker(0.24, 0.02),
    kMtGround(0.18, 0.0);

double smoothstep(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10 - 15 * u + 6 * u * u);  // minimum jerk
}
Eigen::Vector2d rotated(const Eigen::Vector2d& p, double a) {
  return {std::cos(a) * p.x() - std::sin(a) * p.y(), std::sin(a) * p.x() + std::cos(a) * p.y()};
}

/// One foot's pose at phase p of its own cycle (0 = heel strike) of stride k.
struct FootPose {
  Eigen::Vector2d heel_ground;  ///< the heel's ground point (where the foot's frame is)
  double pivot_x = 0;           ///< the heel strike's ground point (toe-out turns about it), moving in swing
  double phi = 0;               ///< inclination, + toes up
  bool stance = false;
  double stance_phase = 0;      ///< p / kStanceEnd in stance
  [[nodiscard]] Eigen::Vector2d point(const Eigen::Vector2d& local) const { return heel_ground + rotated(local, phi); }
};

FootPose stance_pose(double heel_x, double p, const SyntheticWalkOptions& o) {
  FootPose f;
  f.stance = true;
  f.stance_phase = p / kStanceEnd;
  f.pivot_x = heel_x;
  if (p < kHeelRockerEnd) {
    f.phi = o.heel_strike_angle_rad * (1 - smoothstep(p / kHeelRockerEnd));
    f.heel_ground = {heel_x, 0.0};
  } else if (p < kFlatEnd) {
    f.heel_ground = {heel_x, 0.0};
  } else {
    // Heel rise speeding up to toe-off: the foot leaves the ground rotating (about 5 rad/s), as
    // a push-off does, not at rest.
    const double u = (p - kFlatEnd) / (kStanceEnd - kFlatEnd);
    f.phi = -o.toe_off_angle_rad * u * u;
    const Eigen::Vector2d pivot(heel_x + kMtGround.x(), 0.0);
    f.heel_ground = pivot + rotated(-kMtGround, f.phi);
  }
  return f;
}

/// The right foot's first heel strike (x, m): its ankle is under the hip at mid-stance.
double right_first_heel_x(const SyntheticWalkOptions& o) { return 0.3 * o.speed_mps * o.stride_time_s - kAnkleMarker.x(); }

FootPose foot_pose(double cycles, double first_heel_x, const SyntheticWalkOptions& o) {
  const double stride = o.speed_mps * o.stride_time_s;
  const double k = std::floor(cycles), p = cycles - k;
  const double heel_x = first_heel_x + k * stride;
  if (p < kStanceEnd) return stance_pose(heel_x, p, o);
  const double h = 1e-6;
  const FootPose off = stance_pose(heel_x, kStanceEnd - 1e-12, o), before = stance_pose(heel_x, kStanceEnd - h, o),
                 on = stance_pose(heel_x + stride, 0.0, o);
  const double u = (p - kStanceEnd) / (1 - kStanceEnd), s = smoothstep(u);
  // The swing starts with the foot's toe-off velocity (the quintic Hermite term of the initial
  // velocity: zero at both ends, slope 1 at the start) and ends at rest.
  const double carry = (1 - kStanceEnd) / h * (u - 6 * std::pow(u, 3) + 8 * std::pow(u, 4) - 3 * std::pow(u, 5));
  FootPose f;
  f.phi = off.phi + (on.phi - off.phi) * s + (off.phi - before.phi) * carry;
  f.heel_ground = off.heel_ground + (on.heel_ground - off.heel_ground) * s + (off.heel_ground - before.heel_ground) * carry;
  f.heel_ground.y() += o.clearance_m * std::pow(std::sin(M_PI * u), 2);
  // A landing at speed: the quintic Hermite term of the final velocity (zero at both ends, zero
  // velocity and acceleration at the start and acceleration at the end, slope 1 at the end),
  // scaled to the swing's duration; it keeps the foot above its path (u^3 (3u - 4)(1 - u) <= 0).
  f.heel_ground.y() -= o.heel_strike_descent_mps * (1 - kStanceEnd) * o.stride_time_s * (-4 * std::pow(u, 3) + 7 * std::pow(u, 4) - 3 * std::pow(u, 5));
  f.pivot_x = heel_x + stride * s;
  return f;
}

}  // namespace

SyntheticWalk make_synthetic_walk(const SyntheticWalkOptions& o) {
  if (!(o.speed_mps > 0.2 && o.speed_mps < 2.5 && o.stride_time_s > 0.6 && o.stride_time_s < 2.5 && o.duration_s >= 2 * o.stride_time_s &&
        o.duration_s <= 600 && o.rate_hz >= 50 && o.rate_hz <= 2000 && o.heel_strike_descent_mps >= 0 && o.heel_strike_descent_mps <= 1))
    throw InputError("synthetic walk: speed 0.2-2.5 m/s, stride time 0.6-2.5 s, at least two strides, 50-2000 Hz, heel-strike descent 0-1 m/s");
  SyntheticWalk w;
  w.trial = example_trial_frame("synthetic walk", o.duration_s, o.rate_hz, o.mass_kg);
  auto& m = w.trial.markers;
  const auto n = static_cast<int>(m.frames());
  const double Lsh = 0.43, Lth = 0.44, Lt = 0.55, T = o.stride_time_s, v = o.speed_mps;
  const double first_heel_x = right_first_heel_x(o);
  for (auto& f : w.nominal_cop_x_m) f = Eigen::VectorXd::Constant(n, std::nan(""));
  for (auto& c : w.stance) c.assign(static_cast<std::size_t>(n), false);
  for (auto& s : w.stance_phase) s = Eigen::VectorXd::Zero(n);
  for (auto& s : w.sole_x_m) s = Eigen::MatrixX2d::Constant(n, 2, std::nan(""));
  for (auto& s : w.sole_axis_origin_m) s = Eigen::MatrixX2d::Constant(n, 2, std::nan(""));
  const bool toe_out = o.toe_out_rad != 0.0;  // without it, x is the foot's own (no round-off)
  for (int side = 0; side < 2; ++side)
    w.sole_axis_direction[static_cast<std::size_t>(side)] << std::cos(o.toe_out_rad), (side ? 1 : -1) * std::sin(o.toe_out_rad);
  for (int i = 0; i < n; ++i) {
    const double time = m.time_s[i];
    // Slowest and highest at each mid-stance (t/T = 0.3 and 0.8): braking, then propulsion.
    const double wave = 4 * M_PI * (time / T - 0.3);
    const Eigen::Vector2d hip(v * time - o.speed_oscillation_mps * T / (4 * M_PI) * std::sin(wave),
                              o.hip_height_m + o.hip_oscillation_m * std::cos(wave));
    const Eigen::Vector2d sho = hip + Lt * Eigen::Vector2d(std::cos(M_PI / 2 - 0.05), std::sin(M_PI / 2 - 0.05));
    // Over the right foot (-Y) at its mid-stance (t/T = 0.3), over the left half a stride later.
    const double sway = -o.lateral_sway_m * std::cos(2 * M_PI * (time / T - 0.3));
    for (int side = 0; side < 2; ++side) {
      // The left foot is half a cycle ahead in its cycle: its current stance began half a stride back.
      const double cycles = time / T + (side ? 0.5 : 0.0);
      const FootPose f = foot_pose(cycles, first_heel_x - (side ? 0.5 * v * T : 0.0), o);
      const double foot_y = (side == 0 ? -0.5 : 0.5) * o.step_width_m, body_y = (side == 0 ? -0.1 : 0.1) + sway;
      const Eigen::Vector2d& dir = w.sole_axis_direction[static_cast<std::size_t>(side)];
      // A foot point's lab (x, y, z): its sagittal (x, z) turned outward about the pivot.
      const auto foot_lab = [&](const Eigen::Vector2d& local) -> Eigen::Vector3d {
        const Eigen::Vector2d q = f.point(local);
        if (!toe_out) return {q.x(), foot_y, q.y()};
        const double along = q.x() - f.pivot_x;
        return {f.pivot_x + along * dir.x(), foot_y + along * dir.y(), q.y()};
      };
      const Eigen::Vector3d ankle3 = foot_lab(kAnkleMarker);
      const Eigen::Vector2d ankle(ankle3.x(), ankle3.z());
      const Eigen::Vector2d d = ankle - hip;
      const double dist = d.norm();
      if (dist > Lth + Lsh - 1e-3) throw InputError("synthetic walk: the leg cannot reach the foot (a longer stride than the legs allow)");
      const double alpha = std::acos(std::clamp((Lth * Lth + dist * dist - Lsh * Lsh) / (2 * Lth * dist), -1.0, 1.0));
      const Eigen::Vector2d knee = hip + Lth * rotated(d / dist, alpha);  // knee forward
      const double knee_y = body_y + (ankle3.y() - body_y) * Lth / (Lth + Lsh);
      const Eigen::Vector3d pts[] = {{sho.x(), body_y, sho.y()},  {hip.x(), body_y, hip.y()}, {knee.x(), knee_y, knee.y()},
                                     ankle3,  foot_lab(kHeelMarker),  foot_lab(kMtMarker),   foot_lab(kHalluxMarker)};
      for (int k = 0; k < 7; ++k) m.positions_m[static_cast<std::size_t>(7 * side + k)].row(i) = pts[k].transpose();
      if (f.stance) {
        w.stance[side][static_cast<std::size_t>(i)] = true;
        w.stance_phase[side][i] = f.stance_phase;
        // Nominal COP: heel, then heel -> MT head over the flat foot, then the MT head (lab x).
        const double p = f.stance_phase * kStanceEnd;
        const double heel = foot_lab(Eigen::Vector2d::Zero()).x(), mt = foot_lab(kMtGround).x();
        w.sole_x_m[side](i, 0) = heel;
        w.sole_x_m[side](i, 1) = foot_lab(kHalluxMarker).x();
        w.sole_axis_origin_m[side].row(i) << f.pivot_x, foot_y;
        w.nominal_cop_x_m[side][i] =
            p < kHeelRockerEnd ? heel : p < kFlatEnd ? heel + (mt - heel) * (p - kHeelRockerEnd) / (kFlatEnd - kHeelRockerEnd) : mt;
      }
    }
  }
  return w;
}

std::array<ForcePlate, 2> synthetic_walk_feet(const SyntheticWalk& w, const EstimateResult& r) {
  const Eigen::Index n = r.time_s.size();
  std::array<ForcePlate, 2> feet;
  for (int side = 0; side < 2; ++side) {
    auto& p = feet[static_cast<std::size_t>(side)];
    p.name = side_name(side);
    p.force_N = Eigen::MatrixX3d::Zero(w.trial.markers.frames(), 3);
    p.cop_m = Eigen::MatrixX3d::Constant(w.trial.markers.frames(), 3, std::nan(""));
    p.free_moment_Nm = Eigen::MatrixX3d::Zero(w.trial.markers.frames(), 3);
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Index k = r.first_index + i;
    const auto ks = static_cast<std::size_t>(k);
    // Shares: one foot in contact takes all; in double support the foot further into its stance
    // (the trailing one) hands over by a cosine of its remaining stance.
    std::array<double, 2> share = {0, 0};
    const bool both = w.stance[0][ks] && w.stance[1][ks];
    for (int side = 0; side < 2; ++side) {
      if (!w.stance[side][ks]) continue;
      if (!both) share[side] = 1;
      else {
        const double ds = 1.0 / 6.0;  // a double support is the last (and first) sixth of a stance
        const double ph = w.stance_phase[side][k];
        share[side] = ph > 0.5 ? 0.5 * (1 + std::cos(M_PI * (ph - (1 - ds)) / ds)) : 0.5 * (1 - std::cos(M_PI * ph / ds));
      }
    }
    const double sum = share[0] + share[1];
    if (sum <= 0) continue;  // a flight: no synthetic walk has one
    const Eigen::Vector3d total = r.kinematic_total.row(i).transpose();  // (Fx, Fy, M about the origin)
    // The 3D model's lateral total (along the walker's right), shared like the rest.
    const Eigen::Vector3d lateral = r.feet[0].force_lateral_N.size() == n
                                        ? ((r.feet[0].force_lateral_N[i] + r.feet[1].force_lateral_N[i]) * r.frame.lateral_at(k)).eval()
                                        : Eigen::Vector3d::Zero();
    double moment_nominal = 0;
    for (int side = 0; side < 2; ++side)
      if (share[side] > 0) moment_nominal += w.nominal_cop_x_m[side][k] * total.y() * share[side] / sum;
    // One shift of both COPs makes sum x_i Fy_i - y_g Fx = M (floor at y_g = 0), as far as each
    // COP stays under its foot (heel to hallux): a designed gait's angular momentum is not a real
    // walker's, and a COP off the foot is no plate's.
    const double shift = (total.z() + r.ground_level_m() * total.x() - moment_nominal) / total.y();
    for (int side = 0; side < 2; ++side) {
      if (share[side] <= 0) continue;
      auto& p = feet[static_cast<std::size_t>(side)];
      const double f = share[side] / sum;
      p.force_N.row(k) << f * total.x(), f * lateral.y(), f * total.y();
      const double x = std::clamp(w.nominal_cop_x_m[side][k] + shift, w.sole_x_m[side](k, 0), w.sole_x_m[side](k, 1));
      const Eigen::Vector2d& axis = w.sole_axis_direction[static_cast<std::size_t>(side)];
      const double y = w.sole_axis_origin_m[side](k, 1) + (x - w.sole_axis_origin_m[side](k, 0)) * axis.y() / axis.x();
      p.cop_m.row(k) << x, y, r.ground_level_m();
    }
  }
  return feet;
}

Trial make_example_walk(const SyntheticWalkOptions& o) {
  SyntheticWalk w = make_synthetic_walk(o);
  const auto* set = find_marker_set("kin2grf-example");
  EstimateOptions eo;
  // Its lateral total for the plates where the walk moves sideways (the sagittal results are the
  // same); a walk in the feet's planes keeps plates with no lateral force (not round-off's).
  if (o.lateral_sway_m != 0.0 || o.toe_out_rad != 0.0) eo.model = ModelKind::ThreeD;
  const EstimateResult r = estimate(w.trial, nullptr, *set, eo);
  const auto feet = synthetic_walk_feet(w, r);
  // Two plates in series along the walkway, 0.6 m long and 0.5 m wide, each under one stance of
  // the middle stride: the right foot's on FP1, the left foot's next on FP2.
  const double v = o.speed_mps, T = o.stride_time_s;
  const int stride = std::max(1, static_cast<int>(std::floor(o.duration_s / T / 2)));
  const double right_heel = right_first_heel_x(o) + stride * v * T, left_heel = right_heel + 0.5 * v * T;
  ForcePlateRecording rec;
  rec.rate_hz = w.trial.markers.rate_hz;
  rec.time_s = w.trial.markers.time_s;
  const Eigen::Index n = w.trial.markers.frames();
  for (int k = 0; k < 2; ++k) {
    ForcePlate p;
    p.name = k ? "FP2" : "FP1";
    p.type = 2;
    const double x0 = (k ? left_heel : right_heel) - 0.18;
    set_plate_corners(p, {Eigen::Vector3d(x0 + 0.6, 0.25, 0), Eigen::Vector3d(x0, 0.25, 0), Eigen::Vector3d(x0, -0.25, 0),
                          Eigen::Vector3d(x0 + 0.6, -0.25, 0)});
    p.origin_m = Eigen::Vector3d(0, 0, -0.04);
    p.force_N = Eigen::MatrixX3d::Zero(n, 3);
    p.cop_m = Eigen::MatrixX3d::Constant(n, 3, std::nan(""));
    p.free_moment_Nm = Eigen::MatrixX3d::Zero(n, 3);
    p.moment_centre_Nm = Eigen::MatrixX3d::Zero(n, 3);
    // The plate records the stance whose foot stands on it (FP1 the right foot, FP2 the left).
    {
      const int side = k;
      for (Eigen::Index i = 0; i < n; ++i) {
        const Eigen::Vector3d cop = feet[static_cast<std::size_t>(side)].cop_m.row(i).transpose();
        const double heel = w.sole_x_m[side](i, 0);
        if (!cop.allFinite() || !(heel > x0 && heel < x0 + 0.6)) continue;
        const Eigen::Vector3d F = feet[static_cast<std::size_t>(side)].force_N.row(i).transpose();
        p.force_N.row(i) += F.transpose();
        p.moment_centre_Nm.row(i) += (cop - p.centre_m).cross(F).transpose();
      }
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d F = p.force_N.row(i).transpose(), M = p.moment_centre_Nm.row(i).transpose();
      if (F.z() > 1e-6) {
        // The COP on the surface from the force and the moment about the centre.
        p.cop_m.row(i) << p.centre_m.x() - M.y() / F.z(), p.centre_m.y() + M.x() / F.z(), 0.0;
      } else {
        p.cop_m.row(i) = p.centre_m.transpose();
      }
    }
    rec.plates.push_back(p);
  }
  w.trial.plates = rec;
  return w.trial;
}

namespace {

/// The plates at `factor` samples per frame, each channel linear between frames (held after the
/// last): the analog rate of a real capture.
ForcePlateRecording upsampled(const ForcePlateRecording& rec, int factor) {
  if (factor == 1) return rec;
  ForcePlateRecording out = rec;
  const Eigen::Index n = rec.time_s.size(), m = n * factor;
  out.rate_hz = rec.rate_hz * factor;
  out.time_s.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) out.time_s[k] = rec.time_s[0] + static_cast<double>(k) / out.rate_hz;
  auto up = [&](const Eigen::MatrixX3d& x) {
    Eigen::MatrixX3d y(m, 3);
    for (Eigen::Index k = 0; k < m; ++k) {
      const Eigen::Index i = k / factor, j = std::min(i + 1, n - 1);
      const double t = static_cast<double>(k % factor) / factor;
      y.row(k) = (1 - t) * x.row(i) + t * x.row(j);
    }
    return y;
  };
  for (std::size_t p = 0; p < rec.plates.size(); ++p) {
    out.plates[p].force_N = up(rec.plates[p].force_N);
    out.plates[p].cop_m = up(rec.plates[p].cop_m);
    out.plates[p].free_moment_Nm = up(rec.plates[p].free_moment_Nm);
    out.plates[p].moment_centre_Nm = up(rec.plates[p].moment_centre_Nm);
  }
  return out;
}

// TRC and GRF .mot files are OpenSim's, whose convention is Y up (kin2grf's readers take it so):
// the lab's (x, y, z), Z up, become (x, z, -y), a rotation about the x axis (the progression).
Eigen::Matrix3d lab_to_y_up() {
  Eigen::Matrix3d R;
  R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return R;
}

/// The plate's channels that grf_table writes (force, COP, free moment), in the Y-up frame.
ForcePlate y_up(ForcePlate p) {
  const Eigen::Matrix3d R = lab_to_y_up();
  for (Eigen::MatrixX3d* X : {&p.force_N, &p.cop_m, &p.free_moment_Nm}) *X = (*X * R.transpose()).eval();
  return p;
}

}  // namespace

std::vector<std::string> write_examples(const std::string& dir, double seconds, double rate_hz, double analog_rate_hz,
                                        double marker_noise_m) {
  if (!(std::isfinite(marker_noise_m) && marker_noise_m >= 0 && marker_noise_m <= 0.01)) {
    char b[128];
    std::snprintf(b, sizeof b, "example marker noise (--marker-noise) %g mm: must be between 0 and 10", 1000 * marker_noise_m);
    throw InputError(b);
  }
  if (!(std::isfinite(seconds) && seconds >= 1.0 && seconds <= 600.0))
  {
    char b[128];
    std::snprintf(b, sizeof b, "example duration (--seconds) %g s: must be between 1 and 600", seconds);
    throw InputError(b);
  }
  if (!(std::isfinite(rate_hz) && rate_hz >= 50 && rate_hz <= 2000)) {
    char b[128];
    std::snprintf(b, sizeof b, "example marker rate (--rate) %g Hz: must be between 50 and 2000", rate_hz);
    throw InputError(b);
  }
  if (analog_rate_hz == 0) analog_rate_hz = rate_hz;
  const double ratio = analog_rate_hz / rate_hz;
  if (!(std::isfinite(ratio) && ratio >= 1 && ratio <= 100 && ratio == std::round(ratio))) {
    char b[160];
    std::snprintf(b, sizeof b, "example analog rate (--analog-rate) %g Hz: must be 1 to 100 times the marker rate (%g Hz)",
                  analog_rate_hz, rate_hz);
    throw InputError(b);
  }
  ensure_output_folder(dir);
  std::vector<std::string> written;
  {
    SyntheticWalkOptions wo;
    wo.duration_s = std::max(seconds, 2.5 * wo.stride_time_s);
    wo.rate_hz = rate_hz;
    Trial walk = make_example_walk(wo);
    if (marker_noise_m > 0) add_marker_noise(walk.markers, marker_noise_m, 1);
    const std::string base = (std::filesystem::path(dir) / "example_walk").string();
    write_trc(base + ".trc", rotated(walk.markers, lab_to_y_up(), Axis::Y));
    const auto& p = walk.plates->plates;
    auto t = grf_table(walk.plates->time_s, y_up(p[0]), y_up(p[1]));
    t.name = "kin2grf_example_walk_plates";
    write_sto(base + "_grf.mot", t);
    // The C3D last, its plates at the analog rate in place of the marker-rate ones (no copy of the
    // markers).
    walk.plates = upsampled(*walk.plates, static_cast<int>(ratio));
    C3dWriteOptions co;
    co.analog_samples_per_frame = static_cast<int>(ratio);
    write_c3d(base + ".c3d", walk, co);
    written.push_back(base + ".c3d, .trc and _grf.mot (a walk over plates FP1 and FP2)");
  }
  SyntheticOptions so;
  so.duration_s = seconds;
  so.rate_hz = rate_hz;
  Trial t = make_synthetic_trial(so);
  const EstimateResult r = estimate(t, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{});
  t.plates = example_plates(r, t, 0);
  const std::string base = (std::filesystem::path(dir) / "example_squat").string();
  write_c3d(base + ".c3d", t);
  // The TRC and .mot in OpenSim's frame (Y up): the .mot is the estimate on those markers.
  t.plates.reset();
  t.markers = rotated(std::move(t.markers), lab_to_y_up(), Axis::Y);
  write_trc(base + ".trc", t.markers);
  write_grf_mot(base + "_grf.mot", estimate(t, nullptr, *find_marker_set("kin2grf-example"), EstimateOptions{}));
  written.push_back(base + ".c3d, .trc and _grf.mot (a squat on two plates)");
  return written;
}

}  // namespace kin2grf
