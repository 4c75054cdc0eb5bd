// Reference solver (the paper's): the assembled 3N+1 system
//   [ K^x           -a^x ] [u^x]   [f^x]
//   [      K^y      -a^y ] [u^y] = [f^y]
//   [           K^z -a^z ] [u^z]   [f^z]
//   [ a^xT a^yT a^zT  0  ] [dP ]   [ c ]
// solved by BiCGSTAB, warm-started from the previous step. The pressure unknown and the
// volume row are scaled by `alpha` (a diagonal scaling: same solution, better conditioning),
// and the preconditioner is block-diagonal: IC(0) of each K^d and a Jacobi estimate of the
// pressure Schur complement.
#include <vector>

#include "engine/incomplete_cholesky.hpp"
#include "engine/krylov.hpp"
#include "engine/linear_solver.hpp"
#include "engine/stiffness.hpp"

namespace vdm {
namespace {

using RowSpMat = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

class ReferenceSolver final : public LinearSolver {
 public:
  explicit ReferenceSolver(const SolverSettings& s) : settings_(s) {}

  void analyze(const StiffnessPattern& stiffness_pattern) override {
    const SpMat& pattern = stiffness_pattern.matrix;
    n_ = static_cast<int>(pattern.rows());
    const int m = 3 * n_ + 1;
    std::vector<Eigen::Triplet<double, int>> trip;
    trip.reserve(3 * static_cast<size_t>(pattern.nonZeros()) + 6 * n_ + 1);
    for (int d = 0; d < 3; ++d)
      for (int j = 0; j < n_; ++j)
        for (SpMat::InnerIterator it(pattern, j); it; ++it)
          trip.emplace_back(d * n_ + static_cast<int>(it.row()), d * n_ + j, 0.0);
    for (int r = 0; r < 3 * n_; ++r) {
      trip.emplace_back(r, 3 * n_, 0.0);
      trip.emplace_back(3 * n_, r, 0.0);
    }
    trip.emplace_back(3 * n_, 3 * n_, 0.0);
    big_.resize(m, m);
    big_.setFromTriplets(trip.begin(), trip.end());
    big_.makeCompressed();
    for (auto& ic : ic_) ic.analyze(pattern);
    for (auto& k : K_masked_) k = pattern;
    y_ = Vec::Zero(m);
    b_.resize(m);
    s_ = NodeMat::Zero(n_, 3);
    sb_.resize(n_);
    sx_.resize(n_);
  }

  void matrices_changed(const AxisSystem& system) override {
    eliminate_constraints(system, K_masked_);
    mean_diagonal_ = eliminated_mean_diagonal(system);
    for (int d = 0; d < 3; ++d) ic_[d].factorize(K_masked_[d]);
    pending_factorizations_ = 3;
    dirty_ = true;
    s_valid_ = false;
  }

  // s from K^d s^d = a^d per axis (PCG with the IC(0) factors this solver already keeps):
  // accurate to the solver tolerance, which dividing an assembled solve by its pressure is not.
  const NodeMat& pressure_response(const NodeMat& a) override {
    if (s_valid_) return s_;
    for (int d = 0; d < 3; ++d) {
      const SpMat& Kd = K_masked_[d];
      const IncompleteCholesky& ic = ic_[d];
      auto op = [&Kd](const double* in, double* out) { symmetric_multiply(Kd, in, out); };
      auto pre = [&ic](const double* in, double* out) { ic.apply(in, out); };
      sb_ = a.col(d);
      sx_ = s_.col(d);
      pcg(op, pre, sb_, sx_, settings_.tolerance, settings_.max_iterations, pcg_work_);
      s_.col(d) = sx_;
    }
    s_valid_ = true;
    return s_;
  }

  // The BiCGSTAB warm start is the caller's u and dP; the pressure response warm-starts from s_.
  void save_warm_state(std::vector<double>& out) const override {
    put_response(out, s_, s_valid_, pending_factorizations_);
  }

  bool load_warm_state(const std::vector<double>& in) override {
    return take_response(in, s_, s_valid_, pending_factorizations_);
  }

  bool warm_starts_from_u() const override { return settings_.warm_start; }

  SolveReport solve(const NodeMat& rhs, const NodeMat& a, double c, bool volume_constraint, NodeMat& u,
                    double& dP) override {
    SolveReport rep;
    rep.factorizations = pending_factorizations_;
    pending_factorizations_ = 0;
    if (dirty_ || volume_constraint != last_volume_constraint_) {
      fill_matrix(K_masked_, a, volume_constraint);
      dirty_ = false;
      last_volume_constraint_ = volume_constraint;
    }
    // Right-hand side and warm start (previous u, dP).
    for (int d = 0; d < 3; ++d) b_.segment(d * n_, n_) = rhs.col(d);
    b_[3 * n_] = volume_constraint ? alpha_ * c : 0.0;
    if (settings_.warm_start) {
      for (int d = 0; d < 3; ++d) y_.segment(d * n_, n_) = u.col(d);
      y_[3 * n_] = volume_constraint ? dP / alpha_ : 0.0;
    } else {
      y_.setZero();
    }

    const KrylovResult kr =
        bicgstab(op(), pre(), b_, y_, settings_.tolerance, settings_.max_iterations, work_);
    rep.iterations = kr.iterations;
    rep.converged = kr.converged;
    for (int d = 0; d < 3; ++d) u.col(d) = y_.segment(d * n_, n_);
    dP = volume_constraint ? alpha_ * y_[3 * n_] : 0.0;
    return rep;
  }

 private:
  struct Multiply {
    const ReferenceSolver* self;
    void operator()(const double* in, double* out) const {
      Eigen::Map<const Vec> vin(in, self->big_.cols());
      Eigen::Map<Vec> vout(out, self->big_.rows());
      vout.noalias() = self->big_ * vin;
    }
  };
  struct Precondition {
    const ReferenceSolver* self;
    void operator()(const double* in, double* out) const {
      const int n = self->n_;
      for (int d = 0; d < 3; ++d) self->ic_[d].apply(in + d * n, out + d * n);
      out[3 * n] = in[3 * n] * self->inv_schur_;
    }
  };
  Multiply op() const { return {this}; }
  Precondition pre() const { return {this}; }

  void fill_matrix(const std::array<SpMat, 3>& K, const NodeMat& a, bool volume_constraint) {
    alpha_ = pressure_scale(mean_diagonal_, a);
    double* val = big_.valuePtr();
    const int* outer = big_.outerIndexPtr();
    double schur = 0.0;
    for (int d = 0; d < 3; ++d) {
      const int* kouter = K[d].outerIndexPtr();
      const int* kinner = K[d].innerIndexPtr();
      const double* kval = K[d].valuePtr();
      for (int i = 0; i < n_; ++i) {
        // Row d*n+i of the big matrix = column i of the symmetric K^d, then the pressure column.
        int slot = outer[d * n_ + i];
        double diag = 1.0;
        for (int k = kouter[i]; k < kouter[i + 1]; ++k) {
          val[slot++] = kval[k];
          if (kinner[k] == i) diag = kval[k];
        }
        const double ai = volume_constraint ? alpha_ * a(i, d) : 0.0;
        val[slot] = -ai;
        schur += ai * ai / diag;
      }
    }
    // Volume row: columns 0..3N-1 then the (3N, 3N) entry.
    int slot = outer[3 * n_];
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < n_; ++i) val[slot++] = volume_constraint ? alpha_ * a(i, d) : 0.0;
    val[slot] = volume_constraint ? 0.0 : 1.0;
    inv_schur_ = (volume_constraint && schur > 0) ? 1.0 / schur : 1.0;
  }

  SolverSettings settings_;
  int n_ = 0;
  std::array<SpMat, 3> K_masked_;  // the system's K with its constraints eliminated
  double mean_diagonal_ = 1.0;
  RowSpMat big_;
  IncompleteCholesky ic_[3];
  Vec y_, b_;
  NodeMat s_;
  Vec sb_, sx_;
  PcgWorkspace pcg_work_;
  bool s_valid_ = false;
  BicgstabWorkspace work_;
  double alpha_ = 1.0, inv_schur_ = 1.0;
  bool dirty_ = true, last_volume_constraint_ = true;
  int pending_factorizations_ = 0;
};

}  // namespace

std::unique_ptr<LinearSolver> make_reference_solver(const SolverSettings& s) {
  return std::make_unique<ReferenceSolver>(s);
}

std::unique_ptr<LinearSolver> make_structured_solver(const SolverSettings& s);
std::unique_ptr<LinearSolver> make_direct_solver(const SolverSettings& s);

std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& s) {
  switch (s.method) {
    case SolverMethod::reference: return make_reference_solver(s);
    case SolverMethod::structured: return make_structured_solver(s);
    case SolverMethod::direct: return make_direct_solver(s);
  }
  return make_structured_solver(s);
}

}  // namespace vdm
