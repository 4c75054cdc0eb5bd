// Constraints on the elastic core without refactorising (engine/core/core_workspace.hpp).
//
// The lattice's factor holds the organ's own fixed entries. Any other prescribed entry p (a
// node held by kinematic contact or a grasp) is left free in the factored system and given a
// force r_p. With the volume row, a free entry moves by
//   u = u_0 + (C0 - h h^T / den) r,   C0_pq = W_p K_d^-1 W_q^T + delta_pq / k_p (same axis),
// where h_p = W_p K_d^-1 a_d + A_p / k_p is its motion under the fluid's pressure and den the
// volume row's own compliance; holding the entries on their targets is a dense solve of the
// size of the held set. C0 changes only with the set or the factor, so it is factorised once
// and the volume row's rank-one term taken by Sherman-Morrison at every iteration. The same
// columns of K^-1 give constraint contact the organ's exact compliance at its contact points.
#include <algorithm>

#include "engine/core/core_workspace.hpp"

namespace vdm::core {

void LatticeColumns::clear() {
  for (int j : node) slot[static_cast<size_t>(j)] = -1;
  node.clear();
  batch.clear();
  count = 0;
}

void ensure_columns(const CoreModel& m, int d, const std::vector<int>& nodes, CoreWorkspace& w) {
  LatticeColumns& c = w.columns[w.slot[d]];
  if (c.slot.size() != static_cast<size_t>(m.ng)) c.slot.assign(static_cast<size_t>(m.ng), -1);
  const int before = c.count;
  for (int i : nodes)
    for (int p = 0; p < 4; ++p) {
      const int j = m.tie_node(i, p);
      if (c.slot[static_cast<size_t>(j)] >= 0) continue;
      c.slot[static_cast<size_t>(j)] = c.count++;
      c.node.push_back(j);
    }
  solve_columns(m, w.slot[d], before, w);
}

void solve_columns(const CoreModel& m, int k, int before, CoreWorkspace& w) {
  LatticeColumns& c = w.columns[k];
  const int added = c.count - before;
  if (added == 0) return;
  if (c.cols.cols() < c.count) {  // grow with headroom, keeping the columns solved
    Eigen::MatrixXd grown(m.ng, std::max<Eigen::Index>(2 * c.cols.cols(), c.count + 32));
    if (before > 0) grown.leftCols(before) = c.cols.leftCols(before);
    c.cols.swap(grown);
  }
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(m.ng, added);
  for (int q = 0; q < added; ++q) unit(c.node[static_cast<size_t>(before + q)], q) = 1.0;
  c.cols.middleCols(before, added) = w.chol[k].solve(unit);
  c.batch.push_back(added);
}

double tied_compliance(const CoreModel& m, const LatticeColumns& c, int i, int j) {
  double sum = 0;
  for (int q = 0; q < 4; ++q) {
    const auto col = c.cols.col(c.slot[static_cast<size_t>(m.tie_node(j, q))]);
    sum += m.tie_weight(j, q) * tied_at(m, col, i);
  }
  return sum;
}

namespace {

// C0 between entries (i, d) and (j, e): the lattice's response through the ties, and the
// tie's own compliance on the diagonal.
double entry_compliance(const CoreModel& m, const CoreWorkspace& w, int i, int d, int j, int e) {
  if (d != e) return 0.0;
  return tied_compliance(m, w.columns[w.slot[d]], i, j) + (i == j ? 1.0 / m.tie_k[i] : 0.0);
}

}  // namespace

bool prepare_held_entries(const CoreModel& m, CoreWorkspace& w) {
  HeldEntries& H = w.held;
  // The set: prescribed entries the factor does not hold, by node then axis.
  bool same = true;
  int n = 0;
  for (int i = 0; i < m.ns; ++i)
    for (int d = 0; d < 3; ++d) {
      if (!w.mask(i, d) || w.factored_mask(i, d)) continue;
      same = same && n < H.size() && H.node[static_cast<size_t>(n)] == i && H.axis[static_cast<size_t>(n)] == d;
      ++n;
    }
  same = same && n == H.size();
  if (same && H.factored) return true;
  H.node.clear();
  H.axis.clear();
  for (int i = 0; i < m.ns; ++i)
    for (int d = 0; d < 3; ++d)
      if (w.mask(i, d) && !w.factored_mask(i, d)) {
        H.node.push_back(i);
        H.axis.push_back(d);
      }
  H.factored = false;
  if (n == 0) return true;
  for (int d = 0; d < 3; ++d) {
    std::vector<int> on_axis;
    for (int p = 0; p < n; ++p)
      if (H.axis[static_cast<size_t>(p)] == d) on_axis.push_back(H.node[static_cast<size_t>(p)]);
    if (!on_axis.empty()) ensure_columns(m, d, on_axis, w);
  }
  H.C0.resize(n, n);
  for (int p = 0; p < n; ++p)
    for (int q = 0; q <= p; ++q)
      H.C0(p, q) = H.C0(q, p) = entry_compliance(m, w, H.node[static_cast<size_t>(p)], H.axis[static_cast<size_t>(p)],
                                                  H.node[static_cast<size_t>(q)], H.axis[static_cast<size_t>(q)]);
  return factor_held_entries(H);
}

bool factor_held_entries(HeldEntries& H) {
  const int n = H.size();
  H.C0_factor.compute(H.C0);
  H.factored = H.C0_factor.info() == Eigen::Success && H.C0_factor.isPositive();
  H.rhs.resize(n);
  H.h.resize(n);
  H.z.resize(n);
  H.y.resize(n);
  H.r = Vec::Zero(n);
  return H.factored;
}

void add_held_response(const CoreModel& m, const CoreWorkspace& w, int d, Eigen::Ref<Vec> v) {
  const HeldEntries& H = w.held;
  const LatticeColumns& c = w.columns[w.slot[d]];
  for (int p = 0; p < H.size(); ++p) {
    if (H.axis[static_cast<size_t>(p)] != d || H.r[p] == 0.0) continue;
    const int i = H.node[static_cast<size_t>(p)];
    for (int q = 0; q < 4; ++q)
      v += (H.r[p] * m.tie_weight(i, q)) * c.cols.col(c.slot[static_cast<size_t>(m.tie_node(i, q))]);
  }
}

void surface_compliance(const CoreModel& m, CoreWorkspace& w, const std::vector<int>& nodes, Eigen::MatrixXd& C) {
  const int n = static_cast<int>(nodes.size());
  C.setZero(3 * n, 3 * n);
  // The free entries among the nodes' (neither factored nor held).
  std::vector<int> row_of, node_of, axis_of;
  for (int a = 0; a < n; ++a)
    for (int d = 0; d < 3; ++d) {
      const int i = nodes[static_cast<size_t>(a)];
      if (w.mask(i, d)) continue;
      row_of.push_back(3 * a + d);
      node_of.push_back(i);
      axis_of.push_back(d);
    }
  const int f = static_cast<int>(row_of.size());
  if (f == 0) return;
  for (int d = 0; d < 3; ++d) ensure_columns(m, d, nodes, w);
  // h: the entries' motion under a unit volume multiplier.
  auto volume_response = [&](int i, int d) {
    return tied_at(m, w.response.col(d), i) + w.area(i, d) / m.tie_k[i];
  };
  const bool volume = w.den > 0.0;
  Vec hN(f);
  for (int k = 0; k < f; ++k) hN[k] = volume ? volume_response(node_of[static_cast<size_t>(k)], axis_of[static_cast<size_t>(k)]) : 0.0;
  Eigen::MatrixXd G(f, f);
  for (int k = 0; k < f; ++k)
    for (int l = 0; l <= k; ++l)
      G(k, l) = G(l, k) = entry_compliance(m, w, node_of[static_cast<size_t>(k)], axis_of[static_cast<size_t>(k)],
                                           node_of[static_cast<size_t>(l)], axis_of[static_cast<size_t>(l)]) -
                          (volume ? hN[k] * hN[l] / w.den : 0.0);
  // Held entries held: G - B M^-1 B^T, M = C0 - h h^T / den (Sherman-Morrison on C0's factor).
  const HeldEntries& H = w.held;
  if (H.size() > 0 && H.factored) {
    const int P = H.size();
    Vec hP(P);
    for (int p = 0; p < P; ++p) hP[p] = volume ? volume_response(H.node[static_cast<size_t>(p)], H.axis[static_cast<size_t>(p)]) : 0.0;
    Eigen::MatrixXd B(f, P);
    for (int k = 0; k < f; ++k)
      for (int p = 0; p < P; ++p)
        B(k, p) = entry_compliance(m, w, node_of[static_cast<size_t>(k)], axis_of[static_cast<size_t>(k)],
                                   H.node[static_cast<size_t>(p)], H.axis[static_cast<size_t>(p)]) -
                  (volume ? hN[k] * hP[p] / w.den : 0.0);
    Eigen::MatrixXd X = H.C0_factor.solve(B.transpose());  // P x f
    if (volume) {
      const Vec y = H.C0_factor.solve(hP);
      const double denom = w.den - hP.dot(y);
      if (denom > 0.0) X += y * ((hP.transpose() * X) / denom);
    }
    G.noalias() -= B * X;
  }
  for (int k = 0; k < f; ++k)
    for (int l = 0; l < f; ++l) C(row_of[static_cast<size_t>(k)], row_of[static_cast<size_t>(l)]) = G(k, l);
}

void surface_compliance(const CoreModel& m, CoreState& s, const std::vector<int>& nodes, Eigen::MatrixXd& C) {
  surface_compliance(m, *s.work, nodes, C);
}

}  // namespace vdm::core
