#include "kin2grf/dynamics/inverse_dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace kin2grf {

double speed_gate_for(const SolverOptions& o, double v) {
  if (o.speed_gate_ratio <= 0) return std::max(0.0, o.speed_gate_mps);
  return std::max(o.speed_gate_floor_mps, o.speed_gate_ratio * std::abs(v));
}
namespace {

constexpr int kRigidRows = 40, kDefRows = 40, kRheoRows = 48;

}  // namespace

ContactSolver::ContactSolver(const Model& model, const SolverOptions& options)
    : model_(model), options_(options) {
  mass_ = model.mass_diagonal();
  gravity_ = model.gravity_force();
  weight_bilateral_ = Eigen::VectorXd::Ones(kBilateralCount);
  if (options_.norm == MultiplierNorm::TorqueScaled) {
    weight_bilateral_.head(kRigidRows).setZero();
    weight_bilateral_.segment(kDefRows, 16).setConstant(1.0 / options_.torque_length_m);
    weight_bilateral_.tail(4).setZero();
  }
  // The sparsity pattern does not depend on q: take it from a generic configuration (no
  // coordinate zero, so no structural entry vanishes) and order the columns once.
  Eigen::VectorXd generic(coord::kCount);
  for (int i = 0; i < coord::kCount; ++i) generic[i] = 0.37 + 0.113 * i;
  B_ = bilateral_jacobian(generic).transpose().sparseView();
  B_.makeCompressed();
  qr_.analyzePattern(B_);
}

Eigen::MatrixXd ContactSolver::bilateral_jacobian(const Eigen::VectorXd& q) const {
  Eigen::MatrixXd Phi(kBilateralCount, coord::kCount);
  fill_bilateral_jacobian(q, Phi);
  return Phi;
}

void ContactSolver::fill_bilateral_jacobian(const Eigen::VectorXd& q, Eigen::MatrixXd& Phi) const {
  Phi.setZero(kBilateralCount, coord::kCount);
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
    attach(c, Eigen::Vector2d(q[c], q[c + 1]), landmark(side, 1), segment(side, 2));
  }
}

FrameSolution ContactSolver::solve(const Eigen::VectorXd& q, const Eigen::VectorXd& qdd, const FrameContacts& fc) {
  fill_bilateral_jacobian(q, Phi_);  // reused buffer: no allocation per frame
  if (options_.dense_factorisation) return solve_dense(Phi_.transpose(), qdd, fc);
  // B = Phi^T: B(i, j) = Phi(j, i) on the fixed sparsity pattern.
  for (int c = 0; c < B_.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(B_, c); it; ++it) it.valueRef() = Phi_(it.col(), it.row());
  qr_.factorize(B_);
  if (qr_.info() != Eigen::Success || qr_.rank() < kBilateralCount) return solve_dense(Phi_.transpose(), qdd, fc);
  // Columns: b, then (normal, tangent) per contact point. One application of Q^T serves both
  // parts: B^+ X = P R^-1 (Q^T X)_top (B P = Q R, full column rank) and U^T X = (Q^T X)_bottom.
  const Eigen::MatrixXd X = contact_columns(qdd, fc);
  const Eigen::MatrixXd QtX = qr_.matrixQ().transpose() * X;
  const Eigen::MatrixXd Rinv_QtX = qr_.matrixR()
                                       .topLeftCorner(kBilateralCount, kBilateralCount)
                                       .template triangularView<Eigen::Upper>()
                                       .solve(QtX.topRows(kBilateralCount));
  const Eigen::MatrixXd BpX = qr_.colsPermutation() * Rinv_QtX;  // B^+ [b C]
  const Eigen::MatrixXd UtX = QtX.bottomRows(coord::kCount - kBilateralCount);  // U^T [b C]
  return solve_reduced(BpX, UtX, fc);
}

FrameSolution ContactSolver::solve_dense(const Eigen::MatrixXd& Bd, const Eigen::VectorXd& qdd, const FrameContacts& fc) {
  // Rank-revealing dense fallback (a degenerate geometry the sparse factorisation flags).
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Bd);
  const Eigen::MatrixXd X = contact_columns(qdd, fc);
  const Eigen::MatrixXd QtX = qr.householderQ().transpose() * X;
  const Eigen::MatrixXd BpX = Bd.completeOrthogonalDecomposition().solve(X);
  return solve_reduced(BpX, QtX.bottomRows(coord::kCount - qr.rank()), fc);
}

Eigen::MatrixXd ContactSolver::contact_columns(const Eigen::VectorXd& qdd, const FrameContacts& fc) const {
  const Eigen::VectorXd b = mass_.cwiseProduct(qdd) - gravity_;
  const int np = static_cast<int>(fc.points.size());
  Eigen::MatrixXd X(coord::kCount, 1 + 2 * np);
  X.col(0) = b;
  for (int j = 0; j < np; ++j) {
    X.col(1 + 2 * j) = fc.points[static_cast<std::size_t>(j)].jac_normal;
    X.col(2 + 2 * j) = fc.points[static_cast<std::size_t>(j)].jac_tangent;
  }
  return X;
}

FrameSolution ContactSolver::solve_reduced(const Eigen::MatrixXd& BpX, const Eigen::MatrixXd& UtX, const FrameContacts& fc) {
  const int np = static_cast<int>(fc.points.size());
  const int k = 2 * np;
  const Eigen::VectorXd& wB = weight_bilateral_;

  FrameSolution sol;
  sol.contact_lambda = Eigen::VectorXd::Zero(k);
  sol.contact_active.assign(static_cast<std::size_t>(np), true);
  // The speed gate removes a contact from the candidates before the iterations.
  std::vector<bool> allowed(static_cast<std::size_t>(np), true);
  if (options_.speed_gate_mps > 0) {
    for (int j = 0; j < np; ++j) {
      const auto& p = fc.points[static_cast<std::size_t>(j)];
      if (std::abs(p.velocity.x() - options_.belt_velocity_mps) > options_.speed_gate_mps) allowed[static_cast<std::size_t>(j)] = false;
    }
  }
  std::vector<bool> active = allowed;
  std::set<std::vector<bool>> seen;
  Eigen::VectorXd lamC = Eigen::VectorXd::Zero(k);
  for (int it = 0; it < options_.max_iterations; ++it) {
    seen.insert(active);
    sol.iterations = it + 1;
    std::vector<int> cols;
    for (int j = 0; j < np; ++j)
      if (active[static_cast<std::size_t>(j)]) { cols.push_back(2 * j); cols.push_back(2 * j + 1); }
    const int ka = static_cast<int>(cols.size());
    lamC.setZero();
    if (ka > 0) {
      Eigen::MatrixXd A3(UtX.rows(), ka), W(kBilateralCount, ka);
      for (int c = 0; c < ka; ++c) {
        A3.col(c) = UtX.col(1 + cols[static_cast<std::size_t>(c)]);
        W.col(c) = wB.cwiseProduct(BpX.col(1 + cols[static_cast<std::size_t>(c)]));
      }
      const Eigen::VectorXd b3 = UtX.col(0);
      const Eigen::VectorXd w = wB.cwiseProduct(BpX.col(0));
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(A3, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const auto& sv = svd.singularValues();
      // Singular values below 1e-8 of the largest count as zero: two contacts whose columns
      // differ only by round-off (feet at the same place) must not create a force couple.
      const double tol = 1e-8 * (sv.size() ? sv[0] : 0.0);
      int rank = 0;
      for (Eigen::Index i = 0; i < sv.size(); ++i)
        if (sv[i] > tol) ++rank;
      // Fit the first r singular directions exactly; the remaining freedom by the minimum norm.
      auto fit = [&](int r) {
        Eigen::VectorXd lam0 = Eigen::VectorXd::Zero(ka);
        for (int i = 0; i < r; ++i) lam0 += svd.matrixV().col(i) * (svd.matrixU().col(i).dot(b3) / sv[i]);
        if (r == ka) return lam0;
        const Eigen::MatrixXd N = svd.matrixV().rightCols(ka - r);
        Eigen::MatrixXd S(ka + kBilateralCount, ka - r);
        S << N, W * N;
        Eigen::VectorXd rhs(ka + kBilateralCount);
        rhs << -lam0, w - W * lam0;
        const Eigen::VectorXd z = S.completeOrthogonalDecomposition().solve(rhs);
        return Eigen::VectorXd(lam0 + N * z);
      };
      // Feet side by side: with all 3 global directions fitted, the weakest is the moment that
      // only a couple between the feet can make (its singular value shrinks with their distance
      // along x and height); fade it out of the fit. Feet exactly together already leave it out.
      double keep = 1.0;
      if (options_.min_split_distance_m > 0 && rank == UtX.rows()) {
        std::array<bool, 2> side_on{false, false};
        double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
        for (int j = 0; j < np; ++j) {
          if (!active[static_cast<std::size_t>(j)]) continue;
          const auto& p = fc.points[static_cast<std::size_t>(j)];
          side_on[static_cast<std::size_t>(p.side)] = true;
          xmin = std::min(xmin, p.position.x()), xmax = std::max(xmax, p.position.x());
        }
        if (side_on[0] && side_on[1]) {
          const double u = std::clamp(2.0 * (xmax - xmin) / options_.min_split_distance_m - 1.0, 0.0, 1.0);
          keep = u * u * (3.0 - 2.0 * u);  // smoothstep: 0 below half the distance, 1 above it
        }
      }
      Eigen::VectorXd lam = fit(rank);
      if (keep < 1.0) lam = keep * lam + (1.0 - keep) * fit(rank - 1);
      for (int c = 0; c < ka; ++c) lamC[cols[static_cast<std::size_t>(c)]] = lam[c];
    }
    // Re-classify (Eqs. 8-9).
    std::vector<bool> next(static_cast<std::size_t>(np));
    for (int j = 0; j < np; ++j) {
      const double crit = lamC[2 * j] - options_.r_N_per_m * fc.points[static_cast<std::size_t>(j)].gap_m;
      next[static_cast<std::size_t>(j)] = allowed[static_cast<std::size_t>(j)] && crit > 0;
    }
    if (next == active) break;
    if (seen.count(next)) {
      sol.cycled = true;
      break;
    }
    active = next;
    if (it + 1 == options_.max_iterations) sol.capped = true;
  }
  sol.contact_lambda = lamC;
  sol.contact_active = active;
  // Bilateral multipliers: lambda_B = B^+ (b - C lambda_C); the rheonomic ones are the torques.
  Eigen::VectorXd lamB = BpX.col(0);
  for (int c = 0; c < k; ++c)
    if (lamC[c] != 0.0) lamB -= BpX.col(1 + c) * lamC[c];
  sol.joint_torque_Nm = lamB.segment<kJointCount>(kRheoRows);
  for (int side = 0; side < 2; ++side) {
    double fx = 0, fy = 0;
    bool any = false;
    for (int j = 0; j < np; ++j) {
      const auto& p = fc.points[static_cast<std::size_t>(j)];
      if (p.side != side || !active[static_cast<std::size_t>(j)]) continue;
      any = true;
      fy += lamC[2 * j];
      fx += lamC[2 * j + 1];
    }
    sol.active[side] = any;
    sol.force_N[side] = Eigen::Vector2d(fx, fy);
  }
  return sol;
}

}  // namespace kin2grf
