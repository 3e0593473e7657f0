#include "kin2grf/dynamics/mediolateral.hpp"

#include "kin2grf/error.hpp"
#include "kin2grf/kinematics/filter.hpp"

namespace kin2grf {

UpperBodySegments upper_body_segments(const std::array<Eigen::MatrixX3d, kUpperBodyCount>& p, const AnthropometricTable& t) {
  UpperBodySegments out;
  std::vector<std::string> names;
  for (int side = 0; side < 2; ++side) {
    const auto& S = p[static_cast<std::size_t>(side ? kShoulderL : kShoulderR)];
    const auto& E = p[static_cast<std::size_t>(side ? kElbowL : kElbowR)];
    const auto& W = p[static_cast<std::size_t>(side ? kWristL : kWristR)];
    if (S.rows() == 0 || E.rows() != S.rows() || W.rows() != S.rows()) continue;
    out.parts.push_back({t.upper_arm.mass_fraction, S + t.upper_arm.com_fraction * (E - S)});
    out.parts.push_back({t.forearm.mass_fraction, E + t.forearm.com_fraction * (W - E)});
    out.parts.push_back({t.hand.mass_fraction, W});
    names.emplace_back(side ? "the left arm" : "the right arm");
  }
  if (p[kHead].rows() > 0) {
    out.parts.push_back({t.head.mass_fraction, p[kHead]});
    names.emplace_back("the head");
  }
  for (std::size_t k = 0; k < names.size(); ++k)
    out.description += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
  return out;
}

MediolateralForces mediolateral_forces(const ModelMotion& motion, const std::array<Eigen::MatrixX3d, kLandmarkCount>& landmark_lab_m,
                                       const Eigen::MatrixX3d& lateral_axis, double cutoff_hz, const std::array<FootLoad, 2>& feet,
                                       double leg_cutoff_hz, bool own_leg_inertia, const UpperBodySegments* upper) {
  const Model& model = *motion.model;
  const Eigen::Index n = motion.frames();
  bool sizes = lateral_axis.rows() == n;
  for (const auto& p : landmark_lab_m) sizes = sizes && p.rows() == n;
  if (!sizes) throw InputError("mediolateral force: the landmarks' lab positions do not match the motion's frames");
  double mass = 0;
  for (const Body& b : model.bodies) mass += b.mass_kg;
  // A segment's COM in the lab, times its mass (a linear filter: the same as filtering each landmark).
  const auto first_moment = [&](int s) -> Eigen::MatrixXd {
    const Body& b = model.bodies[static_cast<std::size_t>(s)];
    const double f = b.com_fraction();
    return b.mass_kg * ((1 - f) * landmark_lab_m[static_cast<std::size_t>(b.proximal)] + f * landmark_lab_m[static_cast<std::size_t>(b.points[0])]);
  };
  const auto lateral_part = [&](const Eigen::MatrixXd& a) -> Eigen::VectorXd { return (a.array() * lateral_axis.array()).rowwise().sum().matrix(); };
  Eigen::MatrixXd com = Eigen::MatrixXd::Zero(n, 3);
  for (int s = 0; s < kSegmentCount; ++s) com += first_moment(s) / mass;
  if (upper && !upper->parts.empty()) {
    const Eigen::MatrixXd hat_com = first_moment(kTorso) / model.bodies[kTorso].mass_kg;
    for (const auto& part : upper->parts) {
      if (part.com_m.rows() != n) throw InputError("mediolateral force: an upper-body segment does not match the motion's frames");
      // The part's mass moves from the HAT's COM to its own.
      com += part.mass_fraction * (part.com_m - hat_com);
    }
  }
  if (cutoff_hz > 0) com = butterworth_filtfilt(std::move(com), motion.rate_hz, cutoff_hz);
  MediolateralForces out;
  out.com_lateral_m = lateral_part(com);
  out.total_N = mass * lateral_part(second_difference(com, 1.0 / motion.rate_hz));
  const double leg_cutoff = leg_cutoff_hz > 0 ? leg_cutoff_hz : cutoff_hz;
  for (int k = 0; k < 2; ++k) {
    out.foot_N[static_cast<std::size_t>(k)] = Eigen::VectorXd::Zero(n);
    auto& lower_leg = out.lower_leg_N[static_cast<std::size_t>(k)];
    if (!own_leg_inertia) {
      lower_leg = Eigen::VectorXd::Zero(n);
      continue;
    }
    Eigen::MatrixXd leg = Eigen::MatrixXd::Zero(n, 3);
    for (LegSegment s : {kShank, kFoot, kToes}) leg += first_moment(segment(k, s));
    if (leg_cutoff > 0) leg = butterworth_filtfilt(std::move(leg), motion.rate_hz, leg_cutoff);
    lower_leg = lateral_part(second_difference(leg, 1.0 / motion.rate_hz));
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    std::array<double, 2> fy{0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
      const FootLoad& foot = feet[static_cast<std::size_t>(k)];
      if ((*foot.contact)[static_cast<std::size_t>(i)] && (*foot.vertical_N)[i] > 0) fy[static_cast<std::size_t>(k)] = (*foot.vertical_N)[i];
    }
    const double sum_fy = fy[0] + fy[1];
    if (!(sum_fy > 0)) continue;  // flight: no foot to carry it
    double rest = out.total_N[i];
    for (int k = 0; k < 2; ++k)
      if (fy[static_cast<std::size_t>(k)] > 0) rest -= out.lower_leg_N[static_cast<std::size_t>(k)][i];
    for (int k = 0; k < 2; ++k)
      if (fy[static_cast<std::size_t>(k)] > 0)
        out.foot_N[static_cast<std::size_t>(k)][i] = out.lower_leg_N[static_cast<std::size_t>(k)][i] + rest * fy[static_cast<std::size_t>(k)] / sum_fy;
  }
  return out;
}

}  // namespace kin2grf
