#include "kin2grf/dynamics/mediolateral.hpp"

#include "kin2grf/error.hpp"
#include "kin2grf/kinematics/filter.hpp"

namespace kin2grf {

MediolateralForces mediolateral_forces(const ModelMotion& motion, const std::array<Eigen::MatrixX3d, kLandmarkCount>& landmark_lab_m,
                                       const Eigen::MatrixX3d& lateral_axis, double cutoff_hz, const std::array<FootLoad, 2>& feet) {
  const Model& model = *motion.model;
  const Eigen::Index n = motion.frames();
  bool sizes = lateral_axis.rows() == n;
  for (const auto& p : landmark_lab_m) sizes = sizes && p.rows() == n;
  if (!sizes) throw InputError("mediolateral force: the landmarks' lab positions do not match the motion's frames");
  double mass = 0;
  for (const Body& b : model.bodies) mass += b.mass_kg;
  // The whole body's COM in the lab (a linear filter: the same as filtering each landmark).
  Eigen::MatrixXd com = Eigen::MatrixXd::Zero(n, 3);
  for (int s = 0; s < kSegmentCount; ++s) {
    const Body& b = model.bodies[s];
    const double f = b.com_fraction();
    com += (b.mass_kg / mass) * ((1 - f) * landmark_lab_m[static_cast<std::size_t>(b.proximal)] +
                                 f * landmark_lab_m[static_cast<std::size_t>(b.points[0])]);
  }
  if (cutoff_hz > 0) com = butterworth_filtfilt(std::move(com), motion.rate_hz, cutoff_hz);
  const Eigen::MatrixXd acc = second_difference(com, 1.0 / motion.rate_hz);
  MediolateralForces out;
  out.com_lateral_m = (com.array() * lateral_axis.array()).rowwise().sum().matrix();
  out.total_N = mass * (acc.array() * lateral_axis.array()).rowwise().sum().matrix();
  for (int k = 0; k < 2; ++k) out.foot_N[static_cast<std::size_t>(k)] = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    std::array<double, 2> fy{0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
      const FootLoad& foot = feet[static_cast<std::size_t>(k)];
      if ((*foot.contact)[static_cast<std::size_t>(i)] && (*foot.vertical_N)[i] > 0) fy[static_cast<std::size_t>(k)] = (*foot.vertical_N)[i];
    }
    const double sum_fy = fy[0] + fy[1];
    if (!(sum_fy > 0)) continue;  // flight: no foot to carry it
    for (int k = 0; k < 2; ++k) out.foot_N[static_cast<std::size_t>(k)][i] = out.total_N[i] * fy[static_cast<std::size_t>(k)] / sum_fy;
  }
  return out;
}

}  // namespace kin2grf
