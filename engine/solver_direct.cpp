// Direct solver: per-axis sparse LDL^T (AMD ordering and symbolic analysis once), refactorised
// only when the matrices change; the pressure solves s are reused until then.
#include <cmath>

#include "engine/linear_solver.hpp"
#include "engine/sparse_ldlt.hpp"

namespace vdm {
namespace {

class DirectSolver final : public LinearSolver {
 public:
  explicit DirectSolver(const SolverSettings& s) : settings_(s) {}

  void analyze(const StiffnessPattern& pattern) override {
    for (auto& f : ldlt_) f.analyze(pattern.matrix);
    for (auto& k : K_masked_) k = pattern.matrix;
    r_ = NodeMat::Zero(pattern.matrix.rows(), 3);
    s_ = NodeMat::Zero(pattern.matrix.rows(), 3);
  }

  void matrices_changed(const AxisSystem& system) override {
    eliminate_constraints(system, K_masked_);
    factor_ok_ = true;
    for (int d = 0; d < 3; ++d) factor_ok_ = ldlt_[d].factorize(K_masked_[d]) && factor_ok_;
    s_valid_ = false;
    pending_factorizations_ = 3;
  }

  const NodeMat& pressure_response(const NodeMat& a) override {
    if (!s_valid_) {
      for (int d = 0; d < 3; ++d) ldlt_[d].solve(a.col(d).data(), s_.col(d).data());
      s_valid_ = true;
    }
    return s_;
  }

  // No warm starts; the cached s_ (the same bits when solved again) is kept anyway.
  void save_warm_state(std::vector<double>& out) const override {
    put_response(out, s_, s_valid_, pending_factorizations_);
  }

  bool load_warm_state(const std::vector<double>& in) override {
    return take_response(in, s_, s_valid_, pending_factorizations_);
  }

  SolveReport solve(const NodeMat& rhs, const NodeMat& a, double c, bool volume_constraint, NodeMat& u,
                    double& dP) override {
    SolveReport rep;
    rep.factorizations = pending_factorizations_;
    pending_factorizations_ = 0;
    rep.converged = factor_ok_;
    for (int d = 0; d < 3; ++d) ldlt_[d].solve(rhs.col(d).data(), r_.col(d).data());
    dP = volume_constraint ? pressure_for_volume(a, r_, pressure_response(a), c) : 0.0;
    u.noalias() = r_ + dP * s_;
    if (!u.allFinite()) rep.converged = false;
    return rep;
  }

 private:
  SolverSettings settings_;
  std::array<SpMat, 3> K_masked_;  // the system's K with its constraints eliminated
  SparseLdlt ldlt_[3];
  NodeMat r_, s_;
  bool s_valid_ = false, factor_ok_ = true;
  int pending_factorizations_ = 0;
};

}  // namespace

std::unique_ptr<LinearSolver> make_direct_solver(const SolverSettings& s) {
  return std::make_unique<DirectSolver>(s);
}

}  // namespace vdm
