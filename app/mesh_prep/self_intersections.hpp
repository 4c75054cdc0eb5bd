#pragma once
// Whether an organ surface passes through itself: two triangles that cross (sharing an edge
// or a node with no other contact does not count). A self-intersecting surface encloses no
// well-defined volume, so it is no valid organ. CGAL's box-intersection test: O(n log n).
#include <array>
#include <string>
#include <vector>

#include "engine/types.hpp"

namespace vdmsim {

struct SelfIntersections {
  bool tested = false;                    // false: the surface is no manifold, the test could not run
  bool any = false;                       // at least one pair crosses
  std::vector<std::array<int, 2>> pairs;  // crossing triangles (indices into mesh.triangles), up to max_pairs
  std::string text(size_t shown = 5) const;  // "triangles 12 and 840, ..." (the first `shown` pairs)
};

// max_pairs 0: stop at the first crossing (the cheapest: `any` and one pair).
SelfIntersections find_self_intersections(const vdm::SurfaceMesh& mesh, size_t max_pairs = 0);

}  // namespace vdmsim
