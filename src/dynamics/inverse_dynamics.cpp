#include "kin2grf/dynamics/inverse_dynamics.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <cstdint>
#include <stdexcept>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>

namespace kin2grf {

namespace {

/// The (x, y) pairs of q: the landmark points, the segments' COMs and D*. k-th pair's x column.
constexpr int kXyPairs = coord::kComs / 2 + kSegmentCount + 2;
constexpr int xy_coordinate(int k) {
  return k < coord::kComs / 2 ? coord::point_x(k)
         : k < coord::kComs / 2 + kSegmentCount ? coord::com_x(k - coord::kComs / 2)
                                               : coord::dstar_x(k - coord::kComs / 2 - kSegmentCount);
}

// The per-frame solve's fixed capacities: at most 6 contact points (12 multipliers).
constexpr int kMaxK = 2 * kMaxContactPoints;
using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxK, kMaxK>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxK, 1>;
using Tall = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxK + kBilateralCount, kMaxK>;
using TallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxK + kBilateralCount, 1>;
// 3 equations, or more in the dense fallback of a degenerate frame (63 - rank of B).
using Fit = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, coord::kCount, kMaxK>;

/// The frame's candidate points (bit j: point j): the speed gate (near a flight phase, the flight
/// gate) removes a point sliding faster than it along the ground (or belt) before the iterations,
/// and a foot still landing (landing_frames) takes no load yet.
unsigned candidate_points(const FrameContacts& fc, double speed_gate_mps, double flight_speed_gate_mps, double belt_velocity_mps) {
  if (fc.near_flight) speed_gate_mps = flight_speed_gate_mps;
  const int np = static_cast<int>(fc.points.size());
  unsigned allowed = (1U << np) - 1U;
  for (int j = 0; j < np; ++j) {
    const ContactPoint& p = fc.points[static_cast<std::size_t>(j)];
    if (speed_gate_mps > 0 && std::abs(p.velocity.x() - belt_velocity_mps) > speed_gate_mps) allowed &= ~(1U << j);
    if (fc.landing[static_cast<std::size_t>(p.side)]) allowed &= ~(1U << j);
  }
  return allowed;
}

/// The Alart-Curnier classification (Eqs. 8-9): a candidate point is active when
/// lambda_n - r g_n > 0.
unsigned activation(const SmallVector& lamC, const FrameContacts& fc, unsigned allowed, double r_N_per_m) {
  unsigned next = 0;
  const int np = static_cast<int>(fc.points.size());
  for (int j = 0; j < np; ++j) {
    const double crit = lamC[2 * j] - r_N_per_m * fc.points[static_cast<std::size_t>(j)].gap_m;
    if ((allowed >> j & 1U) && crit > 0) next |= 1U << j;
  }
  return next;
}

/// The bilateral multipliers lambda_B = B^+ (b - C lambda_C), whose rheonomic ones are the joint
/// torques, and the torques per unit normal and tangential multiplier of each point (the
/// double-support transition and the touchdown rule move the torques with the multipliers).
void bilateral_multipliers(const Eigen::Ref<const Eigen::MatrixXd>& BpX, const SmallVector& lamC, int np, FrameSolution& sol) {
  Eigen::Matrix<double, kBilateralCount, 1> lamB = BpX.col(0);
  for (int c = 0; c < 2 * np; ++c)
    if (lamC[c] != 0.0) lamB -= BpX.col(1 + c) * lamC[c];
  sol.joint_torque_Nm = lamB.segment<kJointCount>(row::kDriving);
  sol.torque_per_normal.resize(kJointCount, np);
  sol.torque_per_tangent.resize(kJointCount, np);
  for (int j = 0; j < np; ++j) {
    sol.torque_per_normal.col(j) = -BpX.block<kJointCount, 1>(row::kDriving, 1 + 2 * j);
    sol.torque_per_tangent.col(j) = -BpX.block<kJointCount, 1>(row::kDriving, 2 + 2 * j);
  }
}

/// The structure of N = Phi Phi^T's factor: an AMD order of N's pattern (`order`: constraint
/// row -> its place in the factor) and the fill of its elimination in that order.
using FillPattern = Eigen::Matrix<bool, kBilateralCount, kBilateralCount>;
FillPattern symbolic_factor(const Eigen::MatrixXd& Phi, std::array<int, kBilateralCount>& order) {
  const Eigen::MatrixXd Npattern = (Phi.cwiseAbs() * Phi.cwiseAbs().transpose()).unaryExpr([](double v) { return v != 0.0 ? 1.0 : 0.0; });
  Eigen::SparseMatrix<double> Nsparse = Npattern.sparseView();
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
  Eigen::AMDOrdering<int>()(Nsparse, perm);  // perm: new place -> old row (Eigen's P^-1)
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> inverse = perm.inverse();
  for (int r = 0; r < kBilateralCount; ++r) order[static_cast<std::size_t>(r)] = inverse.indices()[r];
  FillPattern fill;
  fill.setConstant(false);
  for (int a = 0; a < kBilateralCount; ++a)
    for (int b = 0; b < kBilateralCount; ++b)
      if (Npattern(a, b) != 0.0) fill(order[static_cast<std::size_t>(a)], order[static_cast<std::size_t>(b)]) = true;
  for (int k = 0; k < kBilateralCount; ++k)
    for (int i = k + 1; i < kBilateralCount; ++i)
      if (fill(i, k))
        for (int j = k + 1; j <= i; ++j)
          if (fill(j, k)) fill(i, j) = fill(j, i) = true;
  return fill;
}
}  // namespace

ContactSolver::ContactSolver(const Model& model, const TrialCalibration& calibration, const SolverOptions& options)
    : model_(model), options_(options), belt_velocity_mps_(calibration.belt_velocity_mps),
      speed_gate_mps_(calibration.speed_gate_mps), flight_speed_gate_mps_(calibration.flight_speed_gate_mps), Phi_(Eigen::MatrixXd::Zero(kBilateralCount, coord::kCount)) {
  mass_ = model.mass_diagonal();
  gravity_ = model.gravity_force();
  weight_bilateral_ = Eigen::VectorXd::Ones(kBilateralCount);
  if (options_.norm == MultiplierNorm::TorqueScaled) {
    weight_bilateral_.segment(row::kRigid, row::kRigidCount).setZero();
    weight_bilateral_.segment(row::kAngle, 2 * kJointCount).setConstant(1.0 / options_.torque_length_m);
    weight_bilateral_.segment(row::kDStar, row::kCount - row::kDStar).setZero();
  }
  // The sparsity pattern does not depend on q: take it from a generic configuration (no
  // coordinate zero, so no structural entry vanishes).
  Eigen::VectorXd generic(coord::kCount);
  for (int i = 0; i < coord::kCount; ++i) generic[i] = 0.37 + 0.113 * i;
  const Eigen::MatrixXd Phi = bilateral_jacobian(generic);
  std::vector<int> phi_column_start(coord::kCount + 1, 0);  // per coordinate: its entries in phi_entries_
  for (int c = 0; c < coord::kCount; ++c) {
    phi_column_start[static_cast<std::size_t>(c)] = static_cast<int>(phi_entries_.size());
    for (int r = 0; r < kBilateralCount; ++r)
      if (Phi(r, c) != 0.0) phi_entries_.push_back({r, c});
  }
  phi_column_start[coord::kCount] = static_cast<int>(phi_entries_.size());
  // N's pattern, an AMD order of it, and the factor's fill (symbolic elimination).
  const FillPattern fill = symbolic_factor(Phi, order_);
  // The factor's entries, row by row (k ascending): entry e of row i is L(i, factor_k_[e]).
  std::array<std::array<int, kBilateralCount>, kBilateralCount> entry{};
  for (auto& row : entry) row.fill(-1);
  factor_row_start_.assign(kBilateralCount + 1, 0);
  for (int i = 0; i < kBilateralCount; ++i) {
    factor_row_start_[static_cast<std::size_t>(i)] = static_cast<int>(factor_k_.size());
    for (int k = 0; k < i; ++k)
      if (fill(i, k)) {
        entry[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = static_cast<int>(factor_k_.size());
        factor_k_.push_back(k);
      }
  }
  factor_row_start_[kBilateralCount] = static_cast<int>(factor_k_.size());
  // The elimination as a schedule: for entry (i, k), the pairs (L(i, m), L(k, m)) with both
  // structurally non-zero, m < k; so the numeric factorisation multiplies no structural zero.
  update_start_.assign(factor_k_.size() + 1, 0);
  for (int i = 0; i < kBilateralCount; ++i)
    for (int e = factor_row_start_[static_cast<std::size_t>(i)]; e < factor_row_start_[static_cast<std::size_t>(i) + 1]; ++e) {
      update_start_[static_cast<std::size_t>(e)] = static_cast<int>(updates_.size());
      const int k = factor_k_[static_cast<std::size_t>(e)];
      for (int f = factor_row_start_[static_cast<std::size_t>(k)]; f < factor_row_start_[static_cast<std::size_t>(k) + 1]; ++f) {
        const int m = factor_k_[static_cast<std::size_t>(f)];
        const int g = entry[static_cast<std::size_t>(i)][static_cast<std::size_t>(m)];
        if (g >= 0) updates_.push_back({g, f, m});
      }
    }
  update_start_[factor_k_.size()] = static_cast<int>(updates_.size());
  // N = Phi Phi^T assembled from the products of Phi's entries that share a coordinate: each
  // product goes to a diagonal place (target < 0: -1 - row) or a factor entry.
  for (int c = 0; c < coord::kCount; ++c) {
    const int b0 = phi_column_start[static_cast<std::size_t>(c)], b1 = phi_column_start[static_cast<std::size_t>(c) + 1];
    for (int a = b0; a < b1; ++a)
      for (int b = b0; b <= a; ++b) {
        const int ia = order_[static_cast<std::size_t>(phi_entries_[static_cast<std::size_t>(a)][0])];
        const int ib = order_[static_cast<std::size_t>(phi_entries_[static_cast<std::size_t>(b)][0])];
        const int target = ia == ib ? -1 - ia : entry[static_cast<std::size_t>(std::max(ia, ib))][static_cast<std::size_t>(std::min(ia, ib))];
        products_.push_back({a, b, target});
      }
  }
  Lv_.assign(factor_k_.size(), 0.0);
  D_.setZero();
  phi_values_.assign(phi_entries_.size(), 0.0);
  // U's translation columns (the body moved along x, along y) do not depend on q: once here.
  U_.setZero();
  for (int k = 0; k < kXyPairs; ++k) U_(xy_coordinate(k), 0) = U_(xy_coordinate(k) + 1, 1) = 1.0;
  U_.col(0).normalize();
  U_.col(1).normalize();
}

bool ContactSolver::factorise_normal_equations() {
  for (std::size_t e = 0; e < phi_entries_.size(); ++e) phi_values_[e] = Phi_(phi_entries_[e][0], phi_entries_[e][1]);
  std::fill(Lv_.begin(), Lv_.end(), 0.0);
  D_.setZero();
  for (const auto& [a, b, target] : products_) {
    const double v = phi_values_[static_cast<std::size_t>(a)] * phi_values_[static_cast<std::size_t>(b)];
    if (target < 0) D_[-1 - target] += v;
    else Lv_[static_cast<std::size_t>(target)] += v;
  }
  // L D L^T, row by row (up-looking): L(i, k) = (N(i, k) - sum_m L(i, m) L(k, m) D(m)) / D(k),
  // D(i) = N(i, i) - sum_k L(i, k)^2 D(k).
  double largest = 0.0;
  for (int i = 0; i < kBilateralCount; ++i) {
    const int e0 = factor_row_start_[static_cast<std::size_t>(i)], e1 = factor_row_start_[static_cast<std::size_t>(i) + 1];
    double d = D_[i];
    for (int e = e0; e < e1; ++e) {
      double v = Lv_[static_cast<std::size_t>(e)];
      for (int u = update_start_[static_cast<std::size_t>(e)]; u < update_start_[static_cast<std::size_t>(e) + 1]; ++u) {
        const auto& [g, f, m] = updates_[static_cast<std::size_t>(u)];
        v -= Lv_[static_cast<std::size_t>(g)] * Lv_[static_cast<std::size_t>(f)] * D_[m];
      }
      const int k = factor_k_[static_cast<std::size_t>(e)];
      v /= D_[k];
      Lv_[static_cast<std::size_t>(e)] = v;
      d -= v * v * D_[k];
    }
    largest = std::max(largest, d);
    if (!(d > 1e-10 * largest)) return false;  // a vanishing pivot: degenerate geometry
    D_[i] = d;
  }
  return true;
}

Eigen::MatrixXd ContactSolver::bilateral_jacobian(const Eigen::VectorXd& q) const {
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Zero(kBilateralCount, coord::kCount);
  fill_bilateral_jacobian(q, Phi);
  return Phi;
}

void ContactSolver::fill_bilateral_jacobian(const FrameVector& q, Eigen::MatrixXd& Phi) const {
  // Every frame writes the same entries (the pattern is fixed), so Phi comes zeroed once by its
  // owner and only the entries are written: clearing 60 x 63 entries a frame was a fifth of the
  // solve.
  assert(Phi.rows() == kBilateralCount && Phi.cols() == coord::kCount);
  int row = 0;
  auto pt = [&](int k) { return Eigen::Vector2d(q[coord::point_x(k)], q[coord::point_x(k) + 1]); };
  auto attach = [&](int xcol, const Eigen::Vector2d& X, int P, int s) {
    const Eigen::Vector2d d = X - pt(P);  // = R(theta) rho
    Phi(row, xcol) = 1.0;
    Phi(row, coord::point_x(P)) = -1.0;
    Phi(row, coord::theta(s)) = d.y();
    ++row;
    Phi(row, xcol + 1) = 1.0;
    Phi(row, coord::point_x(P) + 1) = -1.0;
    Phi(row, coord::theta(s)) = -d.x();
    ++row;
  };
  for (int s = 0; s < kSegmentCount; ++s) {
    const Body& b = model_.bodies[s];
    for (int k = 0; k < 2; ++k)
      if (b.points[k] >= 0) attach(coord::point_x(b.points[k]), pt(b.points[k]), b.proximal, s);
    attach(coord::com_x(s), Eigen::Vector2d(q[coord::com_x(s)], q[coord::com_x(s) + 1]), b.proximal, s);
  }
  for (int j = 0; j < kJointCount; ++j, ++row) {
    Phi(row, coord::phi(j)) = 1.0;
    Phi(row, coord::theta(joint_child(j))) = -1.0;
    Phi(row, coord::theta(joint_parent(j))) = 1.0;
  }
  for (int j = 0; j < kJointCount; ++j, ++row) Phi(row, coord::phi(j)) = 1.0;
  for (int side = 0; side < 2; ++side) {
    const int c = coord::dstar_x(side);
    attach(c, Eigen::Vector2d(q[c], q[c + 1]), landmark(side, kAnkle), segment(side, kFoot));
  }
}

FrameSolution ContactSolver::solve(const FrameVector& q, const FrameVector& qdd, const FrameContacts& fc) {
  fill_bilateral_jacobian(q, Phi_);
  if (options_.dense_factorisation || !factorise_normal_equations()) return solve_dense(Phi_.transpose(), qdd, fc);
  // Columns: b, then (normal, tangent) per contact point.
  contact_columns(qdd, fc, X_);
  const Eigen::Index m = X_.cols();
  // B^+ X = N^-1 (Phi X), worked on Zt = (Phi X)^T in the factor's order (a row of Phi X is a
  // contiguous column of Zt): Phi X on Phi's entries, then L, D, L^T.
  Zt_.setZero(m, kBilateralCount);
  for (std::size_t e = 0; e < phi_entries_.size(); ++e)
    Zt_.col(order_[static_cast<std::size_t>(phi_entries_[e][0])]) += phi_values_[e] * X_.row(phi_entries_[e][1]).transpose();
  for (int i = 0; i < kBilateralCount; ++i)
    for (int e = factor_row_start_[static_cast<std::size_t>(i)]; e < factor_row_start_[static_cast<std::size_t>(i) + 1]; ++e)
      Zt_.col(i) -= Lv_[static_cast<std::size_t>(e)] * Zt_.col(factor_k_[static_cast<std::size_t>(e)]);
  for (int i = 0; i < kBilateralCount; ++i) Zt_.col(i) /= D_[i];
  for (int i = kBilateralCount - 1; i >= 0; --i)
    for (int e = factor_row_start_[static_cast<std::size_t>(i)]; e < factor_row_start_[static_cast<std::size_t>(i) + 1]; ++e)
      Zt_.col(factor_k_[static_cast<std::size_t>(e)]) -= Lv_[static_cast<std::size_t>(e)] * Zt_.col(i);
  BpX_.resize(kBilateralCount, m);
  for (int r = 0; r < kBilateralCount; ++r) BpX_.row(r) = Zt_.col(order_[static_cast<std::size_t>(r)]).transpose();
  // U's rotation column, the body turned about the origin: every (x, y) of q moves by (-y, x),
  // every absolute angle by 1, the relative angles not at all; orthonormal to the translations
  // (Gram-Schmidt, twice for round-off).
  auto turn = U_.col(2);
  turn.setZero();
  for (int k = 0; k < kXyPairs; ++k) {
    const int c = xy_coordinate(k);
    turn[c] = -q[c + 1];
    turn[c + 1] = q[c];
  }
  for (int s = 0; s < kSegmentCount; ++s) turn[coord::theta(s)] = 1.0;
  for (int pass = 0; pass < 2; ++pass)
    for (int b = 0; b < 2; ++b) turn -= U_.col(b).dot(turn) * U_.col(b);
  turn.normalize();
  UtX_.leftCols(m).noalias() = U_.transpose() * X_;
  return solve_reduced(BpX_, UtX_.leftCols(m), fc);
}

FrameSolution ContactSolver::solve_dense(const Eigen::MatrixXd& Bd, const FrameVector& qdd, const FrameContacts& fc) {
  // Rank-revealing dense fallback (a degenerate geometry the structured factorisation flags with a vanishing pivot).
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Bd);
  Columns X;
  contact_columns(qdd, fc, X);
  const Eigen::MatrixXd QtX = qr.householderQ().transpose() * X;
  const Eigen::MatrixXd BpX = Bd.completeOrthogonalDecomposition().solve(X);
  return solve_reduced(BpX, QtX.bottomRows(coord::kCount - qr.rank()), fc);
}

void ContactSolver::contact_columns(const FrameVector& qdd, const FrameContacts& fc, Columns& X) const {
  const int np = static_cast<int>(fc.points.size());
  if (np > kMaxContactPoints) throw std::logic_error("more contact points than kMaxContactPoints");
  X.resize(coord::kCount, 1 + 2 * np);
  X.col(0) = mass_.cwiseProduct(qdd) - gravity_;
  for (int j = 0; j < np; ++j) {
    const ContactPoint& p = fc.points[static_cast<std::size_t>(j)];
    X.col(1 + 2 * j).setZero();
    X.col(2 + 2 * j).setZero();
    for (int e = 0; e < p.jac_normal.entries; ++e)
      X(p.jac_normal.coordinate[static_cast<std::size_t>(e)], 1 + 2 * j) = p.jac_normal.value[static_cast<std::size_t>(e)];
    for (int e = 0; e < p.jac_tangent.entries; ++e)
      X(p.jac_tangent.coordinate[static_cast<std::size_t>(e)], 2 + 2 * j) = p.jac_tangent.value[static_cast<std::size_t>(e)];
  }
}

double ContactSolver::moment_direction_weight(const FrameContacts& fc, unsigned active) const {
  if (!(options_.min_split_distance_m > 0)) return 1.0;
  std::array<bool, 2> side_on{false, false};
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
  for (std::size_t j = 0; j < fc.points.size(); ++j) {
    if (!(active >> j & 1U)) continue;
    const auto& p = fc.points[j];
    side_on[static_cast<std::size_t>(p.side)] = true;
    xmin = std::min(xmin, p.position.x()), xmax = std::max(xmax, p.position.x());
  }
  if (!(side_on[0] && side_on[1])) return 1.0;
  return side_by_side_sagittal_weight(xmax - xmin, options_.min_split_distance_m);
}

FrameSolution ContactSolver::solve_reduced(const Eigen::Ref<const Eigen::MatrixXd>& BpX, const Eigen::Ref<const Eigen::MatrixXd>& UtX,
                                           const FrameContacts& fc) {
  // Fixed capacities (SmallVector etc., above): nothing here touches the heap. Active sets are
  // bit masks (a point j is bit j).
  const int np = static_cast<int>(fc.points.size());
  const int k = 2 * np;
  const Eigen::VectorXd& wB = weight_bilateral_;
  const int neq = static_cast<int>(UtX.rows());

  FrameSolution sol;
  sol.contact_lambda = SmallVector::Zero(k);
  const unsigned allowed = candidate_points(fc, speed_gate_mps_, flight_speed_gate_mps_, belt_velocity_mps_);
  unsigned active = allowed;
  std::uint64_t seen = 0;  // the active sets tried (2^6 of them at most)
  SmallVector lamC = SmallVector::Zero(k);
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, coord::kCount, 1> b3 = UtX.col(0);
  const Eigen::Matrix<double, kBilateralCount, 1> w = wB.cwiseProduct(BpX.col(0));
  for (int it = 0; it < options_.max_iterations; ++it) {
    seen |= std::uint64_t{1} << active;
    sol.iterations = it + 1;
    std::array<int, kMaxK> cols{};
    int ka = 0;
    for (int j = 0; j < np; ++j)
      if (active >> j & 1U) cols[static_cast<std::size_t>(ka++)] = 2 * j, cols[static_cast<std::size_t>(ka++)] = 2 * j + 1;
    lamC.setZero();
    if (ka > 0) {
      Fit A3(neq, ka);
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kBilateralCount, kMaxK> W(kBilateralCount, ka);
      for (int c = 0; c < ka; ++c) {
        A3.col(c) = UtX.col(1 + cols[static_cast<std::size_t>(c)]);
        W.col(c) = wB.cwiseProduct(BpX.col(1 + cols[static_cast<std::size_t>(c)]));
      }
      const Eigen::JacobiSVD<Fit> svd(A3, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const auto& sv = svd.singularValues();
      // Singular values below 1e-8 of the largest count as zero: two contacts whose columns
      // differ only by round-off (feet at the same place) must not create a force couple.
      const double tol = 1e-8 * (sv.size() ? sv[0] : 0.0);
      int rank = 0;
      for (Eigen::Index i = 0; i < sv.size(); ++i)
        if (sv[i] > tol) ++rank;
      // Fit the first r singular directions exactly; the remaining freedom by the minimum norm.
      auto fit = [&](int r) {
        SmallVector lam0 = SmallVector::Zero(ka);
        for (int i = 0; i < r; ++i) lam0 += svd.matrixV().col(i) * (svd.matrixU().col(i).dot(b3) / sv[i]);
        if (r == ka) return lam0;
        const Small N = svd.matrixV().rightCols(ka - r);
        Tall S(ka + kBilateralCount, ka - r);
        S << N, W * N;
        TallVector rhs(ka + kBilateralCount);
        rhs << -lam0, w - W * lam0;
        const SmallVector z = Eigen::CompleteOrthogonalDecomposition<Tall>(S).solve(rhs);
        return SmallVector(lam0 + N * z);
      };
      // Feet side by side: with all 3 global directions fitted, the weakest is the moment that
      // only a couple between the feet can make (its singular value shrinks with their distance
      // along x and height); fade it out of the fit. Feet exactly together already leave it out.
      const double keep = rank == neq ? moment_direction_weight(fc, active) : 1.0;
      SmallVector lam = fit(rank);
      if (keep < 1.0) lam = keep * lam + (1.0 - keep) * fit(rank - 1);
      for (int c = 0; c < ka; ++c) lamC[cols[static_cast<std::size_t>(c)]] = lam[c];
    }
    const unsigned next = activation(lamC, fc, allowed, options_.r_N_per_m);  // Eqs. 8-9
    if (next == active) break;
    if (seen >> next & 1U) {
      sol.cycled = true;
      break;
    }
    active = next;
    if (it + 1 == options_.max_iterations) sol.capped = true;
  }
  sol.contact_lambda = lamC;
  for (int j = 0; j < np; ++j) sol.contact_active[static_cast<std::size_t>(j)] = (active >> j & 1U) != 0;
  bilateral_multipliers(BpX, lamC, np, sol);
  return sol;
}

}  // namespace kin2grf
