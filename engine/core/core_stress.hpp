#pragma once
// The elastic core's strain and stress (docs/model.md, "The elastic core"): per tetrahedron
// from the energy the core minimises, carried to the surface through the ties.
//
// A tet's energy is mu f_c V_t |F_t - R_t|^2 with mu = E/2 and R_t the rotation nearest F_t
// (its derivative in R vanishes there), so its first Piola stress is P = 2 mu (F - R) =
// E (F - R). In the tet's rotated frame, R^T P = E (U - I) with U = R^T F the right stretch: a
// linear solid of Young's modulus E and Poisson's ratio 0 on the corotated strain U - I.
// Turned to world axes:
//
//   eps_t   = sym(F_t R_t^T) - I        the corotated strain (R (U - I) R^T)
//   sigma_t = E eps_t - p I             the core's stress, and the fluid's pressure p
//
// p is the fluid's pressure change (CoreState::pressure; p > 0 pushes the surface out, so it
// compresses the tissue): the volumetric part that keeps the organ incompressible. The fluid
// takes no shear, so the von Mises stress is the core's alone. The symmetric part makes eps_t
// insensitive, to first order, to an error in R (the step's rotations are those of its last
// iteration, within the step's tolerance of the final lattice).
//
// At the surface: each lattice node takes the mean of its tets' eps_t, weighted by the
// material each holds (f_c V_t), and surface node i the interpolation of those with the
// weights that tie it (W, linear in the tet holding its rest position). The field is then
// continuous across the tets (one constant per tet would show the lattice's cells).
#include <vector>

#include <Eigen/Core>

#include "engine/core/elastic_core.hpp"

namespace vdm::core {

struct CoreStrain {
  std::vector<Eigen::Matrix3d> tet;      // per tet (6 per cube, cube-major): eps_t
  std::vector<Eigen::Matrix3d> lattice;  // per lattice node: the f_c V_t-weighted mean of its tets' eps_t
  Vec weight;                            // per lattice node: the sum of those weights (m^3)
};

// eps_t of every tet at lattice displacements `v` (ng x 3) and tet rotations `rotations`
// (tet_rotations()'s), and their means at the lattice nodes. Allocates only on first use.
void core_strain(const CoreModel& m, const NodeMat& v, const std::vector<Eigen::Matrix3d>& rotations, CoreStrain& out);
// The same at the state's last step: its lattice and the rotations its step last fitted.
void core_strain(const CoreModel& m, const CoreState& s, CoreStrain& out);

// The strain the ties carry to surface node i: sum_p W_ip (lattice eps at node p).
Eigen::Matrix3d surface_strain(const CoreModel& m, const CoreStrain& c, int i);

// The surface's stress in the per-axis form the VDM model has (SimState::stress and strain):
// stress(i, d) = sigma_dd = E eps_dd - p, strain(i, d) = eps_dd (its row sum: the volumetric
// strain), eps = surface_strain(i). `stress` and `strain` must be ns x 3.
void surface_stress(const CoreModel& m, const CoreStrain& c, double pressure, NodeMat& stress, NodeMat& strain);

// The stress of the state's last step at the surface: core_strain at its lattice and the
// rotations its step last fitted, then surface_stress with its pressure. `work` is kept
// between calls (no allocation after the first).
void core_surface_stress(const CoreModel& m, const CoreState& s, CoreStrain& work, NodeMat& stress, NodeMat& strain);

// The von Mises stress of a stress tensor, sqrt(3/2 dev(sigma) : dev(sigma)) (Pa).
double von_mises(const Eigen::Matrix3d& sigma);

}  // namespace vdm::core
