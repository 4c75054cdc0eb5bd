#pragma once
// The project's liver made irregular as a CT surface is (tests of the stress view on an
// irregular surface: engine/capsule_test.cpp, engine/core/core_stress_test.cpp).
#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "app/scene/organ_generator.hpp"
#include "engine/geometry.hpp"

namespace vdm::test {

// The project's liver made irregular as a CT surface is: every node moved at random along the
// surface by up to 30 % of its shortest edge, then about one edge in eight flipped (where the
// flip keeps the surface manifold and turns no triangle over).
inline SurfaceMesh irregular_liver(int level, unsigned seed) {
  SurfaceMesh m = vdmsim::make_liver_mesh(level);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  NodeMat a(m.node_count(), 3);
  distributed_area_vectors(m.positions, m.triangles, a);
  Vec shortest = Vec::Constant(m.node_count(), 1e9);
  for (int t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int i = m.triangles(t, k), j = m.triangles(t, (k + 1) % 3);
      const double l = (m.positions.row(i) - m.positions.row(j)).norm();
      shortest[i] = std::min(shortest[i], l);
      shortest[j] = std::min(shortest[j], l);
    }
  for (int i = 0; i < m.node_count(); ++i) {
    const Vec3 n = a.row(i).normalized();
    Vec3 d(uni(rng), uni(rng), uni(rng));
    d -= d.dot(n) * n;
    m.positions.row(i) += (0.3 * shortest[i] * d).transpose();
  }
  // Flips: triangles (i, j, k) and (j, i, l) sharing edge ij become (k, l, j) and (l, k, i).
  std::map<std::pair<int, int>, int> owner;  // directed edge -> triangle
  for (int t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) owner[{m.triangles(t, k), m.triangles(t, (k + 1) % 3)}] = t;
  auto normal = [&](int a0, int b0, int c0) {
    return Vec3((m.positions.row(b0) - m.positions.row(a0)).cross(m.positions.row(c0) - m.positions.row(a0)));
  };
  std::set<std::pair<int, int>> edges_now;
  for (const auto& [e, t] : owner) edges_now.insert({std::min(e.first, e.second), std::max(e.first, e.second)});
  std::vector<char> touched(size_t(m.triangle_count()), 0);
  for (int t = 0; t < m.triangle_count(); ++t) {
    if (touched[size_t(t)] || rng() % 8 != 0) continue;
    const int i = m.triangles(t, 0), j = m.triangles(t, 1), k = m.triangles(t, 2);
    const auto it = owner.find({j, i});
    if (it == owner.end() || touched[size_t(it->second)]) continue;
    const int u = it->second;
    int l = -1;
    for (int c = 0; c < 3; ++c)
      if (m.triangles(u, c) != i && m.triangles(u, c) != j) l = m.triangles(u, c);
    if (l < 0 || edges_now.count({std::min(k, l), std::max(k, l)})) continue;
    const Vec3 n_before = normal(i, j, k) + normal(j, i, l);
    if (normal(k, l, j).dot(n_before) <= 0 || normal(l, k, i).dot(n_before) <= 0) continue;
    edges_now.erase({std::min(i, j), std::max(i, j)});
    edges_now.insert({std::min(k, l), std::max(k, l)});
    m.triangles.row(t) << k, l, j;
    m.triangles.row(u) << l, k, i;
    touched[size_t(t)] = touched[size_t(u)] = 1;
  }
  return m;
}

}  // namespace vdm::test
