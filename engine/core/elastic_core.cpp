// The elastic core's lattice: cubes over the organ's inside, their inside parts, the surface's
// ties to them, and the core's matrix.
#include "engine/core/elastic_core.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <utility>

#include "engine/geometry.hpp"

namespace vdm::core {
namespace {

constexpr int kSamples = 4;  // inside samples per cube edge (64 per cube)
constexpr double kMinFill = 0.02;  // a cube holding a surface node but no inside sample
// The lattice's corner sits at this fraction of a cell below the surface's lowest corner, so
// that its planes do not fall on a box-shaped organ's faces or on its mesh lines.
const Vec3 kOffset(0.63, 0.59, 0.71);

// Corner k of a cube is (x, y, z) = ((k >> 2) & 1, (k >> 1) & 1, k & 1).
int corner_of(int x, int y, int z) { return 4 * x + 2 * y + z; }

// The six Kuhn tets of the unit cube: 0, e_a, e_a + e_b, (1,1,1) for each order (a, b, c) of the
// axes. A point with local coordinates l lies in the tet of the order that sorts l descending.
std::array<int, 4> kuhn_tet(const std::array<int, 3>& order) {
  int c[3] = {0, 0, 0};
  std::array<int, 4> t{};
  t[0] = corner_of(0, 0, 0);
  for (int k = 0; k < 3; ++k) {
    c[order[static_cast<size_t>(k)]] = 1;
    t[static_cast<size_t>(k) + 1] = corner_of(c[0], c[1], c[2]);
  }
  return t;
}

Vec3 corner_position(int k) { return Vec3((k >> 2) & 1, (k >> 1) & 1, k & 1); }

UnitCube make_unit_cube() {
  UnitCube u;
  Eigen::Matrix<double, 8, 8>& K = u.K;
  K.setZero();
  std::array<int, 3> order = {0, 1, 2};
  int tet = 0;
  do {
    const std::array<int, 4> t = kuhn_tet(order);
    Eigen::Matrix3d Dm;
    for (int k = 0; k < 3; ++k) Dm.col(k) = corner_position(t[static_cast<size_t>(k) + 1]) - corner_position(t[0]);
    const Eigen::Matrix3d Dinv = Dm.inverse();  // row k: gradient of N_{k+1}
    Eigen::Matrix<double, 4, 3> G;
    G.bottomRows<3>() = Dinv;
    G.row(0) = -Dinv.colwise().sum();
    const double V = std::abs(Dm.determinant()) / 6;
    for (int a = 0; a < 4; ++a) u.corner[tet][a] = t[static_cast<size_t>(a)];
    for (int k = 0; k < 3; ++k) u.edge_axis[tet][k] = order[static_cast<size_t>(k)];
    u.grad[tet++] = G;
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) K(t[static_cast<size_t>(a)], t[static_cast<size_t>(b)]) += V * G.row(a).dot(G.row(b));
    }
  } while (std::next_permutation(order.begin(), order.end()));
  return u;
}

// Inside samples per cube: vertical rays through a grid of sample columns, the surface's
// crossings of each sorted, a sample inside when an odd number lie below it.
void inside_samples(const SurfaceMesh& s, const Vec3& lo, double h, const Eigen::Vector3i& dims, std::vector<int>& count) {
  const double d = h / kSamples;
  const int cx = dims.x() * kSamples, cy = dims.y() * kSamples, cz = dims.z() * kSamples;
  std::vector<std::pair<int, double>> crossings;
  const auto& P = s.positions;
  for (int t = 0; t < s.triangle_count(); ++t) {
    const Vec3 a = P.row(s.triangles(t, 0)), b = P.row(s.triangles(t, 1)), c = P.row(s.triangles(t, 2));
    const double area2 = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (area2 == 0) continue;  // vertical: no ray crosses it
    const double xmin = std::min({a.x(), b.x(), c.x()}), xmax = std::max({a.x(), b.x(), c.x()});
    const double ymin = std::min({a.y(), b.y(), c.y()}), ymax = std::max({a.y(), b.y(), c.y()});
    const int i0 = std::max(0, static_cast<int>(std::ceil((xmin - lo.x()) / d - 0.5)));
    const int i1 = std::min(cx - 1, static_cast<int>(std::floor((xmax - lo.x()) / d - 0.5)));
    const int j0 = std::max(0, static_cast<int>(std::ceil((ymin - lo.y()) / d - 0.5)));
    const int j1 = std::min(cy - 1, static_cast<int>(std::floor((ymax - lo.y()) / d - 0.5)));
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j) {
        const double px = lo.x() + (i + 0.5) * d, py = lo.y() + (j + 0.5) * d;
        // Barycentric coordinates in the xy projection. A column exactly through an edge would
        // be counted twice; the columns sit off the lattice's planes by the offset above.
        const double l1 = ((px - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (py - a.y())) / area2;
        const double l2 = ((b.x() - a.x()) * (py - a.y()) - (px - a.x()) * (b.y() - a.y())) / area2;
        const double l0 = 1 - l1 - l2;
        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
        crossings.emplace_back(i * cy + j, l0 * a.z() + l1 * b.z() + l2 * c.z());
      }
  }
  std::sort(crossings.begin(), crossings.end());
  count.assign(static_cast<size_t>(dims.prod()), 0);
  size_t k = 0;
  while (k < crossings.size()) {
    const int col = crossings[k].first;
    size_t e = k;
    while (e < crossings.size() && crossings[e].first == col) ++e;
    const int i = col / cy, j = col % cy;
    size_t below = k;
    for (int z = 0; z < cz; ++z) {
      const double pz = lo.z() + (z + 0.5) * d;
      while (below < e && crossings[below].second < pz) ++below;
      if ((below - k) % 2 == 1) ++count[static_cast<size_t>(((i / kSamples) * dims.y() + j / kSamples) * dims.z() + z / kSamples)];
    }
    k = e;
  }
}

}  // namespace

const UnitCube& unit_cube() {
  static const UnitCube cube = make_unit_cube();
  return cube;
}

bool build_core_model(const CoreDef& def, CoreModel& m, std::string& error) {
  const SurfaceMesh& s = def.surface;
  const int ns = s.node_count();
  if (ns < 4 || s.triangle_count() < 4) return error = "elastic core: the surface has too few nodes", false;
  if (!(def.young_modulus > 0)) return error = "elastic core: young_modulus must be > 0", false;
  if (def.fixed.rows() != 0 && def.fixed.rows() != ns) return error = "elastic core: fixed has the wrong size", false;
  m = CoreModel{};
  m.surface = s;
  m.ns = ns;
  m.young_modulus = def.young_modulus;
  m.mu = def.young_modulus / 2;
  m.settings = def.settings;
  m.compute_stress = def.compute_stress;
  m.rest_volume = enclosed_volume(s.positions, s.triangles, Vec3::Zero());
  const double area = surface_area(s.positions, s.triangles);
  if (!(m.rest_volume > 0)) return error = "elastic core: the surface encloses no volume (open, or inward)", false;
  const Vec3 pmin = s.positions.colwise().minCoeff(), pmax = s.positions.colwise().maxCoeff();
  m.size = (pmax - pmin).norm();
  m.h = def.cell_size > 0 ? def.cell_size : m.rest_volume / area;
  if (!(m.h > 1e-6 * m.size)) return error = "elastic core: cell_size is too small for the organ", false;
  const double h = m.h;
  m.origin = pmin - kOffset * h;
  Eigen::Vector3i dims;
  for (int k = 0; k < 3; ++k) dims[k] = static_cast<int>(std::floor((pmax[k] - m.origin[k]) / h)) + 1;
  if (static_cast<double>(dims.x()) * dims.y() * dims.z() > 2e7)
    return error = "elastic core: cell_size gives more than 2e7 cells over the organ's box", false;
  std::vector<int> inside;
  inside_samples(s, m.origin, h, dims, inside);
  auto cube_of = [&](const Eigen::Vector3i& c) { return static_cast<size_t>((c.x() * dims.y() + c.y()) * dims.z() + c.z()); };
  auto cell_of = [&](const Vec3& X, Vec3& local) {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k) {
      const double q = (X[k] - m.origin[k]) / h;
      c[k] = std::clamp(static_cast<int>(std::floor(q)), 0, dims[k] - 1);
      local[k] = std::clamp(q - c[k], 0.0, 1.0);
    }
    return c;
  };
  std::vector<double> fill(inside.size(), 0.0);
  const double per_cube = kSamples * kSamples * kSamples;
  for (size_t c = 0; c < inside.size(); ++c) fill[c] = inside[c] / per_cube;
  Vec3 local;
  for (int i = 0; i < ns; ++i) {
    const size_t c = cube_of(cell_of(s.positions.row(i), local));
    fill[c] = std::max(fill[c], kMinFill);
  }
  // Kept cubes and their corner nodes, numbered in lattice order.
  const Eigen::Vector3i nd = dims + Eigen::Vector3i::Ones();
  std::vector<int> node_id(static_cast<size_t>(nd.prod()), -1), cube_id(fill.size(), -1);
  std::vector<int> kept;
  for (size_t c = 0; c < fill.size(); ++c)
    if (fill[c] > 0) {
      cube_id[c] = static_cast<int>(kept.size());
      kept.push_back(static_cast<int>(c));
    }
  auto node_key = [&](int x, int y, int z) { return static_cast<size_t>((x * nd.y() + y) * nd.z() + z); };
  for (const int c : kept) {
    const int x = c / (dims.y() * dims.z()), y = (c / dims.z()) % dims.y(), z = c % dims.z();
    for (int k = 0; k < 8; ++k) node_id[node_key(x + ((k >> 2) & 1), y + ((k >> 1) & 1), z + (k & 1))] = 0;
  }
  int ng = 0;
  for (size_t key = 0; key < node_id.size(); ++key)
    if (node_id[key] == 0) node_id[key] = ng++;
  m.ng = ng;
  m.lattice.resize(ng, 3);
  for (int x = 0; x < nd.x(); ++x)
    for (int y = 0; y < nd.y(); ++y)
      for (int z = 0; z < nd.z(); ++z) {
        const int id = node_id[node_key(x, y, z)];
        if (id >= 0) m.lattice.row(id) = m.origin + h * Vec3(x, y, z);
      }
  m.cubes.resize(static_cast<Eigen::Index>(kept.size()), 8);
  m.fill.resize(static_cast<Eigen::Index>(kept.size()));
  for (size_t q = 0; q < kept.size(); ++q) {
    const int c = kept[q];
    const int x = c / (dims.y() * dims.z()), y = (c / dims.z()) % dims.y(), z = c % dims.z();
    for (int k = 0; k < 8; ++k)
      m.cubes(static_cast<Eigen::Index>(q), k) = node_id[node_key(x + ((k >> 2) & 1), y + ((k >> 1) & 1), z + (k & 1))];
    m.fill[static_cast<Eigen::Index>(q)] = fill[static_cast<size_t>(c)];
  }
  // Ties: the Kuhn tet holding each node's rest position, barycentric weights.
  NodeMat area_vectors(ns, 3);
  distributed_area_vectors(s.positions, s.triangles, area_vectors);
  const double kappa = def.tie * def.young_modulus / h;
  m.kappa = kappa;
  m.tie_node.resize(ns, 4);
  m.tie_weight.resize(ns, 4);
  m.tie_k.resize(ns);
  for (int i = 0; i < ns; ++i) {
    const Eigen::Vector3i c = cell_of(s.positions.row(i), local);
    const int q = cube_id[cube_of(c)];
    std::array<int, 3> order = {0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int a, int b) { return local[a] > local[b] || (local[a] == local[b] && a < b); });
    const std::array<int, 4> t = kuhn_tet(order);
    const double l0 = local[order[0]], l1 = local[order[1]], l2 = local[order[2]];
    const double w[4] = {1 - l0, l0 - l1, l1 - l2, l2};
    for (int k = 0; k < 4; ++k) {
      m.tie_node(i, k) = m.cubes(q, t[static_cast<size_t>(k)]);
      m.tie_weight(i, k) = w[k];
    }
    m.tie_k[i] = kappa * area_vectors.row(i).norm();
  }
  // A node of almost no area beside larger ones (a sliver's) would be tied by almost no
  // spring, and the fluid's pressure, which moves a free node by its current area over its
  // tie, would carry it off as its triangles grow: its tie is at least that of a tenth of its
  // largest neighbour's area. (A regular or smoothly graded mesh's nodes are all above it.)
  const Vec norm = area_vectors.rowwise().norm();
  Vec largest = Vec::Zero(ns);
  for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) largest[s.triangles(t, a)] = std::max(largest[s.triangles(t, a)], norm[s.triangles(t, b)]);
  for (int i = 0; i < ns; ++i) m.tie_k[i] = std::max(m.tie_k[i], 0.1 * kappa * largest[i]);
  // The core's matrix: 2 mu f_c h (unit cube's sum of V G G^T) per cube.
  const Eigen::Matrix<double, 8, 8>& cube_K = unit_cube().K;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(kept.size() * 64 + static_cast<size_t>(ns) * 16);
  for (Eigen::Index q = 0; q < m.cubes.rows(); ++q) {
    const double scale = 2 * m.mu * m.fill[q] * h;
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b)
        if (cube_K(a, b) != 0) trip.emplace_back(m.cubes(q, a), m.cubes(q, b), scale * cube_K(a, b));
  }
  // Structural zeros where a tie couples two lattice nodes that the cubes' matrix does not (a
  // Kuhn tet's edges at right angles carry no stiffness): a factor made with some ties then
  // has the pattern its symbolic analysis, done once for every tie set, saw.
  for (int i = 0; i < ns; ++i)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) trip.emplace_back(m.tie_node(i, a), m.tie_node(i, b), 0.0);
  m.K_core.resize(ng, ng);
  m.K_core.setFromTriplets(trip.begin(), trip.end());
  m.fixed = def.fixed.rows() == ns ? def.fixed : FlagMat::Zero(ns, 3);
  if (def.use_gravity) {
    if (!(def.density > 0)) return error = "elastic core: density must be > 0 with gravity", false;
    m.gravity_load = NodeMat::Zero(ng, 3);
    for (Eigen::Index q = 0; q < m.cubes.rows(); ++q)
      for (int a = 0; a < 8; ++a)
        m.gravity_load.row(m.cubes(q, a)) += (def.density * m.fill[q] * h * h * h / 8) * def.gravity.transpose();
  }
  if (def.use_inertia) {
    if (!(def.density > 0)) return error = "elastic core: density must be > 0 with inertia", false;
    if (!(def.dt > 0)) return error = "elastic core: the time step must be > 0 with inertia", false;
    if (!(def.damping >= 0)) return error = "elastic core: damping must be >= 0", false;
    m.mass = Vec::Zero(ng);
    for (Eigen::Index q = 0; q < m.cubes.rows(); ++q)
      for (int a = 0; a < 8; ++a) m.mass[m.cubes(q, a)] += def.density * m.fill[q] * h * h * h / 8;
    m.dt = def.dt;
    m.inertia_rate = 1 / (def.dt * def.dt) + def.damping / def.dt;
  }
  return true;
}

}  // namespace vdm::core
