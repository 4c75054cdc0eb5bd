#pragma once
// Forces on the surface that depend on where the surface is (constraint contact), found inside
// an organ model's own nonlinear iteration instead of around whole solves.
//
// A model that can (OrganSolver::trial_step_with) calls the law after each linear solve of its
// iteration with the surface's positions that solve found; the law sets its forces so that it
// holds on the model's linear response at that linearisation (the compliance the model gives),
// and the model solves the linear system again with them. At the model's fixed point the law
// then holds on the organ's exact equilibrium, at the cost of one nonlinear solve.
#include <vector>

#include "engine/sparse.hpp"

namespace vdm {

// The model's compliance at its current linearisation.
class ComplianceSource {
 public:
  virtual ~ComplianceSource() = default;
  // 3n x 3n at surface nodes `nodes` (row 3a + d, column 3b + e: how far node a moves along d
  // under a unit force on node b along e), with what the model holds (fixed, prescribed) held.
  virtual void compliance(const std::vector<int>& nodes, Eigen::MatrixXd& C) = 0;
};

class SurfaceForceLaw {
 public:
  virtual ~SurfaceForceLaw() = default;
  // `x`: the surface's positions (N x 3) solved under `force`, the surface's external forces
  // (N x 3, the law's own share included). Replaces the law's share in `force` by the forces
  // the law asks for; returns whether it changed them.
  virtual bool update(const NodeMat& x, ComplianceSource& compliance, NodeMat& force) = 0;
  // Whether the law's forces are those of constraints on the surface's positions alone (no
  // friction): the model's iteration then minimises one energy on the constrained set, and
  // needs no guard against forces that are no potential's (elastic_core: the mixing's safeguard).
  virtual bool conservative() const { return false; }
};

}  // namespace vdm
