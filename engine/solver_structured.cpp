// Structured solver: u = r + dP s with K^d r^d = rhs^d and K^d s^d = a^d (six SPD solves by
// PCG with IC(0), each warm-started), dP = (c - a.r) / (a.s). While the matrices are
// unchanged s is reused and only the three r solves run.
// Warm starts extrapolate the last two solutions of each system linearly (2 x_n - x_{n-1}):
// under a steadily moving instrument that guess is much closer than x_n alone. The three
// axes are one system: each axis stops when its residual is below the tolerance times the
// norm of the whole right-hand side (all axes), so an axis that carries little load (x and
// y under a vertical probe) is not solved to a finer absolute accuracy than the others.
#include <cmath>

#include "engine/incomplete_cholesky.hpp"
#include "engine/krylov.hpp"
#include "engine/linear_solver.hpp"
#include "engine/stiffness.hpp"

namespace vdm {
namespace {

class StructuredSolver final : public LinearSolver {
 public:
  explicit StructuredSolver(const SolverSettings& s) : settings_(s) {}

  void analyze(const SpMat& pattern) override {
    const Eigen::Index n = pattern.rows();
    for (auto& ic : ic_) ic.analyze(pattern);
    r_ = NodeMat::Zero(n, 3);
    s_ = NodeMat::Zero(n, 3);
    r_prev_ = NodeMat::Zero(n, 3);
    s_prev_ = NodeMat::Zero(n, 3);
    r_solves_ = s_solves_ = 0;
    b_.resize(n);
    x_.resize(n);
    work_.resize(n);
  }

  const NodeMat& pressure_response(const std::array<SpMat, 3>& K, const NodeMat& a) override {
    if (!s_valid_) {
      const double a_norm = a.norm();
      for (int d = 0; d < 3; ++d) solve_axis(K[d], d, a, s_, a_norm, s_prev_, s_solves_);
      ++s_solves_;
      s_valid_ = true;
    }
    return s_;
  }

  void matrices_changed(const std::array<SpMat, 3>& K) override {
    for (int d = 0; d < 3; ++d) ic_[d].factorize(K[d]);
    s_valid_ = false;
    pending_factorizations_ = 3;
  }

  SolveReport solve(const std::array<SpMat, 3>& K, const NodeMat& rhs, const NodeMat& a, double c,
                    bool volume_constraint, NodeMat& u, double& dP) override {
    SolveReport rep;
    rep.factorizations = pending_factorizations_;
    pending_factorizations_ = 0;
    auto count = [&rep](const KrylovResult& kr) {
      rep.iterations += kr.iterations;
      rep.converged = rep.converged && kr.converged;
    };
    const double rhs_norm = rhs.norm(), a_norm = a.norm();
    for (int d = 0; d < 3; ++d) {
      count(solve_axis(K[d], d, rhs, r_, rhs_norm, r_prev_, r_solves_));
      if (volume_constraint && !s_valid_) count(solve_axis(K[d], d, a, s_, a_norm, s_prev_, s_solves_));
    }
    ++r_solves_;
    if (volume_constraint && !s_valid_) ++s_solves_;
    if (volume_constraint) s_valid_ = true;
    dP = volume_constraint ? pressure_for_volume(a, r_, s_, c) : 0.0;
    u.noalias() = r_ + dP * s_;
    return rep;
  }

 private:
  // K x = b.col(d) by PCG with IC(0) until |b - K x| <= tolerance b_all / sqrt(3), warm-started from
  // out.col(d) (the last solution of the same system), extrapolated with prev.col(d) (the one
  // before) once `history` >= 2 solves were made; the result goes back to out.col(d).
  KrylovResult solve_axis(const SpMat& K, int d, const NodeMat& b, NodeMat& out, double b_all, NodeMat& prev,
                          int history) {
    const IncompleteCholesky& ic = ic_[d];
    auto op = [&K](const double* in, double* res) { symmetric_multiply(K, in, res); };
    auto pre = [&ic](const double* in, double* res) { ic.apply(in, res); };
    b_ = b.col(d);
    if (!settings_.warm_start) x_.setZero();
    else if (history >= 2) x_ = 2.0 * out.col(d) - prev.col(d);
    else x_ = out.col(d);
    prev.col(d) = out.col(d);
    const double bd = b_.norm();
    // sqrt(3): the three axes together then meet the tolerance on the whole system.
    const double tol = bd > 0 ? settings_.tolerance * b_all / (bd * std::sqrt(3.0)) : settings_.tolerance;
    const KrylovResult kr = pcg(op, pre, b_, x_, tol, settings_.max_iterations, work_);
    out.col(d) = x_;
    return kr;
  }

  SolverSettings settings_;
  IncompleteCholesky ic_[3];
  NodeMat r_, s_;
  Vec b_, x_;
  PcgWorkspace work_;
  NodeMat r_prev_, s_prev_;  // the solutions before the last (linear extrapolation of warm starts)
  int r_solves_ = 0, s_solves_ = 0;
  bool s_valid_ = false;
  int pending_factorizations_ = 0;
};

}  // namespace

std::unique_ptr<LinearSolver> make_structured_solver(const SolverSettings& s) {
  return std::make_unique<StructuredSolver>(s);
}

double pressure_for_volume(const NodeMat& a, const NodeMat& r, const NodeMat& s, double c) {
  double as = 0.0, ar = 0.0;
  for (int d = 0; d < 3; ++d) {
    as += a.col(d).dot(s.col(d));
    ar += a.col(d).dot(r.col(d));
  }
  // a.s > 0 whenever some node can move; otherwise the fluid has nothing to push.
  return (as > 0.0 && std::isfinite(as)) ? (c - ar) / as : 0.0;
}

double pressure_scale(const std::array<SpMat, 3>& K, const NodeMat& a) {
  double diag = 0.0;
  long count = 0;
  for (int d = 0; d < 3; ++d) {
    diag += K[d].diagonal().cwiseAbs().sum();
    count += K[d].rows();
  }
  const double mean_a = a.cwiseAbs().sum() / std::max<double>(1.0, double(a.size()));
  if (!(mean_a > 0) || !(diag > 0)) return 1.0;
  return (diag / count) / mean_a;
}

}  // namespace vdm
