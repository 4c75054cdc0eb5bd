#pragma once
// The classic baseline (paper section 2.1): springs on the surface edges, optionally one
// volume spring (a uniform pressure proportional to the volume change), solved statically
// each step by Newton with a line search on the energy:
//   E = sum_edges k_e (|x_i - x_j| - L_e)^2 / 2  +  K_v (V - V_0)^2 / (2 V_0)  -  f . u
// A surface of springs has no stiffness against motions that keep every edge length (a flat
// patch bending, a crease folding): the solve adds a vanishing Levenberg-Marquardt term so that
// such motions, when nothing loads them, stay where they are.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "engine/sim_state.hpp"
#include "engine/types.hpp"

namespace vdm {

struct MassSpringDef {
  NodeMat positions;                     // N x 3 rest positions (m)
  TriMat triangles;                      // T x 3, outward; may be empty (then no volume spring)
  std::vector<std::array<int, 2>> edges; // empty: the triangles' unique edges
  Vec stiffness;                         // per edge (N/m); empty: from young_modulus (Van Gelder)
  double young_modulus = 3000;           // E (Pa) of the skin, with `thickness`
  double thickness = 0.005;              // skin thickness (m): k_e = E t sum_{tri on e} area / L_e^2
  double volume_modulus = 0;             // K_v (Pa); 0 = no volume spring
  FlagMat fixed;                         // N x 3; empty = none
  double tolerance = 1e-6;               // free residual / force scale (converges linearly where
                                         // springs are compressed: their Hessian is projected)
  int max_iterations = 100;
};

struct MassSpringModel {
  NodeMat rest;
  TriMat triangles;
  std::vector<std::array<int, 2>> edges;
  Vec rest_length, stiffness;
  double volume_modulus = 0;
  double rest_volume = 0;                // 0 when there are no triangles
  Vec3 origin = Vec3::Zero();
  FlagMat fixed;
  double size = 0;
  double tolerance = 1e-6;
  int max_iterations = 100;
  int n = 0;
};

bool build_mass_spring_model(const MassSpringDef& def, MassSpringModel& model, std::string& error);

struct MassSpringWorkspace;

struct MassSpringState {
  NodeMat u, reaction;                   // N x 3 (m, N)
  double volume = 0, volume_rel_error = 0;
  double pressure = 0;                   // -K_v (V - V_0) / V_0 (Pa)
  int iterations = 0;
  double residual = 0;
  bool converged = true;
  std::shared_ptr<MassSpringWorkspace> work;
};

MassSpringState make_mass_spring_state(const MassSpringModel& model);

// Static equilibrium under `input` (forces, prescribed displacements; pressure ignored).
void step(const MassSpringModel& model, const StepInput& input, MassSpringState& state);

// Energy at u under f (J); with `gradient`, dE/du.
double energy(const MassSpringModel& model, const NodeMat& u, const NodeMat& f, NodeMat* gradient);

}  // namespace vdm
