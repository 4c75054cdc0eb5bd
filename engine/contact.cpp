#include "engine/contact.hpp"
#include "engine/organ_solver.hpp"
#include "engine/simd2.hpp"
#include "engine/step_workspace.hpp"
#include "engine/stopwatch.hpp"
#include "engine/warnings.hpp"

#include <fcl/fcl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace vdm {

double capsule_distance(const Capsule& c, const Vec3& x, Vec3& surface_point, Vec3& normal) {
  const Vec3 d = c.p1 - c.p0;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((x - c.p0).dot(d) / len2, 0.0, 1.0) : 0.0;
  const Vec3 axis_point = c.p0 + t * d;
  Vec3 r = x - axis_point;
  double dist = r.norm();
  if (dist < 1e-15) {  // on the axis: any direction perpendicular to it
    r = d.unitOrthogonal();
    dist = 0.0;
  } else {
    r /= dist;
  }
  normal = r;
  surface_point = axis_point + c.radius * r;
  return dist - c.radius;
}

Vec3 push_out(const ToolShape& t, const Vec3& x, const Vec3& relative, Vec3& dir) {
  const double m = relative.norm(), size = t.size();
  dir = m > 1e-9 * size ? Vec3(-relative / m) : Vec3(t.pose.linear().col(2));
  Vec3 nearest, nearest_normal, p, nrm;
  if (tool_distance(t, x, nearest, nearest_normal) >= 0.0) return x;
  // Along a ray from inside, the distance to a convex surface crosses zero once. The
  // bisection needs only the sign: for a capsule (the probe) it is taken with the pose's
  // inverse made once per ray and without the surface point and normal, the same operations
  // as tool_distance's on the way to the distance, so the same bits.
  const bool capsule = t.kind == ToolShape::Kind::capsule;
  const Eigen::Isometry3d to_shape = t.pose.inverse();
  auto inside = [&](const Vec3& y) {
    if (!capsule) return tool_distance(t, y, p, nrm) < 0.0;
    const Vec3 q = to_shape * y;
    const double h = t.half_size.z();
    const Vec3 r = q - Vec3(0, 0, std::clamp(q.z(), -h, h));
    return r.norm() - t.rounding < 0.0;
  };
  double lo = 0.0, hi = 2.0 * t.bound() + 2.0 * size;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (inside(x + mid * dir) ? lo : hi) = mid;
  }
  // A node that came in from behind (the surface springing back into a retreating tool)
  // would exit far away along the motion: put it on the nearest surface point instead.
  if (hi > 2.0 * size + m) {
    dir = nearest_normal;
    return nearest;
  }
  return x + hi * dir;
}

ToolShape to_tool(const Capsule& c) { return capsule_shape(c.p0, c.p1, c.radius, c.motion); }

Vec3 push_out(const Capsule& c, const Vec3& x, const Vec3& relative, Vec3& dir) {
  return push_out(to_tool(c), x, relative, dir);
}

struct ContactSolver::Fcl {
  std::shared_ptr<fcl::BVHModel<fcl::AABBd>> bvh;
  std::unique_ptr<fcl::CollisionObjectd> organ;
  std::vector<fcl::Vector3d> points;
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  // One FCL shape and object per tool slot, rebuilt only when the slot's kind or hull
  // changes; sizes and poses are updated in place (no allocation per query).
  struct Slot {
    ToolShape::Kind kind = ToolShape::Kind::capsule;
    const ConvexHull* hull = nullptr;
    std::shared_ptr<fcl::CollisionGeometryd> shape;
    std::unique_ptr<fcl::CollisionObjectd> object;
  };
  std::vector<Slot> slots;

  // The lazy refit's own copy of FCL's tree (same nodes, same order), its boxes in float
  // rounded outward: 28 bytes a node instead of FCL's 64, and FCL's model (its boxes,
  // vertices and triangles) is dropped once copied (-8 MB at 40k nodes). A float box holds
  // the double box it stands for, so the walk reaches every leaf it reached before, and the
  // leaves themselves are still tested exactly (the corners' double positions, below).
  struct Node {
    float lo[3], hi[3];
    int first_child;  // >= 0: the first of two adjacent children; < 0: -(triangle + 1)
  };
  std::vector<Node> nodes;

  // The lazy refit (ContactSettings::lazy_refit). FCL's refit fits each leaf to its
  // triangle's corners at the last two refits' positions (its `prev_vertices` and
  // `vertices`): `prev` and `last` here, so that the walk can keep exactly the leaves FCL's
  // refitted tree would give. The tree's boxes hold the node boxes [lo, hi] of their
  // triangles' corners, and every node's positions at the last two refits lie within
  // `slack` of its box: boxes grown by the slack hold every triangle FCL's boxes would.
  NodeMat prev, last, lo, hi;
  std::vector<int> node_triangles_start, node_triangles;  // triangles of each node (CSR)
  std::vector<int> leaf, parent, post_order;             // leaf of each triangle, parent of each BV node,
                                                          // the tree's nodes children first (the first refit's order; freed after it)
  std::vector<char> leaf_dirty;                           // per triangle
  std::vector<int> dirty;
  double slack = 0.0, margin = 0.0;  // margin: far above rounding, keeps the grown test conservative
  long box_updates = 0;  // tree boxes refitted so far (FCL's refit: all of them)
};

namespace {

std::shared_ptr<fcl::CollisionGeometryd> make_fcl_shape(const ToolShape& t) {
  switch (t.kind) {
    case ToolShape::Kind::capsule: return std::make_shared<fcl::Capsuled>(1.0, 1.0);
    case ToolShape::Kind::cylinder: return std::make_shared<fcl::Cylinderd>(1.0, 1.0);
    case ToolShape::Kind::box: return std::make_shared<fcl::Boxd>(1.0, 1.0, 1.0);
    case ToolShape::Kind::convex: {
      auto verts = std::make_shared<std::vector<fcl::Vector3d>>(t.hull->vertices.begin(), t.hull->vertices.end());
      auto faces = std::make_shared<std::vector<int>>();
      for (const auto& tri : t.hull->triangles) faces->insert(faces->end(), {3, tri[0], tri[1], tri[2]});
      return std::make_shared<fcl::Convexd>(verts, int(t.hull->triangles.size()), faces);
    }
  }
  return nullptr;
}

// Sizes the slot's shape to the tool inflated by `pad` (a convex hull is not inflated).
void size_fcl_shape(fcl::CollisionGeometryd& g, const ToolShape& t, double pad) {
  switch (t.kind) {
    case ToolShape::Kind::capsule: {
      auto& c = static_cast<fcl::Capsuled&>(g);
      c.radius = t.rounding + pad;
      c.lz = std::max(2.0 * t.half_size.z(), 1e-9);
      break;
    }
    case ToolShape::Kind::cylinder: {
      auto& c = static_cast<fcl::Cylinderd&>(g);
      c.radius = t.half_size.x() + pad;
      c.lz = 2.0 * (t.half_size.z() + pad);
      break;
    }
    case ToolShape::Kind::box:
      static_cast<fcl::Boxd&>(g).side = 2.0 * (t.half_size + Vec3::Constant(pad));
      break;
    case ToolShape::Kind::convex: break;
  }
  g.computeLocalAABB();
}

// The tool's oriented bounding box (world centre, axes = the pose's columns, half extents).
void tool_box(const ToolShape& t, double pad, Vec3& centre, Vec3& half) {
  Vec3 local = Vec3::Zero();
  half = Vec3::Zero();
  switch (t.kind) {
    case ToolShape::Kind::capsule: half = Vec3(t.rounding, t.rounding, t.half_size.z() + t.rounding); break;
    case ToolShape::Kind::cylinder:
    case ToolShape::Kind::box: half = t.half_size; break;
    case ToolShape::Kind::convex:
      local = 0.5 * (t.hull->lo + t.hull->hi);
      half = 0.5 * (t.hull->hi - t.hull->lo) + Vec3::Constant(t.rounding);
      break;
  }
  half += Vec3::Constant(pad);
  centre = t.pose * local;
}

// Whether an oriented box (centre c, rotation R, half extents h) and an axis-aligned box
// [lo, hi] may overlap: separating axes of both boxes (conservative: edge-edge axes skipped).
// `grow`: the axis-aligned box grown by this much on every side.
inline bool may_overlap(const Vec3& c, const Eigen::Matrix3d& R, const Vec3& h, const Vec3& lo, const Vec3& hi,
                        double grow = 0.0) {
  const Vec3 ac = 0.5 * (lo + hi), ah = 0.5 * (hi - lo) + Vec3::Constant(grow), d = c - ac;
  const Eigen::Matrix3d absR = R.cwiseAbs();
  for (int a = 0; a < 3; ++a)  // world axes
    if (std::abs(d[a]) > ah[a] + absR.row(a).dot(h)) return false;
  for (int b = 0; b < 3; ++b)  // the tool's axes
    if (std::abs(R.col(b).dot(d)) > h[b] + absR.col(b).dot(ah)) return false;
  return true;
}

// FCL's tree nodes (fcl/geometry/bvh/BV_node_base.h) and the lazy tree's copies of them:
// `first_child` >= 0 is the first of two adjacent children, < 0 is -(triangle + 1). (FCL's
// accessors are compiled in its library: a call per node.)
using BvNode = fcl::BVNode<fcl::AABBd>;
template <class N>
inline bool is_leaf(const N& n) {
  return n.first_child < 0;
}
template <class N>
inline int triangle_of(const N& n) {
  return -(n.first_child + 1);
}

// The float box [lo, hi] that holds the double box [a, b] (each bound rounded outward).
float round_down(double v) {
  float f = static_cast<float>(v);
  if (static_cast<double>(f) > v) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float round_up(double v) {
  float f = static_cast<float>(v);
  if (static_cast<double>(f) < v) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}
Vec3 to_vec3(const float* v) { return Vec3(double(v[0]), double(v[1]), double(v[2])); }

}  // namespace

ContactSolver::ContactSolver(const TissueModel& m, ContactSettings settings)
    : fcl_(std::make_unique<Fcl>()), settings_(settings), triangles_(&m.rest.triangles) {
  fcl_->bvh = std::make_shared<fcl::BVHModel<fcl::AABBd>>();
  std::vector<fcl::Triangle> tris;
  tris.reserve(static_cast<size_t>(m.rest.triangle_count()));
  for (int k = 0; k < m.rest.triangle_count(); ++k)
    tris.emplace_back(m.rest.triangles(k, 0), m.rest.triangles(k, 1), m.rest.triangles(k, 2));
  fcl_->points.resize(static_cast<size_t>(m.n));
  for (int i = 0; i < m.n; ++i) fcl_->points[i] = m.rest.positions.row(i).transpose();
  fcl_->bvh->beginModel(m.rest.triangle_count(), m.n);
  fcl_->bvh->addSubModel(fcl_->points, tris);
  fcl_->bvh->endModel();
  fcl_->organ = std::make_unique<fcl::CollisionObjectd>(fcl_->bvh);
  if (lazy()) {
    Fcl& f = *fcl_;
    const int T = m.rest.triangle_count();
    f.prev = f.last = f.lo = f.hi = m.rest.positions;  // before the first refit: the rest positions (FCL's too)
    f.node_triangles_start.assign(static_cast<size_t>(m.n) + 1, 0);
    for (int k = 0; k < T; ++k)
      for (int c = 0; c < 3; ++c) ++f.node_triangles_start[static_cast<size_t>(m.rest.triangles(k, c)) + 1];
    for (int i = 0; i < m.n; ++i) f.node_triangles_start[i + 1] += f.node_triangles_start[i];
    f.node_triangles.resize(3 * static_cast<size_t>(T));
    std::vector<int> fill(f.node_triangles_start.begin(), f.node_triangles_start.end() - 1);
    for (int k = 0; k < T; ++k)
      for (int c = 0; c < 3; ++c) f.node_triangles[fill[m.rest.triangles(k, c)]++] = k;
    const int nbv = f.bvh->getNumBVs();
    f.nodes.resize(static_cast<size_t>(nbv));
    for (int id = 0; id < nbv; ++id) f.nodes[static_cast<size_t>(id)].first_child = f.bvh->getBV(id).first_child;
    f.leaf.assign(static_cast<size_t>(T), -1);
    f.parent.assign(static_cast<size_t>(nbv), -1);
    f.post_order.clear();
    f.post_order.reserve(static_cast<size_t>(nbv));
    // Children before their parents (depth-first, each node after its subtree).
    std::vector<std::pair<int, bool>> todo{{0, false}};
    while (!todo.empty()) {
      const auto [id, expanded] = todo.back();
      todo.pop_back();
      const fcl::BVNode<fcl::AABBd>& node = f.bvh->getBV(id);
      if (node.isLeaf()) {
        f.leaf[node.primitiveId()] = id;
        f.post_order.push_back(id);
      } else if (expanded) {
        f.post_order.push_back(id);
      } else {
        todo.push_back({id, true});
        for (int child : {node.leftChild(), node.rightChild()}) {
          f.parent[child] = id;
          todo.push_back({child, false});
        }
      }
    }
    f.leaf_dirty.assign(static_cast<size_t>(T), 0);
    f.dirty.reserve(static_cast<size_t>(T));
    double edges = 0.0, extent = 0.0;
    for (int k = 0; k < T; ++k)
      for (int c = 0; c < 3; ++c)
        edges += (m.rest.positions.row(m.rest.triangles(k, c)) - m.rest.positions.row(m.rest.triangles(k, (c + 1) % 3))).norm();
    for (const Vec3& p : f.points) extent = std::max(extent, p.cwiseAbs().maxCoeff());
    f.slack = T > 0 ? std::max(0.0, settings_.refit_slack) * edges / (3.0 * T) : 0.0;
    f.margin = 1e-9 * std::max(extent, 1.0);
    std::vector<fcl::Vector3d>().swap(f.points);  // only refit() (not lazy) needs them again
    f.organ.reset();  // the walk reads f.nodes: FCL's model is not needed
    f.bvh.reset();
  }
  fcl_->request = fcl::CollisionRequestd(static_cast<size_t>(m.rest.triangle_count()), false);
  // input_: the penalty method's copy of the scene's input, and the kinematic one's when it
  // does not borrow the caller's (step_kinematic() makes it then, on its first step).
  // SceneSimulation lends its input: none is made.
  if (settings_.method == ContactSettings::Method::penalty) input_ = make_step_input(m);
  active_.assign(m.n, 0);
  mark_.assign(m.n, 0);
  held_target_.reserve(static_cast<size_t>(m.n));  // (reserved, not touched: no memory until used)
  held_normal_.reserve(static_cast<size_t>(m.n));
  candidates_.reserve(static_cast<size_t>(m.n));
  held_.reserve(static_cast<size_t>(m.n));
  holder_.assign(static_cast<size_t>(m.n), 0);
  saved_flags_.reserve(static_cast<size_t>(m.n));
  saved_u_.reserve(static_cast<size_t>(m.n));
  stack_.reserve(256);
  if (settings_.method == ContactSettings::Method::penalty) {
    triangle_mark_.assign(static_cast<size_t>(m.rest.triangle_count()), 0);
    candidates_.reserve(static_cast<size_t>(std::max(m.n, m.rest.triangle_count())));
    penalty_force_ = NodeMat::Zero(m.n, 3);
    penalty_spring_ = NodeMat::Zero(m.n, 3);
    iterate_ = NodeMat::Zero(m.n, 3);
    for (int k = 0; k < kAnderson; ++k) {
      anderson_dg_[k] = NodeMat::Zero(m.n, 3);
      anderson_df_[k] = NodeMat::Zero(m.n, 3);
    }
    last_g_ = last_f_ = residual_ = x_iterate_ = NodeMat::Zero(m.n, 3);
    input_.spring_k = NodeMat::Zero(m.n, 3);
    input_.spring_u = NodeMat::Zero(m.n, 3);
  }
  // x0_, u0_, v0_: with a reference model only (set_solver), sized by its first step.
}

ContactSolver::~ContactSolver() = default;

namespace {


// a == b entry by entry (as the comparison of doubles: -0 == 0), eight at a time in two
// lanes each, leaving at the first block that differs.
bool same_positions(const NodeMat& a, const NodeMat& b) {
  const Eigen::Index n = a.size();
  const double *p = a.data(), *q = b.data();
  constexpr Eigen::Index kBlock = 128;
  Eigen::Index k = 0;
  for (Eigen::Index s = 0; s + kBlock <= n; s += kBlock) {
    __m128d d0 = _mm_setzero_pd(), d1 = d0, d2 = d0, d3 = d0;
    for (k = s; k < s + kBlock; k += 8) {
      d0 = _mm_or_pd(d0, _mm_cmpneq_pd(simd::load2(p + k), simd::load2(q + k)));
      d1 = _mm_or_pd(d1, _mm_cmpneq_pd(simd::load2(p + k + 2), simd::load2(q + k + 2)));
      d2 = _mm_or_pd(d2, _mm_cmpneq_pd(simd::load2(p + k + 4), simd::load2(q + k + 4)));
      d3 = _mm_or_pd(d3, _mm_cmpneq_pd(simd::load2(p + k + 6), simd::load2(q + k + 6)));
    }
    if (_mm_movemask_pd(_mm_or_pd(_mm_or_pd(d0, d1), _mm_or_pd(d2, d3))) != 0) return false;
  }
  for (; k < n; ++k)
    if (p[k] != q[k]) return false;
  return true;
}

}  // namespace

void ContactSolver::refit_lazy(const NodeMat& x) {
  Fcl& f = *fcl_;
  const Eigen::Index n = f.last.rows();
  // A step starts where the last one ended: the tree already has these positions.
  if (refitted_ && same_positions(f.last, x)) return;
  f.prev.swap(f.last);
  if (!refitted_) f.last = x;  // (otherwise copied while checking the boxes)
  Fcl::Node* const bvs = f.nodes.data();
  // A parent's box from its children's (min and max of floats: exact). True when it changed.
  auto merge = [&](Fcl::Node& node) {
    const Fcl::Node &l = bvs[node.first_child], &r = bvs[node.first_child + 1];
    bool changed = false;
    for (int k = 0; k < 3; ++k) {
      const float lo = std::min(l.lo[k], r.lo[k]), hi = std::max(l.hi[k], r.hi[k]);
      changed |= lo != node.lo[k] || hi != node.hi[k];
      node.lo[k] = lo;
      node.hi[k] = hi;
    }
    return changed;
  };
  auto fit_leaf = [&](int tri) {
    Fcl::Node& box = bvs[f.leaf[tri]];
    const int a = (*triangles_)(tri, 0), b = (*triangles_)(tri, 1), c = (*triangles_)(tri, 2);
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = round_down(std::min({f.lo(a, k), f.lo(b, k), f.lo(c, k)}));
      box.hi[k] = round_up(std::max({f.hi(a, k), f.hi(b, k), f.hi(c, k)}));
    }
  };
  if (!refitted_) {  // every box, as FCL's first refit (the rest positions as the previous ones)
    f.lo = f.prev.cwiseMin(f.last);
    f.hi = f.prev.cwiseMax(f.last);
    for (int id : f.post_order) {
      Fcl::Node& node = bvs[id];
      if (is_leaf(node)) fit_leaf(triangle_of(node));
      else merge(node);
    }
    f.box_updates += static_cast<long>(f.post_order.size());
    std::vector<int>().swap(f.post_order);  // only the first refit walks the whole tree (-0.6 MB at 40k)
    refitted_ = true;
    return;
  }
  // Nodes that left their box by more than the slack, two at a time: by how far the worse
  // axis lies outside the box, max(x - hi, lo - x) over the three (for finite positions, as
  // the positions a step leaves are, more than the slack exactly when one of the six
  // differences is). Their boxes are reset to their last two positions (the earlier one was
  // within the slack of the old box) and their triangles listed, in node order, in the same
  // pass.
  const double d = f.slack;
  const simd::V2 d2 = simd::splat(d);
  const double* p[3] = {x.col(0).data(), x.col(1).data(), x.col(2).data()};
  const double* lo[3] = {f.lo.col(0).data(), f.lo.col(1).data(), f.lo.col(2).data()};
  const double* hi[3] = {f.hi.col(0).data(), f.hi.col(1).data(), f.hi.col(2).data()};
  double* const last[3] = {f.last.col(0).data(), f.last.col(1).data(), f.last.col(2).data()};
  f.dirty.clear();
  auto reset = [&](Eigen::Index i) {
    f.lo.row(i) = f.prev.row(i).cwiseMin(f.last.row(i));
    f.hi.row(i) = f.prev.row(i).cwiseMax(f.last.row(i));
    for (int k = f.node_triangles_start[i]; k < f.node_triangles_start[i + 1]; ++k) {
      const int tri = f.node_triangles[k];
      if (!f.leaf_dirty[tri]) {
        f.leaf_dirty[tri] = 1;
        f.dirty.push_back(tri);
      }
    }
  };
  Eigen::Index i = 0;
  for (; i + 2 <= n; i += 2) {  // their three axes in one pass
    auto outside = [&](int c) {
      const simd::V2 v = simd::load2(p[c] + i);
      simd::store2(last[c] + i, v);
      return simd::max2(v - simd::load2(hi[c] + i), simd::load2(lo[c] + i) - v);
    };
    const simd::V2 worst = simd::max2(simd::max2(outside(0), outside(1)), outside(2));
    const int flags = _mm_movemask_pd(_mm_cmpgt_pd(worst, d2));
    if (flags == 0) continue;  // most
    if (flags & 1) reset(i);
    if (flags & 2) reset(i + 1);
  }
  for (; i < n; ++i) {
    bool o = false;
    for (int c = 0; c < 3; ++c) {
      last[c][i] = p[c][i];
      o = o || (p[c][i] - hi[c][i] > d) || (lo[c][i] - p[c][i] > d);
    }
    if (o) reset(i);
  }
  // Their leaves, and each leaf's ancestors up to the first whose box does not change.
  f.box_updates += static_cast<long>(f.dirty.size());
  for (int tri : f.dirty) {
    f.leaf_dirty[tri] = 0;
    fit_leaf(tri);
    for (int id = f.parent[f.leaf[tri]]; id >= 0; id = f.parent[id]) {
      ++f.box_updates;
      if (!merge(bvs[id])) break;
    }
  }
}

void ContactSolver::refit(const NodeMat& x) {
  if (lazy()) {
    refit_lazy(x);
    return;
  }
  // A step starts where the last one ended: the tree already has these positions.
  size_t i = 0;
  if (refitted_)
    while (i < fcl_->points.size() && fcl_->points[i] == x.row(static_cast<Eigen::Index>(i)).transpose()) ++i;
  if (refitted_ && i == fcl_->points.size()) return;
  refitted_ = true;
  for (i = 0; i < fcl_->points.size(); ++i) fcl_->points[i] = x.row(static_cast<Eigen::Index>(i)).transpose();
  fcl_->bvh->beginUpdateModel();
  fcl_->bvh->updateSubModel(fcl_->points);
  fcl_->bvh->endUpdateModel(true, true);
  fcl_->organ->computeAABB();
  fcl_->box_updates += fcl_->bvh->getNumBVs();
}

void ContactSolver::broad_phase(const ToolShape& t, size_t k, double pad, std::vector<int>& found, ContactReport& rep,
                                bool triangles) {
  auto add_triangle = [&](int tri) {
    if (triangles) {
      if (!triangle_mark_[tri]) {
        triangle_mark_[tri] = 1;
        found.push_back(tri);
      }
      return;
    }
    for (int corner = 0; corner < 3; ++corner) {
      const int i = (*triangles_)(tri, corner);
      if (!mark_[i]) {
        mark_[i] = 1;
        found.push_back(i);
      }
    }
  };
  ++rep.queries;
  if (!settings_.fcl_shape_queries) {
    // Walk the refitted BVH: triangles whose boxes meet the tool's oriented box.
    Vec3 c, h;
    tool_box(t, pad, c, h);
    const Eigen::Matrix3d R = t.pose.linear();
    const Fcl& f = *fcl_;
    const bool lazy_tree = lazy();
    const double grow = lazy_tree ? f.slack + f.margin : 0.0;
    const BvNode* const bvs = lazy_tree ? nullptr : &static_cast<const fcl::BVHModel<fcl::AABBd>&>(*f.bvh).getBV(0);
    stack_.clear();
    stack_.push_back(0);
    while (!stack_.empty()) {
      const int id = stack_.back();
      stack_.pop_back();
      int first_child = 0;
      if (lazy_tree) {
        const Fcl::Node& node = f.nodes[static_cast<size_t>(id)];
        if (!may_overlap(c, R, h, to_vec3(node.lo), to_vec3(node.hi), grow)) continue;
        first_child = node.first_child;
      } else {
        const BvNode& node = bvs[id];
        if (!may_overlap(c, R, h, node.bv.min_, node.bv.max_, grow)) continue;
        first_child = node.first_child;
      }
      if (first_child < 0) {
        const int tri = -(first_child + 1);
        if (lazy_tree) {  // FCL's refitted leaf: the corners at the last two refits
          Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max()), hi = -lo;
          for (int corner = 0; corner < 3; ++corner) {
            const Eigen::Index i = (*triangles_)(tri, corner);
            lo = lo.cwiseMin(f.prev.row(i).transpose()).cwiseMin(f.last.row(i).transpose());
            hi = hi.cwiseMax(f.prev.row(i).transpose()).cwiseMax(f.last.row(i).transpose());
          }
          if (!may_overlap(c, R, h, lo, hi)) continue;
        }
        add_triangle(tri);
      } else {
        stack_.push_back(first_child);
        stack_.push_back(first_child + 1);
      }
    }
    return;
  }
  if (fcl_->slots.size() <= k) fcl_->slots.resize(k + 1);
  Fcl::Slot& slot = fcl_->slots[k];
  if (!slot.shape || slot.kind != t.kind || slot.hull != t.hull.get()) {
    slot.kind = t.kind;
    slot.hull = t.hull.get();
    slot.shape = make_fcl_shape(t);
    slot.object = std::make_unique<fcl::CollisionObjectd>(slot.shape);
  }
  size_fcl_shape(*slot.shape, t, pad);
  slot.object->setTransform(t.pose);
  slot.object->computeAABB();
  fcl_->result.clear();
  fcl::collide(fcl_->organ.get(), slot.object.get(), fcl_->request, fcl_->result);
  for (size_t c = 0; c < fcl_->result.numContacts(); ++c) add_triangle(static_cast<int>(fcl_->result.getContact(c).b1));
}

void ContactSolver::step(const TissueModel& m, const StepInput& base, const std::vector<Capsule>& capsules, SimState& s,
                         ContactReport& rep) {
  capsule_tools_.resize(capsules.size());
  for (size_t k = 0; k < capsules.size(); ++k) capsule_tools_[k] = to_tool(capsules[k]);
  step(m, base, capsule_tools_, s, rep);
}

void ContactSolver::step(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools, SimState& s,
                         ContactReport& rep) {
  step_any(m, base, tools, s, rep, nullptr);
}

void ContactSolver::step(const TissueModel& m, StepInput& base, const std::vector<ToolShape>& tools, SimState& s,
                         ContactReport& rep) {
  const bool rows = base.prescribed.rows() == m.n && base.prescribed_u.rows() == m.n;
  step_any(m, base, tools, s, rep, rows ? &base : nullptr);
}

void ContactSolver::step_any(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                             SimState& s, ContactReport& rep, StepInput* borrowed) {
  rep = ContactReport();
  const long boxes = fcl_->box_updates;
  if (settings_.method == ContactSettings::Method::penalty) step_penalty(m, base, tools, s, rep);
  else if (settings_.method == ContactSettings::Method::constraint && !solver_) step_constraint(m, base, tools, s, rep);
  else step_kinematic(m, base, tools, s, rep, borrowed);
  rep.refit_boxes = fcl_->box_updates - boxes;
}

void ContactSolver::copy_scene_constraints(const TissueModel& m, const StepInput& base) {
  if (base.prescribed.rows() == m.n) {
    input_.prescribed = base.prescribed;
    input_.prescribed_u = base.prescribed_u;
  } else {
    input_.prescribed.setZero();
    input_.prescribed_u.setZero();
  }
}

double ContactSolver::penalty_forces(const std::vector<ToolShape>& tools, const NodeMat& x, ContactReport& rep,
                                     const StepInput* base, std::vector<Vec3>* per_tool) {
  const bool has_prescribed = base && base->prescribed.rows() == x.rows();
  if (per_tool) per_tool->assign(tools.size(), Vec3::Zero());
  penalty_force_.setZero();
  penalty_spring_.setZero();
  refit(x);
  candidates_.clear();
  for (size_t k = 0; k < tools.size(); ++k) broad_phase(tools[k], k, 0.0, candidates_, rep, true);
  double smallest = std::numeric_limits<double>::infinity();
  for (const ToolShape& t : tools) smallest = std::min(smallest, t.size());
  const double kc = settings_.penalty_stiffness;
  double deepest = 0.0;
  for (int tri : candidates_) {
    triangle_mark_[tri] = 0;
    const int node[3] = {(*triangles_)(tri, 0), (*triangles_)(tri, 1), (*triangles_)(tri, 2)};
    const Vec3 a = x.row(node[0]).transpose();
    const Vec3 ab = x.row(node[1]).transpose() - a, ac = x.row(node[2]).transpose() - a;
    const double area = 0.5 * ab.cross(ac).norm();
    const double edge = std::max({ab.norm(), ac.norm(), (ac - ab).norm()});
    // S x S sub-triangles, none wider than a quarter of the smallest tool: their centroids
    // are the samples, each standing for area / S^2 of the surface.
    const int S = std::clamp(static_cast<int>(std::ceil(edge / (0.25 * smallest))), 1, 16);
    const double weight = kc * area / (S * S);
    auto sample = [&](double bu, double bv) {
      const Vec3 y = a + bu * ab + bv * ac;
      const double b[3] = {1.0 - bu - bv, bu, bv};
      for (size_t k = 0; k < tools.size(); ++k) {
        const ToolShape& t = tools[k];
        Vec3 p, n;
        const double dist = tool_distance(t, y, p, n);
        if (dist >= 0.0) continue;
        deepest = std::max(deepest, -dist);
        // Force k_c depth w n; its Jacobian k_c w (b n)(b n)^T is bounded by the diagonal
        // k_c w b_i |n_d| |n|_1 (diagonally dominant difference: positive semi-definite).
        const Vec3 force = weight * (-dist) * n;
        const Vec3 spring = weight * n.lpNorm<1>() * n.cwiseAbs();
        for (int c = 0; c < 3; ++c) {
          penalty_force_.row(node[c]) += b[c] * force.transpose();
          penalty_spring_.row(node[c]) += b[c] * spring.transpose();
          if (per_tool && !(has_prescribed && base->prescribed.row(node[c]).minCoeff() != 0))
            (*per_tool)[k] -= b[c] * force;
        }
      }
    };
    for (int i = 0; i < S; ++i)
      for (int j = 0; i + j < S; ++j) {
        sample((i + 1.0 / 3.0) / S, (j + 1.0 / 3.0) / S);                         // upright sub-triangle
        if (i + j < S - 1) sample((i + 2.0 / 3.0) / S, (j + 2.0 / 3.0) / S);  // inverted one
      }
  }
  return deepest;
}

void ContactSolver::step_penalty(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                 SimState& s, ContactReport& rep) {
  if (solver_) {  // fem and mass_spring take no springs: their steps could not be implicit
    s.failed = true;
    s.failure = "penalty contact needs the vdm model (organ.model fem and mass_spring use kinematic contact)";
    return;
  }
  const bool has_prescribed = base.prescribed.rows() == m.n;
  copy_scene_constraints(m, base);
  input_.pressure = base.pressure;
  double smallest = std::numeric_limits<double>::infinity();
  for (const ToolShape& t : tools) smallest = std::min(smallest, t.size());
  // Majorised Newton: at the iterate u_k, the step sees the penalty force F(u_k) plus springs
  // D (u_k - u), D >= the penalty's Jacobian, so that every solve lowers the energy of the
  // linearised problem: the iteration converges for any k_c, but slowly where D exceeds the
  // Jacobian (sliding along a curved tool). Anderson mixing of the last solves speeds it up;
  // it restarts when the residual grows.
  auto t0 = Clock::now();
  iterate_ = s.u;
  penalty_forces(tools, s.x, rep);
  rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const int max_it = std::max(1, settings_.max_penalty_iterations);
  rep.converged = false;
  int history = 0, next_slot = 0;  // Anderson differences stored, ring position
  double last_norm = std::numeric_limits<double>::infinity();  // residual of the last accepted iterate
  bool mixed = false;                                          // the current iterate is a mixed one
  for (int it = 0; it < max_it; ++it) {
    if (it > 0) rewind_step(m, s);
    if (base.force.rows() == m.n) input_.force = base.force + penalty_force_;
    else input_.force = penalty_force_;
    input_.spring_k = penalty_spring_;
    input_.spring_u = iterate_;
    vdm::step(m, input_, s, StepResults::none);  // the results of the last one only (below)
    ++rep.solves;
    rep.iterations += s.stats.iterations;
    if (s.failed) return;  // the caller stops; the state is the step's start
    residual_ = s.u - iterate_;  // f_k = G(u_k) - u_k
    const double change = residual_.cwiseAbs().maxCoeff();
    if (change <= settings_.penalty_tolerance * smallest) {
      rep.converged = true;
      break;
    }
    if (it + 1 == max_it) break;
    // Anderson (type II): u_{k+1} = G(u_k) - sum_j gamma_j dG_j, gamma minimising
    // |f_k - sum_j gamma_j dF_j| over the stored differences. Safeguarded: a mixed iterate
    // whose residual grew is dropped for the plain step from the point before it, G(u_{k-1}),
    // and the history starts again.
    const double norm = residual_.norm();
    if (mixed && norm > last_norm) {
      iterate_ = last_g_;
      history = 0;
      next_slot = 0;
      mixed = false;
    } else {
      if (it > 0) {
        anderson_dg_[next_slot] = s.u - last_g_;
        anderson_df_[next_slot] = residual_ - last_f_;
        next_slot = (next_slot + 1) % kAnderson;
        history = std::min(history + 1, static_cast<int>(kAnderson));
      }
      last_g_ = s.u;
      last_f_ = residual_;
      last_norm = norm;
      iterate_ = s.u;
      mixed = false;
      if (settings_.anderson && history > 0) {
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kAnderson, kAnderson> gram(history, history);
        Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kAnderson, 1> rhs(history), gamma(history);
        for (int a = 0; a < history; ++a) {
          rhs[a] = (anderson_df_[a].array() * residual_.array()).sum();
          for (int b = 0; b <= a; ++b)
            gram(a, b) = gram(b, a) = (anderson_df_[a].array() * anderson_df_[b].array()).sum();
        }
        gram.diagonal() *= 1.0 + 1e-10;  // nearly parallel differences
        gamma = gram.ldlt().solve(rhs);
        if (gamma.allFinite()) {
          for (int a = 0; a < history; ++a) iterate_ -= gamma[a] * anderson_dg_[a];
          mixed = true;
        }
      }
    }
    t0 = Clock::now();
    x_iterate_ = m.rest.positions + iterate_;
    penalty_forces(tools, x_iterate_, rep);
    rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }
  finish_step_results(m, s);
  t0 = Clock::now();
  const double deepest = penalty_forces(tools, s.x, rep, &base, &tool_force_);
  rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  // The contact force at the final positions; the organ pushes the tools with -F.
  rep.max_penetration = deepest;
  // Deeper than half the tool, a penalty this soft lets the surface slip round it.
  static const char* const kTooSoft =
      "penalty contact too soft: an instrument sank more than half its size into the surface";
  if (deepest > 0.5 * smallest && s.warnings.size() < kMaxWarnings &&
      std::find(s.warnings.begin(), s.warnings.end(), kTooSoft) == s.warnings.end())
    s.warnings.emplace_back(kTooSoft);
  for (int i = 0; i < m.n; ++i) {
    if (penalty_force_.row(i).squaredNorm() == 0.0) continue;
    if (has_prescribed && base.prescribed.row(i).minCoeff() != 0) continue;  // driven: the scene holds it
    ++rep.nodes;
    rep.force -= penalty_force_.row(i).transpose();
    s.reaction.row(i) = penalty_force_.row(i);
    const double a = s.area_vectors.row(i).norm();
    s.reaction_pressure[i] = a > 0 ? penalty_force_.row(i).norm() / a : 0.0;
  }
}

void ContactSolver::step_kinematic(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                   SimState& s, ContactReport& rep, StepInput* borrowed) {
  const auto t0 = Clock::now();
  // The start of the step, for re-solving it with a reference model (fem, mass_spring); the
  // VDM engine restores itself with rewind_step().
  if (solver_) {
    x0_ = s.x;
    u0_ = s.u;
    v0_ = s.velocity;
  }
  // A node's position at the step's start (its own motion in the step is x minus that), once
  // the step has been solved: the VDM engine keeps the start's u (StepWorkspace::start, the
  // whole step's when it was done in parts) and its positions are X + u bit for bit (every
  // pass that moves u writes x so), so no copy of x is made.
  const NodeMat* start_u = solver_ ? nullptr : &s.work->start.u;
  auto start_x = [&](int i) -> Vec3 {
    return solver_ ? Vec3(x0_.row(i).transpose()) : Vec3((m.rest.positions.row(i) + start_u->row(i)).transpose());
  };
  const long step0 = s.step;
  const double time0 = s.time;
  const bool has_prescribed = base.prescribed.rows() == m.n;
  // Nodes the scene itself moves (grasped, scripted) on every axis take no part in contact.
  auto driven = [&](int i) { return has_prescribed && base.prescribed.row(i).minCoeff() != 0; };
  // Contacts at the start: nodes inside (or touching) an instrument at its new pose.
  for (int i : held_) active_[i] = 0;
  held_.clear();
  held_target_.clear();
  held_normal_.clear();
  close_d_.resize(tools.size());
  close_p_.resize(tools.size());
  close_n_.resize(tools.size());
  refit(s.x);
  candidates_.clear();
  for (size_t k = 0; k < tools.size(); ++k) broad_phase(tools[k], k, settings_.activation * tools[k].size(), candidates_, rep);
  // `after_solve`: the node may have moved this step (relative motion = its move - the tool's).
  // `known`: close_* hold node i's distances to every tool already.
  auto classify = [&](int i, bool allow_touch, bool after_solve, bool known) {
    const Vec3 x = s.x.row(i).transpose();
    for (size_t k = 0; k < tools.size(); ++k) {
      const ToolShape& t = tools[k];
      if (!known) close_d_[k] = tool_distance(t, x, close_p_[k], close_n_[k]);
      const double dist = close_d_[k];
      const Vec3 &p = close_p_[k], &nrm = close_n_[k];
      const double limit = allow_touch ? settings_.activation * t.size() : -settings_.tolerance * 0.5 * t.size();
      if (dist < limit) {
        Vec3 dir;
        const Vec3 node_move = after_solve ? Vec3(s.x.row(i).transpose() - start_x(i)) : Vec3::Zero();
        const Vec3 target = dist < 0.0 ? push_out(t, x, node_move - t.motion_at(x), dir) : p;
        if (dist >= 0.0) dir = nrm;  // touching: held where it is; the tool pushes it along its normal
        active_[i] = 1;  // (classify only sees free nodes)
        holder_[size_t(i)] = int(k);
        held_.push_back(i);
        held_target_.push_back(target.transpose());
        held_normal_.push_back(dir.transpose());
        return true;
      }
    }
    return false;
  };
  for (int i : candidates_) {
    mark_[i] = 0;
    if (!driven(i)) classify(i, true, false, false);
  }
  rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();

  // Active set: solve, release adhesive nodes, catch penetrating ones, solve again. When the
  // cap is reached with the set still changing, one last solve makes the state and the set
  // agree (that set is not checked again: rep.converged says so).
  // Each solve sees the scene's loads and constraints with the rows of the held nodes set:
  // in `borrowed` (the caller's input, put back after the solve) or in a copy made once per
  // step (input_: its held rows put back after each solve too).
  const int max_it = std::max(1, settings_.max_active_set_iterations);
  StepInput& in = borrowed ? *borrowed : input_;
  if (!borrowed) {
    if (input_.prescribed.rows() != m.n) input_ = make_step_input(m);  // the first such step: allocates once
    input_.force = base.force;  // (0 rows: none)
    input_.pressure = base.pressure;
    copy_scene_constraints(m, base);
  }
  for (int it = 0; it <= max_it; ++it) {
    saved_flags_.resize(held_.size());
    saved_u_.resize(held_.size());
    for (size_t k = 0; k < held_.size(); ++k) {
      const int i = held_[k];
      saved_flags_[k] = in.prescribed.row(i);
      saved_u_[k] = in.prescribed_u.row(i);
      in.prescribed.row(i).setOnes();
      in.prescribed_u.row(i) = held_target_[k] - m.rest.positions.row(i);
    }
    if (it > 0) {  // solve the same step again from its start
      if (solver_) {
        s.u = u0_;
        s.x = x0_;
        s.velocity = v0_;
        s.step = step0;
        s.time = time0;
      } else {
        rewind_step(m, s);
      }
    }
    // The engine's results pass only for the solve kept (finish_step_results below): the
    // set's checks read the reactions of the held nodes alone.
    if (solver_) solver_->step(in, s);
    else vdm::step(m, in, s, StepResults::reactions);
    for (size_t k = 0; k < held_.size(); ++k) {
      in.prescribed.row(held_[k]) = saved_flags_[k];
      in.prescribed_u.row(held_[k]) = saved_u_[k];
    }
    ++rep.solves;
    rep.iterations += s.stats.iterations;
    if (s.failed) return;  // the caller stops; the state is the step's start

    const auto tc = Clock::now();
    bool changed = false;
    // Release nodes the instrument would have to pull (adhesion).
    if (it < max_it) {
      size_t kept = 0;
      for (size_t k = 0; k < held_.size(); ++k) {
        const int i = held_[k];
        if (s.reaction.row(i).dot(held_normal_[k]) < 0.0) {
          active_[i] = 0;
          changed = true;
        } else {
          held_[kept] = i;
          held_target_[kept] = held_target_[k];
          held_normal_[kept] = held_normal_[k];
          ++kept;
        }
      }
      held_.resize(kept);
      held_target_.resize(kept);
      held_normal_.resize(kept);
    }
    // Catch free nodes that the step pushed into an instrument.
    refit(s.x);
    candidates_.clear();
    for (size_t k = 0; k < tools.size(); ++k) broad_phase(tools[k], k, 0.0, candidates_, rep);
    rep.max_penetration = 0.0;
    for (int i : candidates_) {
      mark_[i] = 0;
      if (active_[i] || driven(i)) continue;
      const Vec3 x = s.x.row(i).transpose();
      for (size_t k = 0; k < tools.size(); ++k) {
        close_d_[k] = tool_distance(tools[k], x, close_p_[k], close_n_[k]);
        rep.max_penetration = std::max(rep.max_penetration, -close_d_[k]);
      }
      if (it < max_it && classify(i, false, true, true)) changed = true;
    }
    rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - tc).count();
    if (!changed) {
      rep.converged = it < max_it;
      break;
    }
  }
  if (!solver_) finish_step_results(m, s);
  std::sort(held_.begin(), held_.end());  // the force summed in node order
  tool_force_.assign(tools.size(), Vec3::Zero());
  for (int i : held_) {
    ++rep.nodes;
    rep.force -= s.reaction.row(i).transpose();
    tool_force_[size_t(holder_[size_t(i)])] -= s.reaction.row(i).transpose();
  }
}

}  // namespace vdm
