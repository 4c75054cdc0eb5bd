#include "engine/organ_pair_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include <Eigen/Cholesky>

#include "engine/geometry.hpp"
#include "engine/organ_solver.hpp"
#include "engine/snapshot_bytes.hpp"

namespace vdm {

namespace {
// The most cells a surface's grid has (its cells grow to stay under it).
constexpr double kMostCells = 1 << 20;
// Gauss-Seidel sweeps at most, and the motion a sweep's change predicts that ends them (as a
// share of the finest surface's mean edge).
constexpr int kSweeps = 50;
constexpr double kSweepMotion = 1e-7;
// A surface's grid is kept while its nodes move at most this far (m) from where it was built:
// each triangle is binned by its box grown by as much. Rebuilt at every pass, it took most of
// the joint step's contact search (a 2.5k liver's grid under a gallbladder, 20 rounds a step).
constexpr double kGridSlack = 1e-3;
constexpr double kSixth = 1.0 / 6.0;  // distributed_area_vectors' share of a triangle's corner
// The grid cell holding point p (clamped to the grid), and its index.
template <class G>
Eigen::Array3i cell_in(const G& g, const Eigen::Array3d& p) {
  return ((p - g.lo.array()) / g.cell).floor().template cast<int>().max(0).min(g.dims - 1).eval();
}
template <class G>
size_t cell_index(const G& g, const Eigen::Array3i& c) {
  return static_cast<size_t>((c.z() * g.dims.y() + c.y()) * g.dims.x() + c.x());
}
}  // namespace

void OrganPairContact::measure(Point& point, const Vec3& p, const NodeMat& x_other, const TriMat& t_other) {
  // The normal interpolated from the triangle's vertex normals: it turns continuously from one
  // triangle to the next, so that a point near an edge or a corner (where two balls' nodes
  // meet, nearly always) is not pushed one way and then another as its closest triangle
  // changes between iterations. The gap is measured along it.
  Vec3 normal = Vec3::Zero(), q = Vec3::Zero();
  for (int v = 0; v < 3; ++v) {
    normal += point.weight[v] * normal_at(point.other, point.corner[v], x_other, t_other);
    q += point.weight[v] * x_other.row(point.corner[v]).transpose();
  }
  point.normal = normal.norm() > 0 ? Vec3(normal.normalized()) : Vec3::UnitZ();
  point.gap = (p - q).dot(point.normal);
}

Vec3 OrganPairContact::normal_at(int j, int v, const NodeMat& x, const TriMat& t) {
  const size_t o = static_cast<size_t>(j);
  std::vector<int>& start = ring_start_[o];
  std::vector<int>& ring = ring_[o];
  if (start.empty()) {  // each node's triangles in ascending order (counted, then filled)
    start.assign(static_cast<size_t>(x.rows()) + 1, 0);
    for (Eigen::Index f = 0; f < t.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++start[static_cast<size_t>(t(f, k)) + 1];
    for (size_t i = 0; i + 1 < start.size(); ++i) start[i + 1] += start[i];
    ring.resize(static_cast<size_t>(start.back()));
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (Eigen::Index f = 0; f < t.rows(); ++f)
      for (int k = 0; k < 3; ++k) ring[static_cast<size_t>(fill[static_cast<size_t>(t(f, k))]++)] = static_cast<int>(f);
    normals_[o].resize(x.rows(), 3);
    normal_call_[o].assign(static_cast<size_t>(x.rows()), -1);
  }
  const size_t i = static_cast<size_t>(v);
  if (normal_call_[o][i] != call_) {
    // distributed_area_vectors' sum at v: its triangles' (b - a) x (c - a) in their order,
    // times a sixth; then of unit length.
    Vec3 n = Vec3::Zero();
    for (int e = start[i]; e < start[i + 1]; ++e) {
      const Eigen::Index f = ring[static_cast<size_t>(e)];
      const Vec3 a = x.row(t(f, 0));
      n += (Vec3(x.row(t(f, 1))) - a).cross(Vec3(x.row(t(f, 2))) - a);
    }
    n *= kSixth;
    const double l = n.norm();
    if (l > 0) n /= l;
    normals_[o].row(v) = n.transpose();
    normal_call_[o][i] = call_;
  }
  return normals_[o].row(v).transpose();
}

void OrganPairContact::build_grid(const NodeMat& x, const TriMat& t, double reach, Grid& g) {
  g.lo = x.colwise().minCoeff().transpose();
  g.hi = x.colwise().maxCoeff().transpose();
  double edges = 0;
  for (Eigen::Index f = 0; f < t.rows(); ++f) edges += (x.row(t(f, 1)) - x.row(t(f, 0))).norm();
  // Cells one and a half mean edges wide (at least twice the reach): a node near the surface
  // finds its closest triangle among the 27 cells around it (three edges wide, the search
  // took half as long again).
  g.cell = std::max(1.5 * edges / double(t.rows()), 2 * reach);
  const Vec3 span = g.hi - g.lo;
  while (((span / g.cell).array().floor() + 1).prod() > kMostCells) g.cell *= 1.5;
  g.dims = ((span / g.cell).array().floor() + 1).cast<int>();
  // Each triangle in every cell its box, grown by kGridSlack, meets; the cells' lists one
  // after another in `items` (counted, then filled): flat arrays, grown with a quarter to
  // spare and never shrunk, so that a warm step allocates nothing.
  const size_t cell_count = static_cast<size_t>(g.dims.prod());
  const auto for_each_cell = [&](Eigen::Index f, auto&& visit) {
    Vec3 flo = x.row(t(f, 0)).transpose(), fhi = flo;
    for (int k = 1; k < 3; ++k) {
      flo = flo.cwiseMin(x.row(t(f, k)).transpose());
      fhi = fhi.cwiseMax(x.row(t(f, k)).transpose());
    }
    const Eigen::Array3i a = cell_in(g, flo.array() - kGridSlack), b = cell_in(g, fhi.array() + kGridSlack);
    for (int cz = a.z(); cz <= b.z(); ++cz)
      for (int cy = a.y(); cy <= b.y(); ++cy)
        for (int cx = a.x(); cx <= b.x(); ++cx) visit(cell_index(g, {cx, cy, cz}));
  };
  if (g.start.capacity() < cell_count + 1) g.start.reserve(cell_count + 1 + cell_count / 4);
  g.start.assign(cell_count + 1, 0);
  for (Eigen::Index f = 0; f < t.rows(); ++f) for_each_cell(f, [&](size_t c) { ++g.start[c + 1]; });
  for (size_t c = 0; c < cell_count; ++c) g.start[c + 1] += g.start[c];
  const size_t items = static_cast<size_t>(g.start[cell_count]);
  if (g.items.capacity() < items) g.items.reserve(items + items / 4);
  g.items.resize(items);
  if (g.fill.capacity() < cell_count) g.fill.reserve(cell_count + cell_count / 4);
  g.fill.assign(g.start.begin(), g.start.end() - 1);
  for (Eigen::Index f = 0; f < t.rows(); ++f)
    for_each_cell(f, [&](size_t c) { g.items[static_cast<size_t>(g.fill[c]++)] = static_cast<int>(f); });
  g.built = x;
  g.valid = true;
}

OrganPairContact::OrganPairContact(const std::vector<int>& nodes, const std::vector<double>& edge, double friction,
                                   std::vector<OrganTie> ties)
    : nodes_(nodes), edge_(edge), friction_(friction), ties_(std::move(ties)) {
  const size_t n = nodes.size();
  lambda_.resize(n);
  pressed_.resize(n);
  applied_.resize(n);
  start_.resize(n);
  node_slot_.resize(n);
  node_list_.resize(n);
  compliance_.resize(n);
  compliance_nodes_.resize(n);
  compliance_valid_.assign(n, 0);
  predicted_.resize(n);
  normals_.resize(n);
  ring_start_.resize(n);
  ring_.resize(n);
  normal_call_.resize(n);
  grids_.resize(n);
  for (size_t o = 0; o < n; ++o) {
    lambda_[o].assign(static_cast<size_t>(nodes[o]), Vec3::Zero());
    pressed_[o].assign(static_cast<size_t>(nodes[o]), 0);
    node_slot_[o].assign(static_cast<size_t>(nodes[o]), -1);
  }
  tie_lambda_.assign(ties_.size(), Vec3::Zero());
  tie_torn_.assign(ties_.size(), 0);
}

bool OrganPairContact::slave(int i, int j) const {
  // Surfaces whose mean edges differ by round-off only (the same mesh placed twice) are equal:
  // the earlier organ's nodes are then held out of the later one.
  const double a = edge_[static_cast<size_t>(i)], b = edge_[static_cast<size_t>(j)];
  const bool same = std::abs(a - b) <= 1e-9 * std::max(a, b);
  return i != j && (same ? i < j : a < b);
}

void OrganPairContact::begin_step(const std::vector<const NodeMat*>& start) {
  points_.clear();
  for (size_t o = 0; o < start.size() && o < start_.size(); ++o) start_[o] = *start[o];
  for (NodeMat& a : applied_) a.setZero();
  std::fill(compliance_valid_.begin(), compliance_valid_.end(), 0);
  for (Grid& g : grids_) g.valid = false;
}

void OrganPairContact::find_points(const std::vector<const NodeMat*>& x, const std::vector<const TriMat*>& triangles,
                                   double reach) {
  x_ = x;
  while (!points_.empty() && points_.back().tie >= 0) points_.pop_back();
  // The step's points so far stay (measured again on their triangle): a node pushed out of
  // reach by one correction keeps its place in the next, where its force can fall to zero.
  const size_t kept = points_.size();
  measured_.assign(kept, 0);
  std::vector<char>& measured = measured_;
  for (const Point& p : points_) node_slot_[static_cast<size_t>(p.owner)][static_cast<size_t>(p.node)] = static_cast<int>(&p - points_.data());
  const int organs = static_cast<int>(x.size());
  ++call_;
  for (int j = 0; j < organs; ++j) {
    const NodeMat& xj = *x[j];
    const TriMat& tj = *triangles[j];
    if (tj.rows() == 0) continue;
    bool master = false;
    for (int i = 0; i < organs && !master; ++i) master = slave(i, j);
    if (!master) continue;
    Grid& g = grids_[static_cast<size_t>(j)];
    if (!g.valid || g.built.rows() != xj.rows() || (xj - g.built).cwiseAbs().maxCoeff() > kGridSlack)
      build_grid(xj, tj, reach, g);
    // Nodes within reach of the surface's box now.
    const Vec3 lo = xj.colwise().minCoeff().transpose() - Vec3::Constant(reach);
    const Vec3 hi = xj.colwise().maxCoeff().transpose() + Vec3::Constant(reach);
    for (int i = 0; i < organs; ++i) {
      if (!(slave(i, j))) continue;
      const NodeMat& xi = *x[i];
      for (Eigen::Index k = 0; k < xi.rows(); ++k) {
        const Vec3 p = xi.row(k).transpose();
        if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
        const Eigen::Array3i c = cell_in(g, p.array());
        double best = std::numeric_limits<double>::infinity();
        Point point;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const Eigen::Array3i n = c + Eigen::Array3i(dx, dy, dz);
              if ((n < 0).any() || (n >= g.dims).any()) continue;
              const size_t cn = cell_index(g, n);
              for (int e = g.start[cn]; e < g.start[cn + 1]; ++e) {
                const int f = g.items[static_cast<size_t>(e)];
                const Vec3 a = xj.row(tj(f, 0)), b = xj.row(tj(f, 1)), cc = xj.row(tj(f, 2));
                // No nearer than the triangle's box: a triangle whose box is farther than the
                // nearest found so far is passed over (by a margin beyond round-off, so that
                // the triangle chosen is the one the full search chooses).
                const Eigen::Array3d below = a.array().min(b.array()).min(cc.array()) - p.array();
                const Eigen::Array3d above = p.array() - a.array().max(b.array()).max(cc.array());
                const double box = below.max(above).max(0.0).square().sum();
                if (box > best * (1 + 1e-9) + 1e-18) continue;
                const Vec3 w = closest_barycentric(p, a, b, cc);
                const Vec3 q = w.x() * a + w.y() * b + w.z() * cc;
                const double d = (p - q).squaredNorm();
                if (d >= best) continue;
                best = d;
                point.triangle = f;
                for (int v = 0; v < 3; ++v) {
                  point.corner[v] = tj(f, v);
                  point.weight[v] = w[v];
                }
              }
            }
        if (!(best < std::numeric_limits<double>::infinity())) continue;
        measure(point, p, xj, tj);
        point.owner = i;
        point.node = static_cast<int>(k);
        point.other = j;
        const int at = node_slot_[static_cast<size_t>(i)][static_cast<size_t>(k)];
        if (at >= 0 && static_cast<size_t>(at) < kept && points_[static_cast<size_t>(at)].other == j) {
          points_[static_cast<size_t>(at)] = point;
          measured[static_cast<size_t>(at)] = 1;
        } else if (point.gap <= reach) {
          points_.push_back(point);
        }
      }
    }
  }
  for (size_t k = 0; k < kept; ++k) {
    Point& p = points_[k];
    node_slot_[static_cast<size_t>(p.owner)][static_cast<size_t>(p.node)] = -1;
    if (measured[k]) continue;
    const NodeMat& xo = *x[static_cast<size_t>(p.other)];
    const Vec3 at = (*x[static_cast<size_t>(p.owner)]).row(p.node).transpose();
    const Vec3 w = closest_barycentric(at, xo.row(p.corner[0]), xo.row(p.corner[1]), xo.row(p.corner[2]));
    for (int v = 0; v < 3; ++v) p.weight[v] = w[v];
    measure(p, at, xo, *triangles[static_cast<size_t>(p.other)]);
  }
  // A node no longer in contact holds no force.
  for (size_t o = 0; o < lambda_.size(); ++o)
    for (size_t k = 0; k < lambda_[o].size(); ++k)
      if (!lambda_[o][k].isZero(0)) node_slot_[o][k] = -2;  // has a force
  for (const Point& p : points_) node_slot_[static_cast<size_t>(p.owner)][static_cast<size_t>(p.node)] = -1;
  for (size_t o = 0; o < lambda_.size(); ++o)
    for (size_t k = 0; k < lambda_[o].size(); ++k)
      if (node_slot_[o][k] == -2) {
        lambda_[o][k].setZero();
        node_slot_[o][k] = -1;
      }
  // The ties that hold.
  for (size_t t = 0; t < ties_.size(); ++t) {
    if (tie_torn_[t]) continue;
    const OrganTie& tie = ties_[t];
    Point p;
    p.owner = tie.owner;
    p.node = tie.node;
    p.other = tie.other;
    for (int v = 0; v < 3; ++v) {
      p.corner[v] = tie.corner[v];
      p.weight[v] = tie.weight[v];
    }
    p.tie = static_cast<int>(t);
    points_.push_back(p);
  }
}



void OrganPairContact::reserve_scratch(size_t points, size_t ties) {
  // Grown with a quarter to spare (a slowly growing contact is not reallocated at every new
  // point; W, dense, is the most memory: 3n x 3n), never shrunk.
  const auto spare = [](auto n) { return n + n / 4; };
  if (entries_.size() < points) {
    entries_.resize(spare(points));
    residual_.resize(spare(points));
    frame_.resize(spare(points));
    normal_inverse_.resize(spare(points));
    tangent_inverse_.resize(spare(points));
  }
  const Eigen::Index N = static_cast<Eigen::Index>(3 * points), T = static_cast<Eigen::Index>(3 * ties);
  if (W_.rows() < N) W_.resize(spare(N), spare(N));
  if (tie_block_.rows() < T) tie_block_.resize(spare(T), spare(T));
  for (Eigen::VectorXd* v : {&lambda_scratch_, &moved_, &tie_moved_})
    if (v->size() < N) v->resize(spare(N));
  for (Eigen::VectorXd* v : {&tie_rhs_, &tie_next_, &tie_residual_})
    if (v->size() < T) v->resize(spare(T));
}

bool OrganPairContact::correct(const std::vector<OrganSolver*>& solvers, double& violation, double& change) {
  violation = 0;
  change = 0;
  const size_t n = points_.size();
  if (n == 0) return true;
  // The contact points come first, the ties after them (find_points()).
  size_t contacts = 0;
  while (contacts < n && points_[contacts].tie < 0) ++contacts;
  reserve_scratch(n, n - contacts);
  // The nodes each organ's compliance is needed at: the points' own nodes and their triangles'.
  const auto slot = [&](int organ, int node) {
    int& s = node_slot_[static_cast<size_t>(organ)][static_cast<size_t>(node)];
    if (s < 0) {
      s = static_cast<int>(node_list_[static_cast<size_t>(organ)].size());
      node_list_[static_cast<size_t>(organ)].push_back(node);
    }
    return s;
  };
  for (auto& l : node_list_) l.clear();
  // Each point's entries: (organ, slot, coefficient) of its node's motion relative to its point
  // on the other surface.
  for (size_t p = 0; p < n; ++p) {
    const Point& q = points_[p];
    entries_[p][0] = {q.owner, slot(q.owner, q.node), 1.0};
    for (int v = 0; v < 3; ++v) entries_[p][v + 1] = {q.other, slot(q.other, q.corner[v]), -q.weight[v]};
  }
  bool ok = true;
  // An organ's compliance at the same nodes is kept through the step (begin_step drops it): it
  // is only the contact's model of how the organs answer, and the elastic core's hardly moves
  // within a step (its lattice's factor is fixed; only its volume row's area vectors follow the
  // surface). Asked for afresh after each of the organ's solves, it took 4 % of the
  // gallbladder scene's time, and the rounds with a step's one compliance were 7 % fewer.
  for (size_t o = 0; o < node_list_.size() && ok; ++o) {
    if (node_list_[o].empty() || (compliance_valid_[o] && compliance_nodes_[o] == node_list_[o])) continue;
    if (solvers[o]) {
      ok = solvers[o]->surface_compliance(node_list_[o], compliance_[o]);
    } else {  // an organ that does not yield
      const Eigen::Index m = 3 * static_cast<Eigen::Index>(node_list_[o].size());
      compliance_[o].setZero(m, m);
    }
    compliance_nodes_[o] = node_list_[o];
    compliance_valid_[o] = ok;
  }
  for (size_t o = 0; o < node_list_.size(); ++o)
    for (int node : node_list_[o]) node_slot_[o][static_cast<size_t>(node)] = -1;
  if (!ok) return false;
  // W (3n x 3n): how far point p's node moves relative to its point on the other surface under
  // a unit force at point q (on q's node, and the opposite on q's triangle).
  const Eigen::Index N = static_cast<Eigen::Index>(3 * n);
  auto W = W_.topLeftCorner(N, N);
  for (size_t p = 0; p < n; ++p)
    for (size_t q = 0; q <= p; ++q) {
      Eigen::Matrix3d w = Eigen::Matrix3d::Zero();
      for (const Entry& a : entries_[p])
        for (const Entry& b : entries_[q]) {
          if (a.organ != b.organ || a.c == 0.0 || b.c == 0.0) continue;
          w += (a.c * b.c) * compliance_[static_cast<size_t>(a.organ)].block<3, 3>(3 * a.slot, 3 * b.slot);
        }
      W.block<3, 3>(3 * static_cast<Eigen::Index>(p), 3 * static_cast<Eigen::Index>(q)) = w;
      W.block<3, 3>(3 * static_cast<Eigen::Index>(q), 3 * static_cast<Eigen::Index>(p)) = w.transpose();
    }
  // Each point's residual motion at the forces it was solved with: contact, (gap, slip over
  // the step relative to the other surface); tie, its stretch from its rest offset.
  auto lambda = lambda_scratch_.head(N);
  auto moved = moved_.head(N);
  moved.setZero();
  for (size_t p = 0; p < n; ++p) {
    const Point& q = points_[p];
    lambda.segment<3>(3 * static_cast<Eigen::Index>(p)) = force_of(q);
    const NodeMat &xo = *x_[static_cast<size_t>(q.owner)], &xt = *x_[static_cast<size_t>(q.other)];
    const NodeMat &so = start_[static_cast<size_t>(q.owner)], &st = start_[static_cast<size_t>(q.other)];
    Vec3 at = xo.row(q.node).transpose(), motion = (xo.row(q.node) - so.row(q.node)).transpose();
    for (int v = 0; v < 3; ++v) {
      at -= q.weight[v] * xt.row(q.corner[v]).transpose();
      motion -= q.weight[v] * (xt.row(q.corner[v]) - st.row(q.corner[v])).transpose();
    }
    if (q.tie >= 0) {
      residual_[p] = at - ties_[static_cast<size_t>(q.tie)].offset;
    } else {
      residual_[p] = motion - q.normal.dot(motion) * q.normal;  // the slip (tangential)
      residual_[p] += q.gap * q.normal;
      violation = std::max(violation, -q.gap);
    }
  }
  // The tangent basis at each contact point, and its friction: only points pressed at the
  // step's start hold by friction.
  for (size_t p = 0; p < n; ++p) {
    const Vec3 nrm = points_[p].normal;
    const Vec3 t1 = (std::abs(nrm.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(nrm).normalized();
    frame_[p].col(0) = nrm;
    frame_[p].col(1) = t1;
    frame_[p].col(2) = nrm.cross(t1);
  }
  const Eigen::Index C3 = static_cast<Eigen::Index>(3 * contacts), T3 = N - C3;
  // The diagonal blocks' inverses in each contact point's frame (normal, then tangential).
  for (size_t p = 0; p < contacts; ++p) {
    const Eigen::Index b = 3 * static_cast<Eigen::Index>(p);
    const Eigen::Matrix3d F = frame_[p].transpose() * W.block<3, 3>(b, b) * frame_[p];
    normal_inverse_[p] = F(0, 0) > 0 ? 1.0 / F(0, 0) : 0.0;
    const Eigen::Matrix2d T = F.block<2, 2>(1, 1);
    tangent_inverse_[p] = T.determinant() > 0 ? Eigen::Matrix2d(T.inverse()) : Eigen::Matrix2d::Zero();
  }
  // The ties' block, W_tt + K^-1 (their springs' compliances), factorised in place: the ties
  // are solved together, exactly, in each sweep (one at a time, stiff ties that share a
  // triangle would take thousands of sweeps).
  auto tie_block = tie_block_.topLeftCorner(T3, T3);
  tie_block = W.bottomRightCorner(T3, T3);
  for (size_t p = contacts; p < n; ++p)
    tie_block.diagonal().segment<3>(3 * static_cast<Eigen::Index>(p) - C3).array() +=
        1.0 / ties_[static_cast<size_t>(points_[p].tie)].stiffness;
  Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> tie_factor(tie_block);
  if (T3 > 0 && tie_factor.info() != Eigen::Success) return false;
  auto tie_residual = tie_residual_.head(T3), tie_rhs = tie_rhs_.head(T3), tie_next = tie_next_.head(T3),
       tie_moved = tie_moved_.head(N);  // every point's motion under the ties' change
  for (size_t p = contacts; p < n; ++p) tie_residual.segment<3>(3 * static_cast<Eigen::Index>(p) - C3) = residual_[p];
  // Block Gauss-Seidel: the ties' stretch + moved + force / k zero (solved as one block), then
  // projected over the contact points: each gap + n.moved >= 0 with a pushing normal force
  // (complementary), each pressed point's slip + moved zero within the friction cone (else on
  // its rim). The sweeps end when none moves a point by more than a ten-millionth of the
  // finest surface's mean edge.
  const double motion_tolerance = kSweepMotion * *std::min_element(edge_.begin(), edge_.end());
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    double largest = 0;
    if (T3 > 0) {
      // (W_tt + K^-1) next = W_tt lambda_t - stretch - moved_t: the ties' answer with the
      // contact forces as they are.
      tie_rhs.noalias() = W.bottomRightCorner(T3, T3) * lambda.tail(T3);
      tie_rhs -= tie_residual + moved.tail(T3);
      tie_next = tie_rhs;
      tie_factor.solveInPlace(tie_next);
      tie_next -= lambda.tail(T3);
      lambda.tail(T3) += tie_next;
      tie_moved.noalias() = W.rightCols(T3) * tie_next;
      moved += tie_moved;
      largest = tie_moved.cwiseAbs().maxCoeff();
    }
    for (size_t p = 0; p < contacts; ++p) {
      const Eigen::Index b = 3 * static_cast<Eigen::Index>(p);
      const Point& q = points_[p];
      const Vec3 l = lambda.segment<3>(b);
      const Vec3 r = residual_[p] + moved.segment<3>(b);
      const Eigen::Matrix3d& F = frame_[p];
      const Vec3 lf = F.transpose() * l, rf = F.transpose() * r;
      const double ln = std::max(0.0, lf[0] - rf[0] * normal_inverse_[p]);
      Eigen::Vector2d lt = Eigen::Vector2d::Zero();
      const double mu = pressed_[static_cast<size_t>(q.owner)][static_cast<size_t>(q.node)] ? friction_ : 0.0;
      if (mu > 0 && ln > 0) {
        lt = lf.tail<2>() - tangent_inverse_[p] * rf.tail<2>();
        const double cap = mu * ln, size = lt.norm();
        if (size > cap) lt *= cap / size;
      }
      const Vec3 next = F * Vec3(ln, lt[0], lt[1]);
      const Vec3 d = next - l;
      if (d.isZero(0)) continue;
      lambda.segment<3>(b) = next;
      moved.noalias() += W.middleCols<3>(b) * d;
      largest = std::max(largest, (W.block<3, 3>(b, b) * d).cwiseAbs().maxCoeff());
    }
    if (largest <= motion_tolerance) break;
  }
  change = moved.cwiseAbs().maxCoeff();
  for (size_t p = 0; p < n; ++p) force_of(points_[p]) = lambda.segment<3>(3 * static_cast<Eigen::Index>(p));
  return true;
}

void OrganPairContact::add_forces(int organ, NodeMat& force) const {
  for (const Point& p : points_) {
    const Vec3& l = force_of(p);
    if (l.isZero(0)) continue;
    if (p.owner == organ) force.row(p.node) += l.transpose();
    if (p.other == organ)
      for (int v = 0; v < 3; ++v) force.row(p.corner[v]) -= p.weight[v] * l.transpose();
  }
}

void OrganPairContact::apply(int organ, NodeMat& force) {
  NodeMat& applied = applied_[static_cast<size_t>(organ)];
  if (applied.rows() != force.rows()) applied = NodeMat::Zero(force.rows(), 3);
  force -= applied;
  applied.setZero();
  add_forces(organ, applied);
  force += applied;
}

const NodeMat& OrganPairContact::predict(int organ, const NodeMat& answer) {
  const size_t o = static_cast<size_t>(organ);
  NodeMat& x = predicted_[o];
  x = answer;
  const NodeMat& applied = applied_[o];
  if (applied.rows() != answer.rows() || !compliance_valid_[o]) return x;
  pending_.setZero(answer.rows(), 3);
  add_forces(organ, pending_);
  // The forces change only at the points' nodes, which are the compliance's.
  const std::vector<int>& nodes = compliance_nodes_[o];
  const Eigen::Index k = static_cast<Eigen::Index>(nodes.size());
  if (force_change_.size() < 3 * k) force_change_.resize(3 * k + 3 * k / 4);
  auto force_change = force_change_.head(3 * k);
  for (Eigen::Index a = 0; a < k; ++a)
    force_change.segment<3>(3 * a) = (pending_.row(nodes[static_cast<size_t>(a)]) - applied.row(nodes[static_cast<size_t>(a)])).transpose();
  for (Eigen::Index a = 0; a < k; ++a)
    x.row(nodes[static_cast<size_t>(a)]) += (compliance_[o].middleRows<3>(3 * a) * force_change).transpose();
  return x;
}

void OrganPairContact::end_step() {
  for (auto& p : pressed_) std::fill(p.begin(), p.end(), 0);
  for (const Point& p : points_) {
    if (p.tie >= 0) continue;
    if (force_of(p).dot(p.normal) > 0) pressed_[static_cast<size_t>(p.owner)][static_cast<size_t>(p.node)] = 1;
  }
  for (size_t t = 0; t < ties_.size(); ++t)
    if (!tie_torn_[t] && tie_lambda_[t].norm() > ties_[t].tear) {
      tie_torn_[t] = 1;
      tie_lambda_[t].setZero();
    }
}

Vec3 OrganPairContact::contact_force(int organ) const {
  Vec3 sum = Vec3::Zero();
  for (const Point& p : points_) {
    if (p.tie >= 0) continue;
    if (p.owner == organ) sum += force_of(p);
    if (p.other == organ) sum -= force_of(p);
  }
  return sum;
}

Vec3 OrganPairContact::tie_force(int organ) const {
  Vec3 sum = Vec3::Zero();
  for (size_t t = 0; t < ties_.size(); ++t) {
    if (ties_[t].owner == organ) sum += tie_lambda_[t];
    if (ties_[t].other == organ) sum -= tie_lambda_[t];
  }
  return sum;
}

int OrganPairContact::torn() const { return static_cast<int>(std::count(tie_torn_.begin(), tie_torn_.end(), 1)); }

bool OrganPairContact::tied(int i, int j) const {
  for (size_t t = 0; t < ties_.size(); ++t)
    if (!tie_torn_[t] && ((ties_[t].owner == i && ties_[t].other == j) || (ties_[t].owner == j && ties_[t].other == i))) return true;
  return false;
}

double OrganPairContact::largest_tie_force() const {
  double largest = 0;
  for (const Vec3& l : tie_lambda_) largest = std::max(largest, l.norm());
  return largest;
}

void OrganPairContact::save_state(std::string& out) const {
  snapshot::Writer o(out);
  o.i64(static_cast<std::int64_t>(nodes_.size()));
  for (size_t k = 0; k < nodes_.size(); ++k) {
    o.i64(nodes_[k]);
    o.bytes(lambda_[k].data(), sizeof(Vec3) * lambda_[k].size());
    o.bytes(pressed_[k].data(), pressed_[k].size());
  }
  o.i64(static_cast<std::int64_t>(ties_.size()));
  o.bytes(tie_lambda_.data(), sizeof(Vec3) * tie_lambda_.size());
  o.bytes(tie_torn_.data(), tie_torn_.size());
}

bool OrganPairContact::load_state(std::string_view in, size_t& pos, std::string& error) {
  snapshot::Reader r(in, pos);
  std::int64_t organs = 0, ties = 0;
  if (!r.i64(organs) || organs != static_cast<std::int64_t>(nodes_.size())) {
    error = "state snapshot: the contact between organs is of another scene";
    return false;
  }
  for (size_t k = 0; k < nodes_.size(); ++k) {
    std::int64_t n = 0;
    if (!r.i64(n) || n != nodes_[k] || !r.bytes(lambda_[k].data(), sizeof(Vec3) * lambda_[k].size()) ||
        !r.bytes(pressed_[k].data(), pressed_[k].size())) {
      error = "state snapshot: the contact between organs is truncated or of another scene";
      return false;
    }
  }
  if (!r.i64(ties) || ties != static_cast<std::int64_t>(ties_.size()) ||
      !r.bytes(tie_lambda_.data(), sizeof(Vec3) * tie_lambda_.size()) || !r.bytes(tie_torn_.data(), tie_torn_.size())) {
    error = "state snapshot: the attachments' ties are truncated or of another scene";
    return false;
  }
  return true;
}

}  // namespace vdm
