#pragma once
// VDM's surface on an elastic core (docs/model.md, "The elastic core"). The organ keeps its
// surface and the one pressure that keeps its enclosed volume; in place of VDM's bulk term,
// which ties every node to its rest position, the surface is tied to a coarse lattice laid
// over the organ's inside:
//
//   E = sum_c mu f_c sum_{t in c} V_t |F_t - R_t|^2            the core (as rigid as possible)
//     + sum_i 1/2 kappa |A_i| |u_i - (W v)_i|^2                 the surface tied to it
//     - f . u,   subject to  V(x) = V_0                          the fluid's volume
//
// Cubes c of size h, kept where part of them is inside the surface, f_c that part, each split
// into six tets (Kuhn); F_t the tet's deformation gradient, R_t the rotation nearest it
// (fitted at each nonlinear iteration, as the corotational capsule's are); v the
// lattice's displacements, (W v)_i their linear interpolation at node i's rest position in
// the tet holding it. A rigid motion of the whole costs nothing. With mu = E/2 the core is an
// elastic solid of Young's modulus E and Poisson's ratio 0 in each cube's rotated frame; the
// volume row stands in for the incompressibility. kappa = tie E / h.
//
// Const model + mutable state, as the FEM reference (engine/fem).
#include <memory>
#include <string>
#include <vector>

#include "engine/sim_state.hpp"
#include "engine/sparse.hpp"
#include "engine/types.hpp"

namespace vdm {
class SurfaceForceLaw;
}

namespace vdm::core {

struct CoreSettings {
  // The nonlinear iteration stops when the distance left to its fixed point, as estimated (the
  // last change over one less its contraction rate; a slide's slow modes hide from it, see
  // docs/model.md), is at most this x the organ's size (34 um on a 34 cm
  // liver: a tenth of a pixel of a 1280-wide frame of it). The FEM cases (the model ladder)
  // do not change from 1e-5 to 1e-4; a friction press on the liver ends 0.2 mm and 1 % of its
  // force apart (friction's answer depends on the path). A pressing step takes 3 to 6
  // iterations.
  double tolerance = 1e-4;
  // And the lattice's forces balance to this share of the core's elastic forces: where the
  // rotations converge slowly (a bending under a load, inertia) the change per iteration is
  // small long before the answer is near. (Not counted at the lattice nodes tied to surface
  // nodes whose forces changed within the step: a contact's, which its own test judges.)
  double force_tolerance = 1e-3;
  int max_iterations = 400; // per step
  // With forces from a law (contact), a step whose residual has reached no new low in this many
  // iterations stops, reported as unconverged: contact that does not settle (jaws closing
  // inside the tissue, a tool deep in it) wanders without converging, and would otherwise run
  // to max_iterations at each of the contact's re-solves. A press settles in 3-6 iterations, a
  // slide in 6-15; where many points begin to slip at once the residual falls
  // slowly but falls (up to 70 iterations on a ball pressed to half its depth,
  // CoreHard.ProbePressedToHalfTheBallsDepth).
  int law_stall_iterations = 100;
  int anderson = 6;         // history of the Anderson mixing of the lattice's displacements (0: plain fixed point)
  // Prescribed entries that are not the organ's own fixed ones (a contact's, a grasp's) are
  // held by multipliers through the factor already made, up to this many; beyond it (a large
  // prescribed region) the lattice is factorised with them. 0: always factorise.
  int max_held = 300;
};

struct CoreDef {
  SurfaceMesh surface;            // closed, outward (m)
  double young_modulus = 3000;    // E (Pa), > 0
  double cell_size = 0;           // h (m); 0: V_0 / A_0 of the surface
  double tie = 4;                 // kappa = tie E / h (1/m x Pa)
  FlagMat fixed;                  // surface nodes x 3: 1 = held at 0. Empty: none.
  double density = 1060;          // kg/m^3 (gravity and inertia)
  Vec3 gravity = Vec3(0, 0, -9.81);
  bool use_gravity = false;       // the weight, on the lattice: rho g f_c h^3 / 8 per cube corner
  // The inertia effect: the lattice's lumped mass (rho f_c h^3 / 8 per cube corner, as its
  // weight) and implicit Euler with step dt; damping (1/s) proportional to the mass. The
  // surface has no mass of its own: it follows its ties at once.
  bool use_inertia = false;
  double damping = 0;
  double dt = 1.0 / 30.0;
  bool compute_stress = false;    // strain and stress at the surface after each step (core_stress.hpp)
  CoreSettings settings;
};

struct CoreModel {
  SurfaceMesh surface;
  int ns = 0;                     // surface nodes
  int ng = 0;                     // lattice nodes
  double h = 0;                   // cell size (m)
  double mu = 0;                  // E / 2 (Pa)
  double young_modulus = 0;
  double rest_volume = 0, size = 0;  // m^3; bounding-box diagonal (m)
  Vec3 origin = Vec3::Zero();     // the lattice's corner (m)
  NodeMat lattice;                // ng x 3 rest positions (m)
  Eigen::Matrix<int, Eigen::Dynamic, 8, Eigen::RowMajor> cubes;  // corner node ids, corner k = (k>>2, k>>1, k)&1
  Vec fill;                       // per cube: the inside part f_c, in (0, 1]
  // Node i is tied to lattice nodes tie_node(i, 0..3) with weights tie_weight(i, 0..3).
  Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor> tie_node;
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> tie_weight;
  double kappa = 0;               // the ties' stiffness per area (Pa/m)
  Vec tie_k;                      // kappa |A_i| at rest (N/m), at least kappa |A| / 10 of its largest neighbour's
  SpMat K_core;                   // the core's matrix, one axis (lower and upper), N/m
  NodeMat gravity_load;           // ng x 3 lattice body force (N); empty without gravity
  Vec mass;                       // ng lumped lattice masses (kg); empty without inertia
  double inertia_rate = 0;        // 1/dt^2 + damping/dt (1/s^2): M times it joins K's diagonal
  double dt = 0;                  // the inertia's step (s)
  FlagMat fixed;                  // ns x 3
  bool compute_stress = false;
  CoreSettings settings;
};

bool build_core_model(const CoreDef& def, CoreModel& model, std::string& error);

// The unit cube's six Kuhn tets (0, e_a, e_a + e_b, (1,1,1) for each order of the axes): their
// corners (k = 4x + 2y + z), shape-function gradients (rows) and the sum of V_t G_t G_t^T.
struct UnitCube {
  int corner[6][4];
  // The axis of each of a tet's three edges from corner a to corner a + 1 (its gradients are
  // -e0, e0 - e1, e1 - e2, e2 for those axes e0, e1, e2, so that F - I's column along the edge's
  // axis is the motion's difference along the edge over h).
  int edge_axis[6][3];
  Eigen::Matrix<double, 4, 3> grad[6];
  Eigen::Matrix<double, 8, 8> K;
};
const UnitCube& unit_cube();

struct CoreStats {
  int iterations = 0;       // nonlinear iterations this step
  int factorizations = 0;
  int law_solves = 0;       // linear solves repeated with a SurfaceForceLaw's new forces
  double change = 0;        // last iteration's largest move / size
  int anderson_rejected = 0;  // Anderson iterates that did not lower the merit, replaced by the plain step
  bool converged = true;
};

struct CoreWorkspace;

struct CoreState {
  NodeMat u;                // ns x 3 surface displacements (m)
  NodeMat v;                // ng x 3 lattice displacements (m)
  NodeMat velocity;         // ng x 3 lattice velocities (m/s), with inertia
  // Where the step in progress started: a step solved again after rewind() is a step from
  // here (with inertia also its first guess; static, the last solve's answer is).
  NodeMat u_start, v_start, velocity_start;
  NodeMat u_motion, v_motion;  // the last static step's motion: the next starts from it repeated
  bool rewound = false;
  NodeMat reaction;         // ns x 3 force the constraints apply to the organ (N)
  double pressure = 0;      // the fluid's pressure change (Pa)
  double volume = 0, volume_rel_error = 0;
  CoreStats stats;
  std::vector<std::string> warnings;
  std::unique_ptr<CoreWorkspace> work;
  CoreState();
  ~CoreState();
  CoreState(CoreState&&) noexcept;
  CoreState& operator=(CoreState&&) noexcept;
};

CoreState make_core_state(const CoreModel& model);

// The next step() solves the last one again from where it started (with inertia, its lattice
// position and velocity, from the same first guess; without, from the last answer).
void rewind(CoreState& state);

// One step to the input's prescribed displacements, forces and pressures: static, or with
// inertia implicit Euler from the last step (StepInput's springs and tolerance are not
// taken). With `law`, the law's forces are set after every linear solve of the iteration
// (engine/surface_force_law.hpp) and the solve repeated with them; the caller judges the
// law's forces again at the solved state (ContactSolver solves the step again where they do
// not keep the laws), so the force balance that ends the step leaves out the cubes that carry
// them (iteration_converged; the parts below, for joint steps, count them).
void step(const CoreModel& model, const StepInput& input, CoreState& state, SurfaceForceLaw* law = nullptr);

// step() in its parts, for organs whose steps are iterated together (contact between organs,
// engine/organ_joint_step.hpp): begin_step(); then per iteration solve_iteration() (the
// rotations fitted, the linearisation, the linear solve and `law`'s forces), where the
// caller may change iteration_forces() (forces on the surface, as a law would) and call
// forces_changed() to move the iteration's answer by their change; iteration_converged(),
// whether this organ's iteration has reached its fixed point; advance_iteration(stop), which
// takes the answer when `stop` (the caller's decision, e.g. every organ converged) or mixes
// the next iterate, and returns whether the iteration goes on (false: stopped, stalled, or
// out of iterations); at last end_step(). begin_step() false: the lattice could not be
// factorised (the step is over, reported in the state's warnings; no end_step()).
bool begin_step(const CoreModel& model, const StepInput& input, CoreState& state, SurfaceForceLaw* law);
void solve_iteration(const CoreModel& model, CoreState& state);
// The surface's positions (ns x 3) the iteration's linear solve found, with the forces as last changed.
const NodeMat& iteration_surface(const CoreState& state);
NodeMat& iteration_forces(CoreState& state);
void forces_changed(const CoreModel& model, CoreState& state);
bool iteration_converged(const CoreModel& model, CoreState& state);
// After iteration_converged() and a change of the forces since: the next mix starts from the
// answer with them (its residual taken again, its convergence rate not) and is judged on the
// merit with them.
void mixing_residual(const CoreModel& model, CoreState& state);
bool advance_iteration(const CoreModel& model, CoreState& state, bool stop);
void end_step(const CoreModel& model, CoreState& state);

// The organ's compliance at surface nodes `nodes` (3n x 3n; row 3a + d, column 3b + e: how far
// node a moves along d under a unit force on node b along e) at the last step's linearisation
// (its rotations and surface), with the volume row, and what that step prescribed held (those
// entries' rows and columns are 0). Solved through the lattice's factor: no factorisation.
void surface_compliance(const CoreModel& model, CoreState& state, const std::vector<int>& nodes, Eigen::MatrixXd& C);

// The rotation of each tet (6 per cube, cube-major) at lattice displacements v: the rotation
// nearest its deformation gradient F (the polar decomposition's, for F with det F > 0), found
// by the rotation that maximises tr(R^T F), iterated from `quaternions` (the last ones: a warm
// start; identities at first), which it updates. Returns the core's energy there,
// sum_t mu f_c V_t |F_t - R_t|^2 with the rotations found.
double tet_rotations(const CoreModel& model, const NodeMat& v, std::vector<Eigen::Quaterniond>& quaternions,
                   std::vector<Eigen::Matrix3d>& rotations);

}  // namespace vdm::core
