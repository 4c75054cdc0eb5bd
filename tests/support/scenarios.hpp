#pragma once
// Small scenarios shared by the engine tests: a cube on a table pressed by a plate, a beam
// pulled at one end, spheres. Every helper returns a built model.
#include <string>

#include <gtest/gtest.h>

#include "engine/shapes.hpp"
#include "engine/sim_state.hpp"

namespace vdm::scenario {

inline TissueModel build(const TissueDef& def) {
  TissueModel m;
  std::string err;
  if (!build_tissue_model(def, m, err)) ADD_FAILURE() << "model: " << err;
  return m;
}

// A ball of radius R (icosphere of `level` subdivisions) held at its bottom (below -0.8 R).
inline TissueModel ball_on_base(double R, int level) {
  TissueDef def = default_tissue(make_icosphere(R, level));
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -0.8 * R) def.fixed.row(i).setOnes();
  return build(def);
}

// Cube of side L centred at the origin, bottom face fixed.
inline TissueDef cube_on_table(double L = 0.1, int cells = 6, SolverMethod method = SolverMethod::structured) {
  TissueDef def = default_tissue(make_box(Vec3(L, L, L), cells, cells, cells));
  def.solver.method = method;
  def.solver.tolerance = 1e-10;
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -L / 2 + 1e-12) def.fixed.row(i).setOnes();
  return def;
}

// Prescribes u_z = travel on the top face (z = +L/2) of a cube; x, y free.
inline void press_top(const TissueModel& m, double L, double travel, StepInput& in) {
  for (int i = 0; i < m.n; ++i)
    if (m.rest.positions(i, 2) > L / 2 - 1e-12) {
      in.prescribed(i, 2) = 1;
      in.prescribed_u(i, 2) = travel;
    }
}

// Beam along y from y = 0 to y = length, square section `width`; the end y = 0 fixed.
inline TissueDef clamped_beam(double length = 0.1, double width = 0.02, int along = 10, int across = 2,
                              SolverMethod method = SolverMethod::structured) {
  TissueDef def = default_tissue(
      make_box(Vec3(width, length, width), across, along, across, Vec3(0, length / 2, 0)));
  def.solver.method = method;
  def.solver.tolerance = 1e-10;
  const int n = def.mesh.node_count();
  def.fixed = FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 1) < 1e-12) def.fixed.row(i).setOnes();
  return def;
}

// Prescribes the free end (y = length) of a beam to move by `delta` (all axes).
inline void move_end(const TissueModel& m, double length, const Vec3& delta, StepInput& in) {
  for (int i = 0; i < m.n; ++i)
    if (m.rest.positions(i, 1) > length - 1e-12) {
      in.prescribed.row(i).setOnes();
      in.prescribed_u.row(i) = delta.transpose();
    }
}

}  // namespace vdm::scenario
