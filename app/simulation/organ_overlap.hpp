#pragma once
// Where two organs' surfaces pass into each other: triangles of one crossing triangles of the
// other (found by FCL on the two meshes), and how deep the part of each surface inside the
// other lies. `vdmsim check` reports organs that overlap at rest; a run stops when
// organs pass into each other (contact between organs is not simulated).
#include "engine/types.hpp"

namespace vdmsim {

struct OrganOverlap {
  bool crossing = false;            // some triangles of the two surfaces cross
  double depth = 0;                 // the deepest node of either inside the other organ (m)
  int node = -1;                    // that node: of organ a when in_b, else of organ b
  bool in_b = true;                 // the deepest node is organ a's, inside organ b
  vdm::Vec3 where = vdm::Vec3::Zero();  // that node's position (m)
};

// The overlap of closed surfaces a and b at positions xa, xb. The inside parts are walked from
// the corners of at most `pairs` crossing triangle pairs (each node's depth costs O(triangles)).
OrganOverlap find_overlap(const vdm::NodeMat& xa, const vdm::TriMat& ta, const vdm::NodeMat& xb,
                          const vdm::TriMat& tb, int pairs = 64);

}  // namespace vdmsim
