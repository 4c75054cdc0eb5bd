// Structured solver: u = r + dP s with K^d r^d = rhs^d and K^d s^d = a^d (six SPD solves by
// PCG with IC(0), each warm-started), dP = (c - a.r) / (a.s). While the matrices are
// unchanged s is reused and only the three r solves run. The three axes are one system: each
// axis stops when its residual is below the tolerance times the norm of the whole right-hand
// side (all axes) over sqrt(3), so an axis that carries little load (x and y under a
// vertical probe) is not solved to a finer absolute accuracy than the others. (Warm starts
// extrapolated from the last two solutions were tried: with this ordering they saved one
// iteration in 50 and broke the 60 % cube's mirror symmetry test; not kept.)
// The solves run on a copy of K^d in reverse Cuthill-McKee order (engine/node_ordering).
#include <cmath>
#include <vector>

#include "engine/incomplete_cholesky.hpp"
#include "engine/krylov.hpp"
#include "engine/linear_solver.hpp"
#include "engine/node_ordering.hpp"
#include "engine/stiffness.hpp"

namespace vdm {
namespace {

class StructuredSolver final : public LinearSolver {
 public:
  explicit StructuredSolver(const SolverSettings& s) : settings_(s) {}

  void analyze(const SpMat& pattern) override {
    const int n = static_cast<int>(pattern.rows());
    // The solves run in reverse Cuthill-McKee order: entry (i, j) of the permuted matrix is
    // entry (perm_[i], perm_[j]) of K; src_ maps its values to K's.
    perm_ = reverse_cuthill_mckee(pattern);
    std::vector<int> iperm(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) iperm[perm_[i]] = i;
    std::vector<Eigen::Triplet<double, int>> entries;
    entries.reserve(static_cast<size_t>(pattern.nonZeros()));
    for (int j = 0; j < n; ++j)
      for (int k = pattern.outerIndexPtr()[j]; k < pattern.outerIndexPtr()[j + 1]; ++k)
        entries.emplace_back(iperm[pattern.innerIndexPtr()[k]], iperm[j], double(k));
    SpMat permuted(n, n);
    permuted.setFromTriplets(entries.begin(), entries.end());
    permuted.makeCompressed();
    src_.resize(static_cast<size_t>(permuted.nonZeros()));
    for (Eigen::Index k = 0; k < permuted.nonZeros(); ++k) src_[size_t(k)] = static_cast<int>(permuted.valuePtr()[k]);
    permuted.coeffs().setZero();
    for (int d = 0; d < 3; ++d) {
      Kp_[d] = permuted;
      ic_[d].analyze(Kp_[d]);
    }
    r_ = NodeMat::Zero(n, 3);
    s_ = NodeMat::Zero(n, 3);
    rp_ = NodeMat::Zero(n, 3);
    sp_ = NodeMat::Zero(n, 3);
    b_.resize(n);
    x_.resize(n);
    work_.resize(n);
  }

  const NodeMat& pressure_response(const std::array<SpMat, 3>&, const NodeMat& a) override {
    if (!s_valid_) {
      const double a_norm = a.norm();
      for (int d = 0; d < 3; ++d) solve_axis(d, a, a_norm, sp_, s_);
      s_valid_ = true;
    }
    return s_;
  }

  void matrices_changed(const std::array<SpMat, 3>& K) override {
    for (int d = 0; d < 3; ++d) {
      const double* src = K[d].valuePtr();
      double* dst = Kp_[d].valuePtr();
      for (size_t k = 0; k < src_.size(); ++k) dst[k] = src[src_[k]];
      ic_[d].factorize(Kp_[d]);
    }
    s_valid_ = false;
    pending_factorizations_ = 3;
  }

  void save_warm_state(std::vector<double>& out) const override {
    for (const NodeMat* x : {&r_, &s_, &rp_, &sp_}) put_warm(out, *x);
    out.push_back(s_valid_ ? 1.0 : 0.0);
    out.push_back(pending_factorizations_);
  }

  bool load_warm_state(const std::vector<double>& in) override {
    size_t pos = 0;
    for (NodeMat* x : {&r_, &s_, &rp_, &sp_})
      if (!take_warm(in, pos, *x)) return false;
    if (in.size() != pos + 2) return false;
    s_valid_ = in[pos] != 0.0;
    pending_factorizations_ = static_cast<int>(in[pos + 1]);
    return true;
  }

  // `K` is the one last given to matrices_changed(), of which Kp_ holds the permuted values.
  SolveReport solve(const std::array<SpMat, 3>&, const NodeMat& rhs, const NodeMat& a, double c,
                    bool volume_constraint, NodeMat& u, double& dP) override {
    SolveReport rep;
    rep.factorizations = pending_factorizations_;
    pending_factorizations_ = 0;
    auto count = [&rep](const KrylovResult& kr) {
      rep.iterations += kr.iterations;
      rep.converged = rep.converged && kr.converged;
    };
    const double rhs_norm = rhs.norm(), a_norm = a.norm();
    const bool new_s = volume_constraint && !s_valid_;
    for (int d = 0; d < 3; ++d) {
      count(solve_axis(d, rhs, rhs_norm, rp_, r_));
      if (new_s) count(solve_axis(d, a, a_norm, sp_, s_));
    }
    if (volume_constraint) s_valid_ = true;
    dP = volume_constraint ? pressure_for_volume(a, r_, s_, c) : 0.0;
    u.noalias() = r_ + dP * s_;
    return rep;
  }

 private:
  // K^d x = b.col(d) (original order) by PCG with IC(0) in the permuted order until
  // |b - K x| <= tolerance b_all / sqrt(3), warm-started from xp.col(d) (the last solution of
  // the same system, permuted). The result goes to xp.col(d) and, in node order, to out.col(d).
  KrylovResult solve_axis(int d, const NodeMat& b, double b_all, NodeMat& xp, NodeMat& out) {
    const SpMat& K = Kp_[d];
    const IncompleteCholesky& ic = ic_[d];
    auto op = [&K](const double* in, double* res) { symmetric_multiply(K, in, res); };
    auto pre = [&ic](const double* in, double* res) { ic.apply(in, res); };
    const int n = static_cast<int>(b_.size());
    for (int i = 0; i < n; ++i) b_[i] = b(perm_[i], d);
    if (!settings_.warm_start) x_.setZero();
    else x_ = xp.col(d);
    const double bd = b_.norm();
    // sqrt(3): the three axes together then meet the tolerance on the whole system.
    const double tol = bd > 0 ? settings_.tolerance * b_all / (bd * std::sqrt(3.0)) : settings_.tolerance;
    const KrylovResult kr = pcg(op, pre, b_, x_, tol, settings_.max_iterations, work_);
    xp.col(d) = x_;
    for (int i = 0; i < n; ++i) out(perm_[i], d) = x_[i];
    return kr;
  }

  SolverSettings settings_;
  std::vector<int> perm_;        // solver index -> node (reverse Cuthill-McKee)
  std::vector<int> src_;         // permuted value index -> index in K's values
  std::array<SpMat, 3> Kp_;      // permuted K^d
  IncompleteCholesky ic_[3];
  NodeMat r_, s_;                // node order
  NodeMat rp_, sp_;              // solver order: the last solutions (warm starts)
  Vec b_, x_;
  PcgWorkspace work_;
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
