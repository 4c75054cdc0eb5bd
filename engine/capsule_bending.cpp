#include "engine/capsule_bending.hpp"

#include <algorithm>

#include <Eigen/SparseCore>

namespace vdm {

CapsulePairs capsule_bending_pairs(const std::vector<std::array<int, 2>>& edges, const std::vector<double>& cot,
                                   const Vec& area, double D) {
  using Sp = Eigen::SparseMatrix<double>;
  const Eigen::Index n = area.size();
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(4 * edges.size());
  for (size_t e = 0; e < edges.size(); ++e) {
    const int i = edges[e][0], j = edges[e][1];
    const double c = cot[e];
    t.emplace_back(i, j, -c);
    t.emplace_back(j, i, -c);
    t.emplace_back(i, i, c);
    t.emplace_back(j, j, c);
  }
  Sp C(n, n);
  C.setFromTriplets(t.begin(), t.end());
  const Vec inv_m = area.cwiseInverse();
  const Sp K = Sp(D * (C * inv_m.asDiagonal() * C)).pruned(0.0, 0.0);

  // K's strict upper triangle, column by column: pairs (i, j), i < j, sorted by (i, j) after.
  std::vector<std::pair<std::array<int, 2>, double>> bending;
  for (Eigen::Index j = 0; j < K.outerSize(); ++j)
    for (Sp::InnerIterator it(K, j); it; ++it)
      if (it.row() < j) bending.push_back({{int(it.row()), int(j)}, -it.value()});
  std::sort(bending.begin(), bending.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

  // Merge the two sorted pair lists.
  CapsulePairs out;
  out.edges.reserve(edges.size() + bending.size());
  size_t a = 0, b = 0;
  while (a < edges.size() || b < bending.size()) {
    const bool take_a = b == bending.size() || (a < edges.size() && edges[a] <= bending[b].first);
    const bool take_b = a == edges.size() || (b < bending.size() && bending[b].first <= edges[a]);
    out.edges.push_back(take_a ? edges[a] : bending[b].first);
    out.cot.push_back(take_a ? cot[a] : 0.0);
    out.bending.push_back(take_b ? bending[b].second : 0.0);
    a += take_a;
    b += take_b;
  }
  return out;
}

}  // namespace vdm
