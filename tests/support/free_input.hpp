#pragma once
// A step input for `n` nodes with nothing prescribed and no force: tests of the models that
// are built without a TissueModel (mass_spring, the elastic core) start from it.
#include "engine/sim_state.hpp"

namespace vdm::test {

inline StepInput free_input(int n) {
  StepInput in;
  in.force = NodeMat::Zero(n, 3);
  in.prescribed = FlagMat::Zero(n, 3);
  in.prescribed_u = NodeMat::Zero(n, 3);
  return in;
}

}  // namespace vdm::test
