#pragma once
// The finite-element reference model: corotational linear elasticity on linear tetrahedra,
// solved statically (Newton) each step. Same split as the VDM engine: a const FemModel
// built once from a FemDef, a mutable FemState, and fem::step().
//
// Energy (rest volume V_e, F = deformation gradient, F = R S its polar decomposition):
//   E = sum_e V_e mu |F_e - R_e|^2  +  sum_g (lambda / 2) V_g theta_g^2  -  f . u
// with theta_e = tr(S_e) - 3 the corotated volumetric strain. This is linear elasticity
// (E, nu) in each element's rotated frame, so a rigid motion costs nothing. Linear tets lock
// as nu -> 0.5 when theta is held per element; with `nodal_volumetric` (default) theta_g is
// the volume-weighted average of theta_e over the tets around node g (the "average nodal
// pressure" tet of Bonet and Burton), which has about one volumetric constraint per node
// instead of five or six per node and does not lock in bending up to nu = 0.49.
#include <string>
#include <vector>

#include "engine/fem/tet_mesh.hpp"
#include "engine/sparse.hpp"

namespace vdm::fem {

using FlagMat = Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 3>;

struct FemSettings {
  double tolerance = 1e-9;     // Newton: free residual below this x the force scale
  int max_iterations = 40;     // Newton iterations per (sub)step
  int max_bisections = 6;      // a failed step is split in two, at most this deep
  bool nodal_volumetric = true;  // average nodal volumetric strain (anti-locking); false: per tet
  // Linear solves of Newton: sparse LDL^T up to `direct_max_dofs` unknowns, else conjugate
  // gradients with an incomplete Cholesky preconditioner (on the projected, PSD tangent) to
  // `cg_tolerance`. Simplicial LDL^T of a 3D mesh grows too fast past ~10^4 unknowns.
  int direct_max_dofs = 12000;
  // With SuiteSparse's supernodal Cholesky (built with CHOLMOD) the direct solve stays the
  // faster one much further.
  int direct_max_dofs_supernodal = 300000;
  double cg_tolerance = 1e-6;
  int cg_max_iterations = 5000;
};

struct FemDef {
  TetMesh mesh;                  // metres; surface nodes first
  double young_modulus = 3000;   // E (Pa), > 0
  double poisson_ratio = 0.45;   // nu, in [0, 0.5)
  double density = 1060;         // kg/m^3 (gravity only)
  Vec3 gravity = Vec3(0, 0, -9.81);
  bool use_gravity = false;
  FlagMat fixed;                 // surface_nodes x 3: 1 = u held at 0. Empty: none.
  FemSettings settings;
};

struct FemModel {
  TetMesh mesh;
  int n = 0;                      // all nodes
  int ns = 0;                     // surface nodes (the first ns)
  int tets = 0;
  double mu = 0, lambda = 0;      // Lame parameters (Pa)
  double young_modulus = 0, poisson_ratio = 0;
  std::vector<Eigen::Matrix<double, 4, 3>> grad;  // per tet: row q = rest gradient of N_q (1/m)
  Vec tet_volume;                 // rest V_e (m^3)
  // Volumetric groups g (nodes, or tets without nodal averaging): members (tet, weight) with
  // theta_g = sum weight * theta_e, and the group's rest volume V_g.
  std::vector<int> group_start;   // size groups + 1
  std::vector<int> group_tet;
  std::vector<double> group_weight;
  Vec group_volume;
  NodeMat gravity_force;          // n x 3 lumped body force (N); empty without gravity
  FlagMat fixed;                  // n x 3 (interior rows zero)
  double rest_volume = 0;         // m^3
  double size = 0;                // bounding-box diagonal (m)
  FemSettings settings;
};

bool build_fem_model(const FemDef& def, FemModel& model, std::string& error);

// Lame parameters from Young's modulus and Poisson's ratio.
double lame_mu(double young, double poisson);
double lame_lambda(double young, double poisson);

}  // namespace vdm::fem
