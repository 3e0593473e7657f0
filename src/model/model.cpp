#include "kin2grf/model/model.hpp"

#include "kin2grf/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace kin2grf {

const char* joint_name(int j) {
  static const char* names[] = {"hip_r", "knee_r", "ankle_r", "mtp_r", "hip_l", "knee_l", "ankle_l", "mtp_l"};
  return names[j];
}

const char* segment_name(int s) {
  static const char* names[] = {"torso", "thigh_r", "shank_r", "foot_r", "toes_r", "thigh_l", "shank_l", "foot_l", "toes_l"};
  return names[s];
}

Eigen::VectorXd Model::mass_diagonal() const {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(coord::kCount);
  for (int s = 0; s < kSegmentCount; ++s) {
    m[coord::com_x(s)] = bodies[s].mass_kg;
    m[coord::com_x(s) + 1] = bodies[s].mass_kg;
    m[coord::theta(s)] = bodies[s].inertia_kgm2;
  }
  return m;
}

Eigen::VectorXd Model::gravity_force() const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(coord::kCount);
  for (int s = 0; s < kSegmentCount; ++s) f[coord::com_x(s) + 1] = -bodies[s].mass_kg * gravity_mps2;
  return f;
}

double leg_length_m(const Model& model) {
  const auto& b = model.bodies;
  return 0.5 * (b[kThighR].length_m + b[kShankR].length_m + b[kThighL].length_m + b[kShankL].length_m);
}

std::vector<std::string> segment_proportion_notes(const BodyGeometry& g) {
  std::vector<std::string> out;
  char b[400];
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(side);
    const double ratio = g.shank[k] / g.thigh[k];
    if (ratio < kMinShankPerThigh || ratio > kMaxShankPerThigh) {
      std::snprintf(b, sizeof b,
                    "%s is %.3f m against its thigh's %.3f m (%.2f of it; a shank is 0.9-1.1 of its thigh): the %s knee or "
                    "ankle landmark seems misplaced (a functional joint centre from a small range of motion, a marker off "
                    "its landmark): the shank's centre of mass, the foot's length and the ankle torque move with it",
                    segment_name(segment(side, kShank)), g.shank[k], g.thigh[k], ratio, side_name(side));
      out.emplace_back(b);
    }
  }
  for (const auto& [name, lengths] : {std::pair{"thigh", g.thigh}, std::pair{"shank", g.shank}}) {
    const double apart = std::abs(lengths[0] - lengths[1]) / std::max(lengths[0], lengths[1]);
    if (apart > kMaxSidesApart) {
      std::snprintf(b, sizeof b, "the right %s is %.3f m and the left %.3f m (%.0f %% apart): a landmark of one side seems misplaced",
                    name, lengths[0], lengths[1], 100 * apart);
      out.emplace_back(b);
    }
  }
  return out;
}

Model build_model(const BodyGeometry& g, double mass, const AnthropometricTable& t) {
  if (!(mass > 0) || mass > 500) throw InputError("body mass " + std::to_string(mass) + " kg is not plausible");
  Model m;
  m.body_mass_kg = mass;
  m.anthropometry = t.name;
  auto set = [&](int s, int prox, int distal, double L, const SegmentInertia& si) {
    if (!(L > 0.005) || L > 2.0)
      throw InputError(std::string("segment ") + segment_name(s) + " length " + std::to_string(L) +
                       " m is not plausible: are the markers' units right (C3D POINT:UNITS, the TRC's Units)?");
    Body& b = m.bodies[s];
    b.proximal = prox;
    b.points[0] = distal;
    b.points_local[0] = Eigen::Vector2d(L, 0);
    b.length_m = L;
    b.com_local = Eigen::Vector2d(si.com_fraction * L, 0);
    b.mass_kg = si.mass_fraction * mass;
    const double rho = si.gyration_fraction * L;
    b.inertia_kgm2 = b.mass_kg * rho * rho;
  };
  set(kTorso, kHip, kShoulder, g.torso, t.hat);
  for (int side = 0; side < 2; ++side) {
    set(segment(side, kThigh), kHip, landmark(side, kKnee), g.thigh[side], t.thigh);
    set(segment(side, kShank), landmark(side, kKnee), landmark(side, kAnkle), g.shank[side], t.shank);
    set(segment(side, kFoot), landmark(side, kAnkle), landmark(side, kMt), g.foot[side], t.foot);
    set(segment(side, kToes), landmark(side, kMt), landmark(side, kHallux), g.toes[side], t.toes);
    Body& foot = m.bodies[segment(side, kFoot)];
    foot.points[1] = landmark(side, kHeel);
    foot.points_local[1] = g.heel_local[side];
  }
  return m;
}

}  // namespace kin2grf
