#include "app/check/fixed_nodes.hpp"

#include <array>

#include "app/simulation/prepared_scene.hpp"

namespace vdmsim {

FixedCount count_fixed(const OrganDef& organ, const vdm::NodeMat& rest) {
  FixedCount c;
  c.nodes = static_cast<int>(rest.rows());
  std::vector<std::array<bool, 3>> held(static_cast<size_t>(c.nodes), {false, false, false});
  std::vector<SceneProblem> ignored;  // the scene was validated when it was prepared
  for (size_t k = 0; k < organ.fixed.size(); ++k) {
    const std::vector<int> nodes = select_nodes(organ.fixed[k].region, rest, organ.field + ".fixed", ignored);
    c.per_region.push_back(static_cast<int>(nodes.size()));
    for (int i : nodes)
      for (int d = 0; d < 3; ++d) held[static_cast<size_t>(i)][d] = held[static_cast<size_t>(i)][d] || organ.fixed[k].axes[d];
  }
  for (const auto& h : held) {
    const int axes = int(h[0]) + int(h[1]) + int(h[2]);
    if (axes == 3) ++c.fixed;
    else if (axes > 0) ++c.partly;
  }
  return c;
}

}  // namespace vdmsim
