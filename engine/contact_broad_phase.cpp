#include "engine/contact_broad_phase.hpp"

#include <fcl/fcl.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/contact_settings.hpp"
#include "engine/simd2.hpp"

namespace vdm {


struct ContactBroadPhase::Fcl {
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
    double convex_growth = -1.0;  // a convex shape's growth (m, make_fcl_shape): rebuilt when more is needed
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

// A convex hull is built grown by `growth` (m): its vertices are scaled about the centroid so
// that every face moves out by at least that much (the centroid is the inradius' centre), a
// polytope that holds the hull rounded and inflated by `growth`.
std::shared_ptr<fcl::CollisionGeometryd> make_fcl_shape(const ToolShape& t, double growth) {
  switch (t.kind) {
    case ToolShape::Kind::capsule: return std::make_shared<fcl::Capsuled>(1.0, 1.0);
    case ToolShape::Kind::cylinder: return std::make_shared<fcl::Cylinderd>(1.0, 1.0);
    case ToolShape::Kind::box: return std::make_shared<fcl::Boxd>(1.0, 1.0, 1.0);
    case ToolShape::Kind::convex: {
      const double scale = 1.0 + growth / t.hull->inradius;
      auto verts = std::make_shared<std::vector<fcl::Vector3d>>();
      for (const Vec3& v : t.hull->vertices) verts->push_back(t.hull->centroid + scale * (v - t.hull->centroid));
      auto faces = std::make_shared<std::vector<int>>();
      for (const auto& tri : t.hull->triangles) faces->insert(faces->end(), {3, tri[0], tri[1], tri[2]});
      return std::make_shared<fcl::Convexd>(verts, int(t.hull->triangles.size()), faces);
    }
  }
  return nullptr;
}

// The share of the tool's size FCL's shapes are grown by, at least ten times GJK's tolerance
// (the query stays a superset).
constexpr double kFclGrazeMargin = 1e-3;

// Sizes the slot's shape to the tool inflated by `pad` (a convex hull is grown when it is
// built: make_fcl_shape).
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

ContactBroadPhase::ContactBroadPhase(const TissueModel& m, const ContactSettings& settings)
    : fcl_(std::make_unique<Fcl>()),
      triangles_(&m.rest.triangles),
      lazy_(settings.lazy_refit && !settings.fcl_shape_queries),
      fcl_shape_queries_(settings.fcl_shape_queries) {
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
    f.slack = T > 0 ? std::max(0.0, settings.refit_slack) * edges / (3.0 * T) : 0.0;
    f.margin = 1e-9 * std::max(extent, 1.0);
    std::vector<fcl::Vector3d>().swap(f.points);  // only refit() (not lazy) needs them again
    f.organ.reset();  // the walk reads f.nodes: FCL's model is not needed
    f.bvh.reset();
  }
  fcl_->request = fcl::CollisionRequestd(static_cast<size_t>(m.rest.triangle_count()), false);
  stack_.reserve(256);
}

ContactBroadPhase::~ContactBroadPhase() = default;

long ContactBroadPhase::box_updates() const { return fcl_->box_updates; }

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

void ContactBroadPhase::refit_lazy(const NodeMat& x) {
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

void ContactBroadPhase::refit(const NodeMat& x) {
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

void ContactBroadPhase::query(const ToolShape& t, size_t k, double pad, bool triangles, std::vector<char>& seen,
                              std::vector<int>& found) {
  auto add_triangle = [&](int tri) {
    if (triangles) {
      if (!seen[tri]) {
        seen[tri] = 1;
        found.push_back(tri);
      }
      return;
    }
    for (int corner = 0; corner < 3; ++corner) {
      const int i = (*triangles_)(tri, corner);
      if (!seen[i]) {
        seen[i] = 1;
        found.push_back(i);
      }
    }
  };
  if (!fcl_shape_queries_) {
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
  // FCL's GJK decides a graze to its own tolerance (gjk_tolerance, m): the shape is grown by
  // more than that so that no triangle the exact test after it would take is missed.
  const double grown = pad + std::max(kFclGrazeMargin * t.size(), 10.0 * fcl_->request.gjk_tolerance);
  const double convex_growth = t.kind == ToolShape::Kind::convex ? grown + t.rounding : 0.0;
  if (!slot.shape || slot.kind != t.kind || slot.hull != t.hull.get() || convex_growth > slot.convex_growth) {
    slot.kind = t.kind;
    slot.hull = t.hull.get();
    slot.convex_growth = convex_growth;
    slot.shape = make_fcl_shape(t, convex_growth);
    slot.object = std::make_unique<fcl::CollisionObjectd>(slot.shape);
  }
  size_fcl_shape(*slot.shape, t, grown);
  slot.object->setTransform(t.pose);
  slot.object->computeAABB();
  fcl_->result.clear();
  fcl::collide(fcl_->organ.get(), slot.object.get(), fcl_->request, fcl_->result);
  for (size_t c = 0; c < fcl_->result.numContacts(); ++c) add_triangle(static_cast<int>(fcl_->result.getContact(c).b1));
}

}  // namespace vdm
