#pragma once
// How much of the organ organ.fixed holds: the nodes held on every axis, on some, and what each
// organ.fixed entry selects (for `vdmsim check`).
#include <vector>

#include "app/scene/scene.hpp"

namespace vdmsim {

struct FixedCount {
  int nodes = 0;                 // the organ's nodes
  int fixed = 0;                 // held on all three axes
  int partly = 0;                // held on one or two axes only
  std::vector<int> per_region;   // nodes each of its fixed entries selects
};

// Counts on the rest positions `rest` of `organ` (the prepared organ's, after scale and placement).
FixedCount count_fixed(const OrganDef& organ, const vdm::NodeMat& rest);

}  // namespace vdmsim
