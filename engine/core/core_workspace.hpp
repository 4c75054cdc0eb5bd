#pragma once
// The elastic core's step workspace (engine/core/core_step.cpp, held_entries.cpp): the
// factorised lattice matrices, the columns of their inverses that constraints need, the
// entries held by multipliers, and the last linearisation. Internal to engine/core.
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#ifdef VDMSIM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include <vector>

#include "engine/core/elastic_core.hpp"
#include "engine/surface_force_law.hpp"

namespace vdm::core {

// Columns of K_d^-1 at lattice nodes (the lattice's response to a unit force there), solved
// on demand and kept until axis d is factorised again.
struct LatticeColumns {
  std::vector<int> slot;  // per lattice node: its column, or -1
  std::vector<int> node;  // per column: its lattice node
  // Per multi-column solve that made them, in order: how many columns it added. A state
  // snapshot solves them again in the same groups (a column's last bits depend on the group
  // it was solved in), so that a loaded state's columns are the run's.
  std::vector<int> batch;
  Eigen::MatrixXd cols;   // ng x capacity
  int count = 0;
  void clear();
};

// Prescribed surface entries that the factorisation does not hold (a contact's or a grasp's
// nodes): held by multipliers r, the forces that put them on their targets, found on the
// small compliance matrix of the held entries through the factor the core already has.
struct HeldEntries {
  std::vector<int> node, axis;  // per entry, ordered by node then axis
  Eigen::MatrixXd C0;           // the entries' compliance without the volume row
  Eigen::LDLT<Eigen::MatrixXd> C0_factor;
  bool factored = false;        // C0_factor is of these entries and the current factors
  Vec rhs, h, z, y, r;          // per entry: target - free motion, volume response, solves, multipliers
  int size() const { return static_cast<int>(node.size()); }
};

struct CoreWorkspace {
  SpMat K[3];
#ifdef VDMSIM_HAVE_CHOLMOD
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> chol[3];
#else
  Eigen::SimplicialLDLT<SpMat> chol[3];
#endif
  FlagMat factored_mask;      // per axis, the prescribed entries its factor holds
  bool factored[3] = {false, false, false};  // factored_mask.col(d) has a factor
  // Axes whose factored entries are the same share one factor (the common case: the organ's
  // fixed entries on every axis): axis d's is chol[slot[d]], with its columns columns[slot[d]].
  int slot[3] = {0, 1, 2};
  FlagMat chol_mask;          // per factor, the entries it was made for
  bool chol_ok[3] = {false, false, false};
  bool analyzed = false;
  double reg = 0;             // the share of K_core's largest diagonal entry on every factor's diagonal (1e-10)
  LatticeColumns columns[3];
  HeldEntries held;
  std::vector<Eigen::Matrix3d> rotation;
  std::vector<Eigen::Quaterniond> quaternion;  // per tet, the last rotations (warm start)
  NodeMat area, force, target, x;
  NodeMat force_before;      // the forces before a SurfaceForceLaw's update
  std::vector<int> changed;  // the nodes whose forces it changed
  std::vector<char> changed_in_step;  // per surface node: its force changed within this step (forces_changed)
  // Per lattice node: it ties a surface node whose force changed within the step (tied_to_changed),
  // or is a corner of a cube that has such a node (near_changed): iteration_converged's buffers.
  std::vector<char> tied_to_changed, near_changed;
  std::vector<double> column_weight;  // per column of an axis: its weight in a force change (zero between uses)
  std::vector<int> column_used;       // the columns with a weight
  FlagMat mask;               // every prescribed entry (the factor's and the held ones)
  NodeMat b;              // per axis, the lattice's load
  NodeMat a;              // per axis, the volume row's lattice entries: sum over free entries A_i W_i^T
  NodeMat rotation_load;  // per axis, the lagged rotations' load on the lattice
  NodeMat inertia_load;   // per axis, M (rate v_start + velocity_start / dt): implicit Euler's (with inertia)
  NodeMat v_new, u_new;
  NodeMat residual, elastic;  // per axis, the lattice's force imbalance and elastic forces (convergence)
  NodeMat tied_v, tied_load;  // per surface node: the lattice's motion there (W v), a load to spread (W^T L)
  NodeMat tied_s;             // W v at the iterate s.v (the safeguard's merit reads it; tied_v: at v_new)
  // Anderson mixing of the lattice's displacements: differences of iterates and of residuals.
  Eigen::MatrixXd dX, dG;
  NodeMat response;    // per axis K_d^-1 a0_d, a0 = a at the step's first iteration
  NodeMat response_a;  // a0
  double response_lag = 0;  // the multiplier the load's share -lambda (a - a0) is taken with
  Eigen::MatrixXd two_rhs, two_out;  // two loads solved at once (solve_axes) and their answers
  double den = 0;  // the volume row's a^T K^-1 a + sum A^2 / k, at the last iteration
  Vec x_prev, g_prev, g, mixed;
  int history = 0, next = 0;
  // The step's iteration between its parts (begin_step ... end_step, core_step.cpp).
  struct Iteration {
    SurfaceForceLaw* law = nullptr;
    int it = -1;                 // the iteration in progress
    double lambda = 0, c = 0;    // the volume row's multiplier and residual at its linearisation
    double tol = 0, core_energy = 0;
    double g_norm_prev = 0, g_norms[4] = {0, 0, 0, 0}, g_norm = 0, change = 0;
    double g_norm_least = 0;
    int it_least = 0;
    bool safeguard = false, mixed = false, done = false;
    // The law's forces are judged again at the solved state by the step's caller (step(): a
    // single organ's contact, which solves again where they do not keep the laws), so the
    // force balance may leave out the cubes that carry them (iteration_converged).
    bool law_judged_after = false;
    double merit_last = 0, rhs_last = 0;
  } iter;
};

// Builds factor slot k's matrix, K_core with the ties of the entries w.chol_mask.col(k) holds
// (and the regularisation and inertia's mass), and factorises it: w.K[k], w.chol[k],
// w.chol_ok[k] (the symbolic analysis once, for every slot). The slot's columns and the held
// entries' factor are then out of date and dropped. The same mask gives the same bits: a
// state snapshot rebuilds its factors with it.
void factorize_slot(const CoreModel& m, int k, CoreWorkspace& w);

// Solves K_d out.col(d) = rhs.col(d) on every axis: one solve of three columns when the axes
// share a factor.
void solve_axes(CoreWorkspace& w, const NodeMat& rhs, NodeMat& out);
// Both loads' answers, in one solve per factor.
void solve_axes(CoreWorkspace& w, const NodeMat& rhs1, NodeMat& out1, const NodeMat& rhs2, NodeMat& out2);

// The lattice's motion at surface node i's rest position for a lattice field `v` (one axis).
template <class V>
double tied_at(const CoreModel& m, const V& v, int i) {
  double wv = 0;
  for (int p = 0; p < 4; ++p) wv += m.tie_weight(i, p) * v[m.tie_node(i, p)];
  return wv;
}

// Makes sure columns of K_d^-1 are solved for every lattice node that surface nodes `nodes`
// are tied to (one multi-column solve for those missing).
void ensure_columns(const CoreModel& m, int d, const std::vector<int>& nodes, CoreWorkspace& w);

// Solves the columns of factor slot k from column `before` to its count (the lattice nodes
// added to its node list since), in one multi-column solve, and notes the batch.
void solve_columns(const CoreModel& m, int k, int before, CoreWorkspace& w);

// (K_d^-1) between the lattice motions at surface nodes i and j (W_i K_d^-1 W_j^T), from the
// columns ensure_columns() made.
double tied_compliance(const CoreModel& m, const LatticeColumns& c, int i, int j);

// The held entries of this step: the prescribed entries (w.mask) that the factor does not
// hold (w.factored_mask); their C0 factorised again when they or the factors changed.
// False when C0 could not be factorised.
bool prepare_held_entries(const CoreModel& m, CoreWorkspace& w);

// Factorises the held entries' H.C0 (H.factored: it is positive definite) and sizes their
// per-entry vectors (the multipliers zero). A state snapshot calls it on the saved C0.
bool factor_held_entries(HeldEntries& H);

// Adds r_p (W_p^T, through K_d^-1) to the lattice's motion `v` for every held entry on axis d.
void add_held_response(const CoreModel& m, const CoreWorkspace& w, int d, Eigen::Ref<Vec> v);

// The compliance at surface nodes (3n x 3n, row 3a + d, column 3b + e) at the last
// iteration's linearisation: the organ with its volume row, the factor's entries fixed and the
// held entries held (their rows and columns 0).
void surface_compliance(const CoreModel& m, CoreWorkspace& w, const std::vector<int>& nodes, Eigen::MatrixXd& C);

}  // namespace vdm::core
