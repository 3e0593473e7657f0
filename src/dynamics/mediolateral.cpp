#include "kin2grf/dynamics/mediolateral.hpp"

#include <algorithm>
#include <cmath>

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

std::vector<std::array<double, kLandmarkCount>> com_landmark_weights(const Model& model) {
  const double mass = model.body_mass_kg;  // the segments' masses sum to it (build_model)
  std::vector<std::array<double, kLandmarkCount>> w(2, std::array<double, kLandmarkCount>{});
  for (int s = 0; s < kSegmentCount; ++s) {
    const Body& b = model.bodies[static_cast<std::size_t>(s)];
    const double f = b.com_fraction(), share = s == kTorso ? 1.0 : b.mass_kg / mass;
    auto& sum = w[s == kTorso ? 1 : 0];
    sum[static_cast<std::size_t>(b.proximal)] += share * (1 - f);
    sum[static_cast<std::size_t>(b.points[0])] += share * f;
  }
  return w;
}

namespace {

/// The HAT's share of the body mass less the upper body's parts of their own (their mass leaves
/// the HAT's COM, which keeps the rest).
double hat_share(const Model& model, const UpperBodySegments* upper) {
  double share = model.bodies[kTorso].mass_kg / model.body_mass_kg;
  if (upper)
    for (const auto& part : upper->parts) share -= part.mass_fraction;
  return share;
}

/// x delayed by d frames (row i takes x at i - d, linearly interpolated; the first row before
/// the first frame).
Eigen::MatrixXd delayed(const Eigen::MatrixXd& x, double d) {
  const Eigen::Index n = x.rows();
  Eigen::MatrixXd out(n, x.cols());
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = std::max(0.0, static_cast<double>(i) - d);
    const auto a = std::min<Eigen::Index>(static_cast<Eigen::Index>(t), n - 1), b = std::min<Eigen::Index>(a + 1, n - 1);
    const double w = t - static_cast<double>(a);
    out.row(i) = (1 - w) * x.row(a) + w * x.row(b);
  }
  return out;
}

}  // namespace

MediolateralForces mediolateral_forces(const ModelMotion& motion, const std::array<Eigen::MatrixX3d, kLandmarkCount>& landmark_lab_m,
                                       const Eigen::MatrixX3d& lateral_axis, double cutoff_hz, const std::array<FootLoad, 2>& feet,
                                       double leg_cutoff_hz, bool own_leg_inertia, const UpperBodySegments* upper, double upper_body_lag_s,
                                       const std::vector<bool>* near_flight) {
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
  for (int s = 0; s < kSegmentCount; ++s)
    if (s != kTorso) com += first_moment(s) / mass;
  // The upper body: the HAT's COM with its share of the mass, less the parts of their own (arms,
  // head), each at its own COM.
  const Eigen::MatrixXd hat_com = first_moment(kTorso) / model.bodies[kTorso].mass_kg;
  const double trunk_share = hat_share(model, upper);
  if (upper)
    for (const auto& part : upper->parts) {
      if (part.com_m.rows() != n) throw InputError("mediolateral force: an upper-body segment does not match the motion's frames");
      com += part.mass_fraction * part.com_m;
    }
  const auto filtered = [&](Eigen::MatrixXd x) { return cutoff_hz > 0 ? butterworth_filtfilt(std::move(x), motion.rate_hz, cutoff_hz) : x; };
  const auto total_of = [&](const Eigen::MatrixXd& filtered_com) -> Eigen::VectorXd {
    return mass * lateral_part(second_difference(filtered_com, 1.0 / motion.rate_hz));
  };
  MediolateralForces out;
  const Eigen::MatrixXd but_trunk = std::move(com);  // every part of the COM but the trunk's share
  com = filtered(but_trunk + trunk_share * hat_com);
  out.total_N = total_of(com);
  out.com_lateral_m = lateral_part(com);
  if (upper_body_lag_s > 0) {
    // The trunk's share delayed (its acceleration a(t - tau)); near a flight phase as measured.
    const Eigen::VectorXd lagged = total_of(filtered(but_trunk + delayed(trunk_share * hat_com, upper_body_lag_s * motion.rate_hz)));
    for (Eigen::Index i = 0; i < n; ++i)
      if (!(near_flight && i < static_cast<Eigen::Index>(near_flight->size()) && (*near_flight)[static_cast<std::size_t>(i)])) out.total_N[i] = lagged[i];
  }
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

WholeBodyLateral whole_body_lateral(const Model& model, const std::vector<Eigen::MatrixX3d>& lab_sums, const UpperBodySegments* upper,
                                    const Eigen::MatrixX3d& lateral_axis, double rate_hz, double cutoff_hz) {
  const Eigen::Index n = lateral_axis.rows();
  if (lab_sums.size() != 2 || lab_sums[0].rows() != n || lab_sums[1].rows() != n)
    throw InputError("whole body's lateral balance: the landmarks' sums do not match the lateral axes' frames");
  Eigen::MatrixXd com = lab_sums[0] + hat_share(model, upper) * lab_sums[1];
  if (upper)
    for (const auto& part : upper->parts) {
      if (part.com_m.rows() != n) throw InputError("whole body's lateral balance: an upper-body segment does not match the frames");
      com += part.mass_fraction * part.com_m;
    }
  if (cutoff_hz > 0) com = butterworth_filtfilt(std::move(com), rate_hz, cutoff_hz);
  WholeBodyLateral out;
  out.com_lateral_m = (com.array() * lateral_axis.array()).rowwise().sum().matrix();
  out.total_N = model.body_mass_kg * (second_difference(com, 1.0 / rate_hz).array() * lateral_axis.array()).rowwise().sum().matrix();
  return out;
}

JointMoments3D least_squares_lateral_split(const JointMoments3D& zero, const JointMoments3D& unit, const std::vector<bool>& frames,
                                           std::array<Eigen::VectorXd, 2>& foot_N) {
  JointMoments3D out = zero;
  const auto n = static_cast<Eigen::Index>(frames.size());
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!frames[static_cast<std::size_t>(i)]) continue;
    std::array<double, 2> A{0.0, 0.0}, B{0.0, 0.0};
    for (std::size_t k = 0; k < 2; ++k)
      for (const auto member : {&JointMoments3D::ankle_lab_Nm, &JointMoments3D::knee_lab_Nm, &JointMoments3D::hip_lab_Nm}) {
        const Eigen::RowVector3d a = (zero.*member)[k].row(i), h = (unit.*member)[k].row(i) - a;
        A[k] += h.squaredNorm();
        B[k] += a.dot(h);
      }
    if (!(A[0] + A[1] > 0)) continue;
    const double T = foot_N[0][i] + foot_N[1][i];
    const double F0 = (A[1] * T + B[1] - B[0]) / (A[0] + A[1]);
    if (!std::isfinite(F0)) continue;  // a moment not finite at this frame: the split stays
    const std::array<double, 2> split{F0, T - F0};
    for (std::size_t k = 0; k < 2; ++k) {
      foot_N[k][i] = split[k];
      for (const auto member : {&JointMoments3D::ankle_Nm, &JointMoments3D::knee_Nm, &JointMoments3D::hip_Nm, &JointMoments3D::ankle_lab_Nm,
                                &JointMoments3D::knee_lab_Nm, &JointMoments3D::hip_lab_Nm})
        (out.*member)[k].row(i) = (zero.*member)[k].row(i) + split[k] * ((unit.*member)[k].row(i) - (zero.*member)[k].row(i));
    }
  }
  return out;
}

}  // namespace kin2grf
