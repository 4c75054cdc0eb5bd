#pragma once
// Every axis of a surface's nodes below height z held (an organ resting on its base): the
// fixed entries of the elastic core's tests.
#include "engine/sim_state.hpp"

namespace vdm::test {

inline FlagMat held_below(const SurfaceMesh& s, double z) {
  FlagMat fixed = FlagMat::Zero(s.node_count(), 3);
  for (int i = 0; i < s.node_count(); ++i)
    if (s.positions(i, 2) < z) fixed.row(i).setOnes();
  return fixed;
}

}  // namespace vdm::test
