#pragma once
// The three interchangeable solvers of the VDM system (vdm-model.md section 6). Each sees the
// per-axis matrices after constrained entries were eliminated (identity rows/columns).
#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "engine/settings.hpp"
#include "engine/sparse.hpp"
#include "engine/types.hpp"

namespace vdm {

struct SolveReport {
  int iterations = 0;
  bool converged = true;
  int factorizations = 0;
};

// The per-axis system a solver sees: K^d as assembled (unmasked: edge weights and diagonals,
// on the model's pattern), the constrained entries (mask(i, d) != 0: row and column i of K^d
// become the identity) and per-axis springs added to the free diagonal entries (null: none).
// Each solver eliminates the constraints its own way (the structured one while it copies K
// into its own layout).
struct AxisSystem {
  const AxisStiffness* K = nullptr;
  const StiffnessPattern* pattern = nullptr;
  const FlagMat* mask = nullptr;
  const NodeMat* springs = nullptr;
  // The first system of a step (not a step redone, not a later nonlinear iteration): the
  // change of its solution from the last step's first is a good guess of the next change.
  bool step_start = false;
};

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  // Once: the (shared) pattern of the per-axis matrices.
  virtual void analyze(const StiffnessPattern& pattern) = 0;
  // The matrices or the constrained set changed: refactor / rebuild preconditioners. A
  // solver keeps what it needs of `system` (it may not read the referenced arrays again).
  virtual void matrices_changed(const AxisSystem& system) = 0;
  // Solves  K^d u^d - dP a^d = rhs^d (d = x, y, z),  a . u = c, for the system last given to
  // matrices_changed(), where `a` is zero on constrained entries (whose rows are identities
  // carrying their prescribed values in rhs). Without the volume constraint dP = 0 and the
  // last row is dropped. `u` holds the previous solution on entry when warm_starts_from_u()
  // (the caller copies it there only then); otherwise it is only written.
  virtual SolveReport solve(const NodeMat& rhs, const NodeMat& a, double c, bool volume_constraint, NodeMat& u,
                            double& dP) = 0;
  // The relative residual the next solves stop at (the settings' tolerance until told
  // otherwise): a step's input may loosen it (StepInput::tolerance). Only the structured
  // solver takes it; the others ignore it (the direct solver is exact).
  virtual void set_tolerance(double /*tolerance*/) {}
  // Whether solve() reads `u` as its warm start (the others keep their own, or need none).
  virtual bool warm_starts_from_u() const { return false; }
  // `count` doubles of the solver's own scratch that nothing reads between its calls (the
  // caller may use them until it next calls the solver), or null when it has not that many.
  // Never allocates. The step's results pass works there (no array of its own: memory).
  virtual double* spare_doubles(size_t /*count*/) { return nullptr; }
  // s with K^d s^d = a^d on every axis (zero on constrained entries): the displacement per
  // unit of fluid pressure. Valid until the matrices change.
  virtual const NodeMat& pressure_response(const NodeMat& a) = 0;
  // What a solve carries over to the next (warm starts, the cached pressure response), for
  // state snapshots (engine/state_snapshot): appended to `out`, and read back (after
  // matrices_changed() with the same matrices) from `in`; false when `in` does not fit.
  virtual void save_warm_state(std::vector<double>& out) const = 0;
  virtual bool load_warm_state(const std::vector<double>& in) = 0;
};

std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& settings);

// Warm-state helpers: matrices and a flag and a count as doubles, in a fixed order.
inline void put_warm(std::vector<double>& out, const NodeMat& x) { out.insert(out.end(), x.data(), x.data() + x.size()); }
inline bool take_warm(const std::vector<double>& in, size_t& pos, NodeMat& x) {
  if (in.size() - pos < static_cast<size_t>(x.size())) return false;
  std::copy(in.begin() + static_cast<std::ptrdiff_t>(pos), in.begin() + static_cast<std::ptrdiff_t>(pos + x.size()), x.data());
  pos += static_cast<size_t>(x.size());
  return true;
}

// A solver's whole warm state when it is its cached pressure response s, whether s is valid,
// and the factorisations still pending (the direct and reference solvers).
inline void put_response(std::vector<double>& out, const NodeMat& s, bool valid, int pending) {
  put_warm(out, s);
  out.push_back(valid ? 1.0 : 0.0);
  out.push_back(pending);
}
inline bool take_response(const std::vector<double>& in, NodeMat& s, bool& valid, int& pending) {
  size_t pos = 0;
  if (!take_warm(in, pos, s) || in.size() != pos + 2) return false;
  valid = in[pos] != 0.0;
  pending = static_cast<int>(in[pos + 1]);
  return true;
}

// dP = (c - a.r) / (a.s): the pressure that makes u = r + dP s satisfy the volume row
// (0 when a.s is not positive: no node is free to move).
double pressure_for_volume(const NodeMat& a, const NodeMat& r, const NodeMat& s, double c);

// The mean diagonal entry of the eliminated matrices of `system` (identity rows: 1; free
// rows: K plus springs). With `a` and `a_free` (N x 3) also, in the same pass, a_free = a
// with the constrained entries zeroed (the step's free area vectors).
double eliminated_mean_diagonal(const AxisSystem& system, const NodeMat* a = nullptr, NodeMat* a_free = nullptr);

// The scale that makes the pressure column comparable with the stiffness blocks: the mean
// diagonal of the eliminated K over mean |a| (the reference solver's unknown is dP / scale).
double pressure_scale(double mean_diagonal, const NodeMat& a);

// K_masked[d] = K^d of `system` with its constrained rows and columns replaced by the
// identity and its springs on the free diagonal (K_masked carries the system's pattern;
// values written).
void eliminate_constraints(const AxisSystem& system, std::array<SpMat, 3>& K_masked);

}  // namespace vdm
