#include "kin2grf/synth/example.hpp"

#include <cmath>

#include "kin2grf/io/force_plate.hpp"
#include "kin2grf/pipeline.hpp"

namespace kin2grf {

Trial example_trial_frame(const std::string& path, double duration_s, double rate_hz, double mass_kg) {
  Trial t;
  t.path = path;
  t.format = "C3D";
  t.body_mass_kg = mass_kg;
  auto& m = t.markers;
  m.rate_hz = rate_hz;
  const int n = static_cast<int>(std::lround(duration_s * rate_hz));
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / rate_hz);
  m.up_axis = Axis::Z;
  const char* names[] = {"SHO", "HJC", "KJC", "AJC", "HEE", "MT1", "HLX"};
  for (const char* side : {"R", "L"})
    for (const char* nm : names) m.names.push_back(std::string(side) + nm);
  m.descriptions.assign(m.names.size(), "");
  m.positions_m.assign(m.names.size(), Eigen::MatrixX3d(n, 3));
  return t;
}

Trial make_synthetic_trial(const SyntheticOptions& o) {
  Trial t = example_trial_frame("synthetic", o.duration_s, o.rate_hz, o.mass_kg);
  auto& m = t.markers;
  const auto n = static_cast<int>(m.frames());
  const double Lsh = 0.43, Lth = 0.44, Lt = 0.55;
  for (int i = 0; i < n; ++i) {
    const double time = m.time_s[i];
    const double s = o.squat_depth * 0.5 * (1 - std::cos(2 * M_PI * time / o.squat_period_s)) * 0.6;
    // Flight: standing, then a ballistic parabola of apex flight_height_m in the middle third.
    double lift = 0.0;
    if (o.flight_height_m > 0) {
      const double g = 9.81, v0 = std::sqrt(2 * g * o.flight_height_m), tf = 2 * v0 / g;
      const double t1 = 0.5 * (o.duration_s - tf);
      if (time > t1 && time < t1 + tf) lift = v0 * (time - t1) - 0.5 * g * (time - t1) * (time - t1);
    }
    // Sagittal (x forward, z up): feet flat, shank leans forward, thigh back, torso forward.
    const Eigen::Vector2d ankle(0.0, 0.08 + lift), heel(-0.05, 0.035 + lift), mt(0.13, 0.025 + lift), hallux(0.19, 0.02 + lift);
    const double th_sh = M_PI / 2 - 0.45 * s, th_th = M_PI / 2 + 0.9 * s, th_t = M_PI / 2 - 0.35 * s;
    const Eigen::Vector2d knee = ankle + Lsh * Eigen::Vector2d(std::cos(th_sh), std::sin(th_sh));
    const Eigen::Vector2d hip = knee + Lth * Eigen::Vector2d(std::cos(th_th), std::sin(th_th));
    const Eigen::Vector2d sho = hip + Lt * Eigen::Vector2d(std::cos(th_t), std::sin(th_t));
    const Eigen::Vector2d pts[] = {sho, hip, knee, ankle, heel, mt, hallux};
    for (int side = 0; side < 2; ++side) {
      const double y = side == 0 ? -0.1 : 0.1;  // right foot at -Y (Y points left)
      for (int k = 0; k < 7; ++k) {
        Eigen::Vector2d p = pts[k];
        if (side == 1 && k >= 2 && o.left_leg_raised_rad > 0) {
          // Rotate the left leg about the hip (counter-clockwise: swung forward).
          const double a = o.left_leg_raised_rad;
          const Eigen::Vector2d d = p - hip;
          p = hip + Eigen::Vector2d(std::cos(a) * d.x() - std::sin(a) * d.y(), std::sin(a) * d.x() + std::cos(a) * d.y());
        }
        m.positions_m[static_cast<std::size_t>(7 * side + k)].row(i) << p.x(), y, p.y();
      }
    }
  }
  return t;
}

ForcePlateRecording example_plates(const EstimateResult& r, const Trial& t, int unloaded_ends) {
  const auto feet = as_lab_plates(r);
  ForcePlateRecording rec;
  rec.rate_hz = t.markers.rate_hz;
  rec.time_s = r.time_s;
  for (int side = 0; side < 2; ++side) {
    ForcePlate p = feet[static_cast<std::size_t>(side)];
    p.name = side ? "FP2" : "FP1";
    p.type = 2;
    const double y0 = side ? 0.0 : -0.5;  // right plate at -Y, left at +Y
    set_plate_corners(p, {Eigen::Vector3d(0.4, y0 + 0.5, 0), Eigen::Vector3d(-0.2, y0 + 0.5, 0), Eigen::Vector3d(-0.2, y0, 0),
                          Eigen::Vector3d(0.4, y0, 0)});
    p.origin_m = Eigen::Vector3d(0, 0, -0.04);
    const Eigen::Index n = p.force_N.rows();
    for (Eigen::Index i = 0; i < n; ++i) {
      if (i < unloaded_ends || i >= n - unloaded_ends) {
        p.force_N.row(i).setZero();
        p.cop_m.row(i).setConstant(std::nan(""));
      }
      if (!p.cop_m.row(i).allFinite()) p.cop_m.row(i) = p.centre_m.transpose();
      // Moment about the surface centre: the force at the COP (a plate's free moment is zero here).
      p.moment_centre_Nm.row(i) = (Eigen::Vector3d(p.cop_m.row(i).transpose()) - p.centre_m).cross(Eigen::Vector3d(p.force_N.row(i).transpose())).transpose();
    }
    rec.plates.push_back(p);
  }
  return rec;
}

}  // namespace kin2grf
