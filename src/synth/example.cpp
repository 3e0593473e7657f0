#include "kin2grf/synth/example.hpp"

#include <cmath>

namespace kin2grf {

Trial make_synthetic_trial(const SyntheticOptions& o) {
  Trial t;
  t.path = "synthetic";
  t.format = "C3D";
  t.body_mass_kg = o.mass_kg;
  auto& m = t.markers;
  m.rate_hz = o.rate_hz;
  const int n = static_cast<int>(std::lround(o.duration_s * o.rate_hz));
  m.time_s = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / o.rate_hz);
  m.up_axis = Axis::Z;
  const char* names[] = {"SHO", "HJC", "KJC", "AJC", "HEE", "MT1", "HLX"};
  for (const char* side : {"R", "L"})
    for (const char* nm : names) m.names.push_back(std::string(side) + nm);
  m.descriptions.assign(m.names.size(), "");
  m.positions_m.assign(m.names.size(), Eigen::MatrixX3d(n, 3));
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
      for (int k = 0; k < 7; ++k) m.positions_m[static_cast<std::size_t>(7 * side + k)].row(i) << pts[k].x(), y, pts[k].y();
    }
  }
  return t;
}

}  // namespace kin2grf
