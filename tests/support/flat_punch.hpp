#pragma once
// The flat-punch block (docs/model.md, "mesh convergence"): a 10 x 10 x 5 cm block, bottom
// fixed, a flat frictionless punch of radius 5 mm pressed 5 mm into the top face's centre.
// Read back: the top face's vertical displacement at given distances from the centre and the
// punch force. The same case at several resolutions shows whether a model converges.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "engine/shapes.hpp"
#include "engine/sim_state.hpp"

namespace vdm::punch {

struct PunchResult {
  int nodes = 0;
  std::vector<double> dent;  // u_z (m) of the top face at each asked distance along +x
  double force = 0;          // N, the punch's push (> 0)
  double volume_error = 0;   // relative
};

struct PunchCase {
  double width = 0.1, height = 0.05;
  double radius = 0.005, depth = 0.005;
  double bulk = 20000, connectivity = 2000;
  CapsuleForm capsule = CapsuleForm::membrane;
  int steps = 5;
  bool square = false;    // a square punch of half-width `radius` (edges on the lattice's lines)
};

// Runs the punch on a block of `cells` cells across (cells / 2 up), returning the dent at
// `distances` (m, from the centre along +x: lattice nodes when the distances are multiples of
// the cell size).
inline PunchResult run_punch(const PunchCase& c, int cells, const std::vector<double>& distances) {
  TissueDef def = default_tissue(make_box(Vec3(c.width, c.width, c.height), cells, cells, cells / 2));
  def.bulk = c.bulk;
  def.connectivity_modulus = c.connectivity;
  def.capsule = c.capsule;
  def.solver.method = SolverMethod::direct;
  def.solver.tolerance = 1e-10;
  const int n = def.mesh.node_count();
  const double top = c.height / 2;
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -top + 1e-12) def.fixed.row(i).setOnes();
  TissueModel m;
  std::string error;
  PunchResult r;
  if (!build_tissue_model(def, m, error)) {
    ADD_FAILURE() << error;
    return r;
  }
  SimState s = make_sim_state(m);
  StepInput in = make_step_input(m);
  std::vector<int> pressed;
  for (int i = 0; i < n; ++i) {
    const auto p = m.rest.positions.row(i);
    if (p(2) > top - 1e-12 && (c.square ? std::max(std::abs(p(0)), std::abs(p(1))) : std::hypot(p(0), p(1))) <= c.radius + 1e-9) pressed.push_back(i);
  }
  for (int k = 1; k <= c.steps; ++k) {
    for (const int i : pressed) {
      in.prescribed(i, 2) = 1;
      in.prescribed_u(i, 2) = -c.depth * k / c.steps;
    }
    step(m, in, s);
    if (s.failed) {
      ADD_FAILURE() << "punch step " << k << ": " << s.failure;
      return r;
    }
  }
  r.nodes = n;
  for (const int i : pressed) r.force -= s.reaction(i, 2);
  r.volume_error = s.volume_rel_error;
  for (const double d : distances) {
    const int i = nearest_node(m.rest.positions, Vec3(d, 0, top));
    r.dent.push_back(s.u(i, 2));
  }
  return r;
}

}  // namespace vdm::punch
