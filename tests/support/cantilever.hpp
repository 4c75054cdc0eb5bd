#pragma once
// A square cantilever along x for the elastic core's tests: its surface, its root face held,
// and the mean z displacement of its tip face.
#include "engine/shapes.hpp"
#include "engine/types.hpp"

namespace vdm::test {

// A length x side x side box from x = 0 to x = length, `along` cells along it, `across` across.
inline SurfaceMesh cantilever_surface(double length, double side, int along, int across) {
  return make_box(Vec3(length, side, side), along, across, across, Vec3(length / 2, 0, 0));
}

// Every axis of the nodes on the root face (x = 0) held.
inline FlagMat cantilever_root(const SurfaceMesh& beam) {
  FlagMat fixed = FlagMat::Zero(beam.positions.rows(), 3);
  for (Eigen::Index i = 0; i < beam.positions.rows(); ++i)
    if (beam.positions(i, 0) < 1e-9) fixed.row(i).setOnes();
  return fixed;
}

// The mean z displacement of the tip face's nodes (x = length) under surface displacements u.
inline double cantilever_tip_z(const SurfaceMesh& beam, const NodeMat& u, double length) {
  double sum = 0;
  int count = 0;
  for (Eigen::Index i = 0; i < beam.positions.rows(); ++i)
    if (beam.positions(i, 0) > length - 1e-9) {
      sum += u(i, 2);
      ++count;
    }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace vdm::test
