// Constraint contact with Coulomb friction (ContactSettings::Method::constraint).
//
// Contact points are surface points: the nodes near a tool and, where a triangle's inside
// meets a tool that none of its corners touches (a probe thinner than the edges), the
// triangle's deepest point, its force spread on the corners by barycentric weights (more
// points on a triangle that the tool meets, deeper than allowed, away from its points). Each
// carries a force in its frame (n: the tool's outward normal, t1, t2):
//   non-penetration   gap >= 0, f_n >= 0, gap f_n = 0;
//   Coulomb friction  |f_t| <= mu f_n; below the cone the point moves with the tool over the
//                     step (no slip), on it the force opposes the slip.
// The forces are found as SOFA's constraint solver does: the organ is solved with the
// current forces (the first solve: the last step's, matched by node or triangle), the gaps
// and slips measured, then a projected Gauss-Seidel over the contacts finds the forces that
// satisfy the laws on the linear model `point = point_solved + W (f - f_solved)`, and the
// organ is solved again with them. W, the compliance between contact points, comes from
// PatchCompliance (the nodes' compliance on a patch of the surface around them), times a
// scale fitted after the first correction to what the solve moved against what W
// predicted. The loop ends when the measured gaps and slips are within the tolerance and the
// forces the pass found would move no point by more: the state is then the organ's exact
// equilibrium under forces that satisfy the laws.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "engine/contact.hpp"
#include "engine/headroom.hpp"
#include "engine/organ_solver.hpp"
#include "engine/stopwatch.hpp"

namespace vdm {

namespace {

// The relative residual of the contact iteration's intermediate solves (StepInput::tolerance),
// as a share of the contact's relative tolerance (ContactSettings::constraint_tolerance):
// 2.5e-4 at the default 0.5 %. Their errors must stay well below the contact tolerance: the
// frictionless capsule of the tests, pressed 10 mm into a ball with a contact tolerance 25
// times tighter than the default, lost 10 % of its force with a share of 0.2, and keeps it to
// the printed digit with 0.05; probe_poke's force is then within 0.1 % of every solve tight's.
constexpr double kLooseShare = 0.05;

// The Gauss-Seidel on the contact points' forces stops when a sweep's changes move no point,
// through its own compliance, by more than this share of the contact tolerance: the
// contact's own convergence test allows a whole tolerance, and on a slide's 70 points that
// pull on one another through the fluid the forces' relative change falls by only a few
// percent a sweep (most passes used to end at their 200 sweeps).
constexpr double kSweepMotionShare = 0.01;

// An orthonormal frame whose first column is n.
Eigen::Matrix3d contact_frame(const Vec3& n) {
  Vec3 t1 = std::abs(n.x()) < 0.6 ? n.cross(Vec3::UnitX()) : n.cross(Vec3::UnitY());
  t1.normalize();
  Eigen::Matrix3d f;
  f.col(0) = n;
  f.col(1) = t1;
  f.col(2) = n.cross(t1);
  return f;
}

Vec3 point_of(const ContactPoint& c, const NodeMat& x) {
  Vec3 p = Vec3::Zero();
  for (int v = 0; v < c.count; ++v) p += c.weight[v] * x.row(c.node[v]).transpose();
  return p;
}

// Sub-triangles no wider than a quarter of the tool: their centroids are a triangle's samples.
int samples_across(const Vec3& a, const Vec3& b, const Vec3& c, double tool_size) {
  const double edge = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
  return std::clamp(static_cast<int>(std::ceil(edge / (0.25 * tool_size))), 1, 16);
}

// Calls f(bu, bv) for every sample of an S x S subdivided triangle (barycentric weights
// 1 - bu - bv, bu, bv).
template <class F>
void for_each_sample(int S, F&& f) {
  for (int i = 0; i < S; ++i)
    for (int j = 0; i + j < S; ++j) {
      f((i + 1.0 / 3.0) / S, (j + 1.0 / 3.0) / S);
      if (i + j < S - 1) f((i + 2.0 / 3.0) / S, (j + 2.0 / 3.0) / S);
    }
}

// The triangle a, b, c's point closest to (deepest inside) the tool: the best of its samples,
// with `refine` then refined by a pattern search over the barycentric weights (the signed
// distance to a convex tool is convex along the triangle's plane, so the search finds the
// minimum: a tool thinner than the samples' spacing is found too). Returns the distance; bu,
// bv: the point's weights. Where no point of the triangle can be closer than `wanted` (a
// lower bound at or beyond it), returns that bound without searching further: the signed
// distance to a convex tool changes by at most the distance moved, and every point of the
// triangle is within its largest corner distance of its centroid and within a sub-triangle's
// edge of a sample.
double deepest_in_triangle(const ToolShape& t, const Vec3& a, const Vec3& b, const Vec3& c, double& bu, double& bv,
                           Vec3& surface, Vec3& normal, bool refine, double wanted) {
  const Vec3 ab = b - a, ac = c - a;
  Vec3 sp, sn;
  auto at = [&](double u, double v) { return tool_distance(t, a + u * ab + v * ac, sp, sn); };
  {
    const Vec3 centroid = (a + b + c) / 3.0;
    const double from_centroid =
        std::sqrt(std::max({(a - centroid).squaredNorm(), (b - centroid).squaredNorm(), (c - centroid).squaredNorm()}));
    const double bound = tool_distance(t, centroid, sp, sn) - from_centroid;
    if (bound >= wanted) return bound;
  }
  const int S = samples_across(a, b, c, t.size());
  const double reach = std::sqrt(std::max({ab.squaredNorm(), ac.squaredNorm(), (c - b).squaredNorm()}));
  double best = std::numeric_limits<double>::infinity();
  for_each_sample(S, [&](double u, double v) {
    const double d = at(u, v);
    if (d < best) {
      best = d;
      bu = u;
      bv = v;
    }
  });
  if (best - reach / S >= wanted) return best - reach / S;
  static const double kDirections[6][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, -1}, {-1, 1}};
  for (double h = 0.5 / S; refine && h > 1e-4 / S;) {
    bool better = false;
    for (const auto& dir : kDirections) {
      const double u = bu + h * dir[0], v = bv + h * dir[1];
      if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
      const double d = at(u, v);
      if (d < best) {
        best = d;
        bu = u;
        bv = v;
        better = true;
      }
    }
    if (!better) h *= 0.5;
  }
  best = at(bu, bv);
  surface = sp;
  normal = sn;
  return best;
}


// The gap of a surface point to a tool, and the tool's surface point and normal it is measured
// to: the nearest surface point, except for a point deeper than a quarter of the tool's size.
// There the tool moved across a good part of itself in one step (a fast tool), the nearest
// surface may be its far side, and the point is pushed out back along its motion relative to
// the tool instead (to the face that came to it, as kinematic contact does). `start`: the
// point at the step's start.
double contact_gap(const ToolShape& t, const Vec3& point, const Vec3& start, Vec3& surface, Vec3& normal) {
  const double d = tool_distance(t, point, surface, normal);
  if (d >= -0.25 * t.size()) return d;
  Vec3 dir;
  const Vec3 exit = push_out(t, point, (point - start) - t.motion_at(point), dir);
  if (!exit.allFinite() || !dir.allFinite()) return d;
  surface = exit;
  normal = dir;
  return -(exit - point).norm();
}

// Whether `flags` (per node and axis; empty: none) holds node i on every axis.
bool on_every_axis(const FlagMat& flags, int i) { return flags.rows() > i && flags.row(i).minCoeff() != 0; }

// Whether triangle `tri` takes another point with tool k at `q`, `depth` deep (signed
// distance, negative inside): none within a fiftieth of the tool's size, and every point
// within a quarter of it is shallower by half the penetration allowed (`allowed`, m): the
// tool meets the triangle somewhere its points do not hold (a tool moved across a large
// triangle, or the triangle turned about a point it is held at). A triangle holds eight
// points at most: the ninth takes the place of one apart from the tool with no force (left
// behind by a tool that swept across the triangle), or is refused. Returns false to refuse;
// `replace` is the index of the point to replace, or -1 to add one.
bool takes_another_point(const std::vector<ContactPoint>& contacts, int tri, int k, const Vec3& q, double depth,
                         const NodeMat& x, double size, double allowed, int& replace) {
  int count = 0;
  replace = -1;
  for (size_t i = 0; i < contacts.size(); ++i) {
    const ContactPoint& c = contacts[i];
    if (c.triangle != tri || c.tool != k) continue;
    ++count;
    const double d = (point_of(c, x) - q).norm();
    if (d < 0.02 * size || (d < 0.25 * size && c.gap <= depth + 0.5 * allowed)) return false;
    if (c.gap > 0.0 && c.force.squaredNorm() == 0.0 && (replace < 0 || c.gap > contacts[size_t(replace)].gap))
      replace = static_cast<int>(i);
  }
  if (count < 8) replace = -1;
  return count < 8 || replace >= 0;
}

// Contact points in a fixed order (tool, triangle, node), whatever order the broad phase
// found them in: the Gauss-Seidel's result depends on the order.
bool in_order(const ContactPoint& a, const ContactPoint& b) {
  if (a.tool != b.tool) return a.tool < b.tool;
  if (a.triangle != b.triangle) return a.triangle < b.triangle;
  if (a.node[0] != b.node[0]) return a.node[0] < b.node[0];
  if (a.weight[1] != b.weight[1]) return a.weight[1] < b.weight[1];
  return a.weight[2] < b.weight[2];
}

}  // namespace

int ContactSolver::find_contact_points(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                        const NodeMat& x, const NodeMat& start_u, double limit, bool warm,
                                        ContactReport& rep) {
  // Nodes that cannot move on any axis take no force.
  auto immobile = [&](int i) { return on_every_axis(base.prescribed, i) || on_every_axis(m.held, i); };
  auto add = [&](int k, int tri, const int* nodes, const double* weights, int count, double gap, const Vec3& surface,
                 const Vec3& normal) {
    ContactPoint c;
    c.tool = k;
    c.triangle = tri;
    c.count = count;
    for (int v = 0; v < count; ++v) {
      c.node[v] = nodes[v];
      c.weight[v] = weights[v];
      c.start += weights[v] * (m.rest.positions.row(nodes[v]) + start_u.row(nodes[v])).transpose();
    }
    c.point = point_of(c, x);
    c.solved = c.point;
    c.gap = gap;
    c.surface = surface;
    c.normal = normal;
    if (gap < -0.25 * tools[static_cast<size_t>(k)].size())
      c.gap = contact_gap(tools[static_cast<size_t>(k)], c.point, c.start, c.surface, c.normal);
    if (warm)  // the force the last step ended with there (a triangle's: all its points')
      for (const ContactPoint& l : last_contacts_)
        if (l.tool == k && l.triangle == tri && (tri >= 0 || l.node[0] == nodes[0])) {
          c.force += l.force;
          if (tri < 0) break;
        }
    if (tri < 0) node_tool_[static_cast<size_t>(nodes[0])] = k;
    else triangle_tool_[static_cast<size_t>(tri)] = k;
    contacts_.push_back(c);
  };
  refit(x);
  int put = 0;
  for (size_t kk = 0; kk < tools.size(); ++kk) {
    const int k = static_cast<int>(kk);
    const ToolShape& t = tools[kk];
    const double size = t.size();
    ToolShape before = t;  // the tool where it was at the step's start
    before.pose = t.previous;
    candidates_.clear();
    broad_phase(t, kk, std::max(limit, 0.0) * size, candidates_, rep, true);
    for (int tri : candidates_) {
      triangle_mark_[static_cast<size_t>(tri)] = 0;
      int nd[3];
      Vec3 p[3];
      bool corner_contact = false, all_immobile = true, moved_corner = false;
      for (int v = 0; v < 3; ++v) {
        nd[v] = (*triangles_)(tri, v);
        p[v] = x.row(nd[v]).transpose();
        const int owner = node_tool_[static_cast<size_t>(nd[v])];
        if (owner >= 0) {
          corner_contact |= owner == k;
          all_immobile = false;
          continue;
        }
        if (immobile(nd[v])) {
          moved_corner |= on_every_axis(base.prescribed, nd[v]);
          continue;
        }
        all_immobile = false;
        Vec3 sp, sn;
        const double dist = tool_distance(t, p[v], sp, sn);
        if (dist < limit * size) {
          const double one = 1.0;
          add(k, -1, &nd[v], &one, 1, dist, sp, sn);
          ++put;
          corner_contact = true;
        }
      }
      const int owner = triangle_tool_[static_cast<size_t>(tri)];
      // (a triangle with a corner the scene moves, e.g. grasped, goes where that corner is
      // taken: it may lie in the jaw that holds it, and takes no point)
      if ((owner >= 0 && owner != k) || all_immobile || moved_corner) continue;
      // The triangle's deepest inner point: where no corner touches this tool, any point
      // closer than the limit; beside touching corners, or in a triangle that has points
      // already, only one deeper than the penetration allowed (ContactSettings::tolerance:
      // the chord of a round tool between nodes held on it cuts into it; a tool that moved
      // across a large triangle meets it away from the point first placed).
      const bool more = owner == k;
      const double need = (corner_contact || more ? -settings_.tolerance : limit) * size;
      double bu = 0, bv = 0;
      Vec3 best_p, best_n;
      // (refined only where no corner touches: beside touching corners the samples' centroids
      // keep the point inside the triangle, away from the corners that hold it already)
      const double best = deepest_in_triangle(t, p[0], p[1], p[2], bu, bv, best_p, best_n, !corner_contact, need);
      const Vec3 q = p[0] + bu * (p[1] - p[0]) + bv * (p[2] - p[0]);
      const double allowed = settings_.tolerance * size;
      int replace = -1;
      if (best >= need || (more && !takes_another_point(contacts_, tri, k, q, best, x, size, allowed, replace)))
        continue;
      // A triangle the tool was already deep through at the step's start (an instrument placed
      // inside the organ, or withdrawn through the hole it left) is left pierced: pushing its
      // inside out of the tool would tear the surface off its corners (its corners are kept
      // out as nodes). Only where the tool's motion relative to it leads out nearby (a tool
      // placed just under the surface: out ahead of its tip) is it pushed out that way.
      if (best < -0.25 * size) {
        Vec3 q0 = Vec3::Zero(), sp, sn, dir;
        const double w0[3] = {1.0 - bu - bv, bu, bv};
        for (int v = 0; v < 3; ++v) q0 += w0[v] * (m.rest.positions.row(nd[v]) + start_u.row(nd[v])).transpose();
        if (tool_distance(before, q0, sp, sn) < -0.25 * size) {
          // (push_out turns to the nearest surface point when the way out is far)
          const Vec3 relative = -t.motion_at(q0);
          const Vec3 way = relative.norm() > 1e-9 * size ? Vec3(-relative.normalized()) : Vec3(before.pose.linear().col(2));
          push_out(before, q0, relative, dir);
          if (dir.dot(way) < 0.99) continue;
        }
      }
      const double w[3] = {1.0 - bu - bv, bu, bv};
      if (replace >= 0) contacts_.erase(contacts_.begin() + replace);
      add(k, tri, nd, w, 3, best, best_p, best_n);
      ++put;
    }
  }
  return put;
}

double ContactSolver::deepest_surface_point(const std::vector<ToolShape>& tools, const NodeMat& x,
                                            ContactReport& rep) {
  refit(x);
  double deepest = 0.0;
  for (size_t k = 0; k < tools.size(); ++k) {
    const ToolShape& t = tools[k];
    candidates_.clear();
    broad_phase(t, k, 0.0, candidates_, rep, true);
    for (int tri : candidates_) {
      triangle_mark_[static_cast<size_t>(tri)] = 0;
      // (a triangle with a corner the scene moves on every axis, e.g. grasped, takes no point:
      // input_ holds the scene's prescribed motion)
      bool moved_corner = false;
      for (int v = 0; v < 3; ++v) moved_corner |= on_every_axis(input_.prescribed, (*triangles_)(tri, v));
      if (moved_corner) continue;
      const Vec3 a = x.row((*triangles_)(tri, 0)).transpose(), b = x.row((*triangles_)(tri, 1)).transpose(),
                 c = x.row((*triangles_)(tri, 2)).transpose();
      Vec3 sp, sn;
      for (const Vec3* corner : {&a, &b, &c}) deepest = std::max(deepest, -tool_distance(t, *corner, sp, sn));
      for_each_sample(samples_across(a, b, c, t.size()), [&](double u, double v) {
        deepest = std::max(deepest, -tool_distance(t, a + u * (b - a) + v * (c - a), sp, sn));
      });
    }
  }
  return deepest;
}

void ContactSolver::begin_constraint_step(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                          SimState& s, ContactReport& rep, bool carry) {
  auto t0 = Clock::now();
  if (input_.prescribed.rows() != m.n) input_ = make_step_input(m);  // the first such step: allocates once
  input_.pressure = base.pressure;
  copy_scene_constraints(m, base);
  if (contact_force_.rows() != m.n) contact_force_ = NodeMat::Zero(m.n, 3);
  if (node_tool_.size() != static_cast<size_t>(m.n)) node_tool_.assign(static_cast<size_t>(m.n), -1);
  if (node_slot_.size() != static_cast<size_t>(m.n)) node_slot_.assign(static_cast<size_t>(m.n), -1);
  const size_t T = static_cast<size_t>(m.rest.triangle_count());
  if (triangle_tool_.size() != T) triangle_tool_.assign(T, -1);
  if (triangle_mark_.size() != T) triangle_mark_.assign(T, 0);
  double smallest = std::numeric_limits<double>::infinity();
  for (const ToolShape& t : tools) smallest = std::min(smallest, t.size());
  contact_tolerance_ = settings_.constraint_tolerance * smallest;

  for (int i : held_) active_[static_cast<size_t>(i)] = 0;
  held_.clear();
  for (const ContactPoint& c : contacts_) {
    if (c.triangle < 0) node_tool_[static_cast<size_t>(c.node[0])] = -1;
    else triangle_tool_[static_cast<size_t>(c.triangle)] = -1;
    for (int v = 0; v < c.count; ++v) contact_force_.row(c.node[v]).setZero();
  }
  last_contacts_.swap(contacts_);
  contacts_.clear();
  // (the two lists trade places every step: each keeps the capacity either has reached)
  if (contacts_.capacity() < last_contacts_.capacity()) contacts_.reserve(last_contacts_.capacity());
  if (carry) {
    // The last step's points that held a force, where the tool still touches them (within
    // the activation distance at the step's start), with their forces: a held instrument's
    // next step then starts from the forces it ended with, node by node. A carried point's
    // force is taken out of the last step's, so that no new point takes it again.
    for (ContactPoint& l : last_contacts_) {
      if (l.force.squaredNorm() == 0.0 || l.tool >= static_cast<int>(tools.size())) continue;
      if (l.triangle < 0 && node_tool_[static_cast<size_t>(l.node[0])] >= 0) continue;
      bool free = true;
      for (int v = 0; v < l.count; ++v)
        free = free && !on_every_axis(base.prescribed, l.node[v]) && !on_every_axis(m.held, l.node[v]);
      if (!free) continue;
      const ToolShape& t = tools[static_cast<size_t>(l.tool)];
      ContactPoint c = l;
      c.start.setZero();
      for (int v = 0; v < c.count; ++v)
        c.start += c.weight[v] * (m.rest.positions.row(c.node[v]) + s.u.row(c.node[v])).transpose();
      c.point = c.solved = point_of(c, s.x);
      c.predicted.setZero();
      c.gap = contact_gap(t, c.point, c.start, c.surface, c.normal);
      if (c.gap >= settings_.activation * t.size() + t.motion_at(c.point).norm()) continue;
      if (c.triangle < 0) node_tool_[static_cast<size_t>(c.node[0])] = c.tool;
      else triangle_tool_[static_cast<size_t>(c.triangle)] = c.tool;
      contacts_.push_back(c);
      l.force.setZero();
    }
  }
  // Before the solve the positions are the step's start.
  find_contact_points(m, base, tools, s.x, s.u, settings_.activation, true, rep);
  std::sort(contacts_.begin(), contacts_.end(), in_order);
  rep.collision_ms += ms_since(t0);
}

void ContactSolver::step_constraint(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                    SimState& s, ContactReport& rep) {
  begin_constraint_step(m, base, tools, s, rep);
  const double tolerance = contact_tolerance_;
  const bool has_force = base.force.rows() == m.n;
  auto t0 = Clock::now();
  const int max_it = std::max(1, settings_.max_constraint_iterations);
  rep.converged = false;
  bool predicted = false;  // the contacts hold a prediction of the next solve's motion
  // Loose solves (ContactSettings::loose_solves): the solves that only move the forces toward
  // the laws stop at a looser relative residual (kLooseShare); once the forces meet the laws,
  // the same forces are solved to the model's tolerance and checked again, so the step ends
  // on a solve as accurate as any other step's. The last solve the cap allows is a tight one,
  // and so is the first of a step that starts with no contact (it may end with none, and then
  // that solve is the step's).
  // (Only with a solver that takes the tolerance: the others would solve the same forces twice.)
  const double loose_tolerance = kLooseShare * settings_.constraint_tolerance;
  const bool can_loosen =
      settings_.loose_solves && solver_->takes_tolerance() && m.solver.tolerance < loose_tolerance;
  bool loose = can_loosen && !contacts_.empty();
  double last_merit = std::numeric_limits<double>::infinity();
  for (int it = 0; it < max_it; ++it) {
    if (loose && it + 1 == max_it) loose = false;
    const bool solved_loose = loose;  // this iteration's solve (`loose` may change below)
    input_.tolerance = loose ? loose_tolerance : 0.0;
    // The organ under the contact forces.
    if (it > 0) solver_->rewind(s);
    for (const ContactPoint& c : contacts_)
      for (int v = 0; v < c.count; ++v) contact_force_.row(c.node[v]).setZero();
    for (const ContactPoint& c : contacts_)
      for (int v = 0; v < c.count; ++v) contact_force_.row(c.node[v]) += c.weight[v] * c.force.transpose();
    if (has_force) input_.force = base.force + contact_force_;
    else input_.force = contact_force_;
    solver_->trial_step(input_, s, StepResults::none);
    ++rep.solves;
    rep.iterations += s.stats.iterations;
    if (s.failed) {  // the caller stops; the state is the step's start
      input_.tolerance = 0.0;
      return;
    }

    t0 = Clock::now();
    // What the solve moved against what the compliance predicted: the compliance's scale.
    if (predicted) {
      double along = 0.0, norm = 0.0;
      for (const ContactPoint& c : contacts_) {
        const Vec3 moved = point_of(c, s.x) - c.solved;
        along += moved.dot(c.predicted);
        norm += c.predicted.squaredNorm();
      }
      // (the patch's scale once per step, at its first correction; an exact compliance's at every
      // correction: it is the core's with its rotations held, stiffer than the organ by a
      // factor that grows with the press, 1.5 to 2.2 on a ball pressed into a block)
      if (norm > tolerance * tolerance && along > 0.0 && (it == 1 || exact_compliance_used_))
        compliance_scale_ = std::clamp(compliance_scale_ * std::clamp(along / norm, 0.5, 2.0), 0.1, 10.0);
    }
    // The contacts at the solved positions, and the points the solve pushed into a tool.
    measure_contacts(tools, s.x);
    const size_t before = contacts_.size();
    const bool added =
        find_contact_points(m, base, tools, s.x, solver_->start_u(s), -settings_.constraint_tolerance, false, rep) > 0;
    if (it == 0 && before == 0 && added && can_loosen) loose = true;  // contact met during the first solve
    if (added) sort_contacts();
    const int C = static_cast<int>(contacts_.size());
    if (C == 0) {  // (a loose solve always has contacts: they are never removed within a step)
      rep.converged = true;
      rep.collision_ms += ms_since(t0);
      break;
    }

    // The compliance between the contact nodes (again when they or the engine's matrix changed).
    collect_contact_nodes();
    // (a model that gives its exact compliance gives it at this solve's linearisation)
    const bool exact = solver_->surface_compliance(contact_nodes_, exact_compliance_);
    exact_compliance_used_ = exact;
    if (!exact &&
        (contact_nodes_ != compliance_nodes_ || compliance_refreshes_ != solver_->contact_stiffness_version(s))) {
      compliance_.compute(m.neighbours, solver_->contact_stiffness(m, s), m.held, base.prescribed, contact_nodes_,
                          std::max(0, settings_.compliance_rings));
      assign_with_headroom(compliance_nodes_, contact_nodes_.begin(), contact_nodes_.end());
      compliance_refreshes_ = solver_->contact_stiffness_version(s);
    }
    double violation = 0.0, change = 0.0;
    project_forces(tools, exact, compliance_scale_, violation, change);
    rep.collision_ms += ms_since(t0);
    if (!added && violation <= tolerance && change <= tolerance) {
      if (solved_loose) {  // met on a loose solve: the same forces to the model's tolerance
        loose = false;
        continue;
      }
      rep.converged = true;
      break;
    }
    // Loose solves only while they bring the forces closer to the laws: once an iteration
    // does not, the rest of the step is solved to the model's tolerance.
    const double merit = std::max(violation, change);
    if (loose && it > 0 && !(merit < last_merit)) loose = false;
    last_merit = merit;
    if (it + 1 == max_it) break;  // the state stays that of the forces it was solved with
    store_forces();
    predicted = true;
  }
  input_.tolerance = 0.0;
  end_constraint_step(m, base, tools, s, rep);
}

// The contact points at positions x: where they are (also as solved), their gaps, the tools'
// surface points and normals they are measured to.
void ContactSolver::measure_contacts(const std::vector<ToolShape>& tools, const NodeMat& x) {
  for (ContactPoint& c : contacts_) {
    c.point = point_of(c, x);
    c.solved = c.point;
    c.gap = contact_gap(tools[static_cast<size_t>(c.tool)], c.point, c.start, c.surface, c.normal);
  }
}

void ContactSolver::sort_contacts() { std::sort(contacts_.begin(), contacts_.end(), in_order); }

// The nodes the contact points use (contact_nodes_) and each one's index there (node_slot_).
void ContactSolver::collect_contact_nodes() {
  for (int i : contact_nodes_) node_slot_[static_cast<size_t>(i)] = -1;
  contact_nodes_.clear();
  for (const ContactPoint& c : contacts_)
    for (int v = 0; v < c.count; ++v)
      if (node_slot_[static_cast<size_t>(c.node[v])] < 0) {
        node_slot_[static_cast<size_t>(c.node[v])] = static_cast<int>(contact_nodes_.size());
        contact_nodes_.push_back(c.node[v]);
      }
}

// On the linear model point = point_solved + W (f - f_solved), the forces that keep the laws
// (a projected Gauss-Seidel from the points' forces): lambda_c_ (per point in its frame) and
// force_c_ (in world axes) the forces found, motion_c_ the motion they predict of each point;
// `scale` multiplies the compliance. With `rounds` > 1 the laws are linearised where the
// points are predicted to go, not only where they were solved: after a round of Gauss-Seidel
// the frames (the tool's normal and tangents) and gaps are measured again where that round's
// forces put the points, and the next round starts from there, until a round moves no point
// by more than the tolerance. On a round tool a point slides around the tool and its force
// turns with the tool's normal; a tangent plane holds a point that slides along a probe's tip
// outside the tip by the square of its slide over the tip's diameter, so that a slide's patch
// is dragged ahead of the probe and comes back over many of the organ's solves (a
// frictionless slide on the core: 8 iterations a step instead of 17, median). `violation`:
// how far the measured state breaks the laws; `change`: how far the forces found would move a
// point.
void ContactSolver::project_forces(const std::vector<ToolShape>& tools, bool exact, double scale, double& violation,
                                  double& change, int rounds) {
  const int C = static_cast<int>(contacts_.size());
  const double mu = std::max(0.0, settings_.friction);
  const size_t n3 = 3 * static_cast<size_t>(C);
  resize_with_headroom(frames_, static_cast<size_t>(C));
  resize_square_with_headroom(compliance_c_, n3);
  resize_square_with_headroom(delassus_, n3);
  resize_with_headroom(residual_c_, n3);
  resize_with_headroom(lambda_c_, n3);
  resize_with_headroom(change_c_, n3);
  resize_with_headroom(force_c_, n3);
  resize_with_headroom(motion_c_, n3);
  Eigen::Map<Eigen::MatrixXd> compliance(compliance_c_.data(), 3 * C, 3 * C), delassus(delassus_.data(), 3 * C, 3 * C);
  Eigen::Map<Eigen::VectorXd> residual_c(residual_c_.data(), 3 * C), lambda_c(lambda_c_.data(), 3 * C),
      change_c(change_c_.data(), 3 * C), force(force_c_.data(), 3 * C), motion(motion_c_.data(), 3 * C);
  // The compliance between the points, in world axes.
  for (int a = 0; a < C; ++a) {
    const ContactPoint& ca = contacts_[static_cast<size_t>(a)];
    for (int b = 0; b <= a; ++b) {
      const ContactPoint& cb = contacts_[static_cast<size_t>(b)];
      Eigen::Matrix3d w = Eigen::Matrix3d::Zero();
      for (int va = 0; va < ca.count; ++va)
        for (int vb = 0; vb < cb.count; ++vb) {
          const int ia = node_slot_[static_cast<size_t>(ca.node[va])], ib = node_slot_[static_cast<size_t>(cb.node[vb])];
          const double ww = ca.weight[va] * cb.weight[vb];
          if (exact) w += ww * exact_compliance_.block<3, 3>(3 * ia, 3 * ib);
          else
            for (int d = 0; d < 3; ++d) w(d, d) += ww * compliance_.at(d, ia, ib);
        }
      compliance.block<3, 3>(3 * a, 3 * b) = scale * w;
      compliance.block<3, 3>(3 * b, 3 * a) = scale * w.transpose();
    }
  }
  // How far the measured state breaks the laws (each point in its measured frame; the
  // tangential part below, once the forces are found).
  violation = 0.0;
  for (int a = 0; a < C; ++a) {
    const ContactPoint& c = contacts_[static_cast<size_t>(a)];
    const double fn = c.normal.dot(c.force);
    violation = std::max(violation, fn > 0.0 ? std::abs(c.gap) : std::max(0.0, -c.gap));
    force.segment<3>(3 * a) = c.force;
  }
  motion.setZero();
  for (int round = 0; round < rounds; ++round) {
    // Each point's frame, gap and slip where the forces so far put it; on a tool other than a
    // capsule, and deep in a tool (contact_gap's push-out along the relative motion), along
    // its measured normal: a box's or a hull's faces are flat, and their normal jumps at the
    // edges, where measuring again would turn the point's force from face to face.
    for (int a = 0; a < C; ++a) {
      const ContactPoint& c = contacts_[static_cast<size_t>(a)];
      const ToolShape& t = tools[static_cast<size_t>(c.tool)];
      const Vec3 q = c.point + motion.segment<3>(3 * a);
      Vec3 surface, n = c.normal;
      double gap = c.gap + c.normal.dot(q - c.point);
      if (t.kind == ToolShape::Kind::capsule && c.gap >= -0.25 * t.size()) {
        const double d = tool_distance(t, q, surface, n);
        if (d >= -0.25 * t.size()) gap = d;
        else n = c.normal;
      }
      frames_[static_cast<size_t>(a)] = contact_frame(n);
      const Eigen::Matrix3d& F = frames_[static_cast<size_t>(a)];
      const Vec3 slip = q - c.start - t.motion_at(q);
      residual_c.segment<3>(3 * a) = Vec3(gap, F.col(1).dot(slip), F.col(2).dot(slip));
      lambda_c.segment<3>(3 * a) = F.transpose() * force.segment<3>(3 * a);
    }
    for (int a = 0; a < C; ++a)
      for (int b = 0; b <= a; ++b) {
        const Eigen::Matrix3d block = frames_[static_cast<size_t>(a)].transpose() *
                                      compliance.block<3, 3>(3 * a, 3 * b) * frames_[static_cast<size_t>(b)];
        delassus.block<3, 3>(3 * a, 3 * b) = block;
        delassus.block<3, 3>(3 * b, 3 * a) = block.transpose();
      }
    // Projected Gauss-Seidel: change_c holds the predicted residuals as the forces change.
    change_c = residual_c;
    for (int sweep = 0; sweep < 200; ++sweep) {
      double moved = 0.0, moved_point = 0.0, largest = 0.0;
      for (int a = 0; a < C; ++a) {
        const Eigen::Matrix3d A = delassus.block<3, 3>(3 * a, 3 * a);
        const Vec3 old = lambda_c.segment<3>(3 * a);
        Vec3 f = old;
        if (!(A(0, 0) > 0.0)) {  // a point that cannot move (every node fixed): no force
          f.setZero();
        } else {
          f[0] = std::max(0.0, old[0] - change_c[3 * a] / A(0, 0));
          const Eigen::Vector2d qt = change_c.segment<2>(3 * a + 1) + A.block<2, 1>(1, 0) * (f[0] - old[0]);
          const Eigen::Matrix2d Att = A.block<2, 2>(1, 1);
          Eigen::Vector2d ft = old.tail<2>();
          if (mu > 0.0 && Att.determinant() > 1e-12 * Att.squaredNorm()) ft -= Att.inverse() * qt;
          const double cone = mu * f[0], len = ft.norm();
          if (len > cone) ft *= len > 0.0 ? cone / len : 0.0;
          f.tail<2>() = ft;
        }
        const Vec3 delta = f - old;
        if (delta.squaredNorm() > 0.0) {
          change_c.noalias() += delassus.middleCols<3>(3 * a) * delta;
          lambda_c.segment<3>(3 * a) = f;
          moved_point = std::max(moved_point, (A * delta).cwiseAbs().maxCoeff());
        }
        moved = std::max(moved, delta.cwiseAbs().maxCoeff());
        largest = std::max(largest, f.cwiseAbs().maxCoeff());
      }
      if (moved <= 1e-6 * largest || moved_point <= kSweepMotionShare * contact_tolerance_) break;
    }
    // The round's forces in world axes (a force the law zeroes is exactly zero), and how far
    // they move the points.
    double round_motion = 0.0;
    for (int a = 0; a < C; ++a) {
      const Vec3 moved = frames_[static_cast<size_t>(a)] * (change_c.segment<3>(3 * a) - residual_c.segment<3>(3 * a));
      motion.segment<3>(3 * a) += moved;
      round_motion = std::max(round_motion, moved.norm());
      force.segment<3>(3 * a) = frames_[static_cast<size_t>(a)] * lambda_c.segment<3>(3 * a);
    }
    if (round_motion <= contact_tolerance_) break;
  }
  // Converged: the solved state keeps the laws within the tolerance, and the forces the
  // pass found would move no contact point by more than it, along the normal or along the
  // tool (a slipping point's slip is free, but where it ends is the forces' answer: counting
  // the normal motion alone, frictionless nodes on a round tip stop up to 0.5 mm from where
  // a 25 times tighter tolerance puts them, against 0.08 mm).
  change = 0.0;
  for (int a = 0; a < C; ++a) {
    const ContactPoint& c = contacts_[static_cast<size_t>(a)];
    change = std::max(change, motion.segment<3>(3 * a).norm());
    // Tangentially only where the point sticks, by the forces it was solved with (in its
    // measured frame) and by the pass's (in the frame it found them in): a slipping point's
    // slip is free.
    const Eigen::Matrix3d F0 = contact_frame(c.normal);
    const Vec3 f = F0.transpose() * c.force, g = lambda_c.segment<3>(3 * a);
    const bool stuck = f[0] > 0.0 && f.tail<2>().norm() < mu * f[0] * (1.0 - 1e-3);
    const bool sticks = g[0] > 0.0 && g.tail<2>().norm() < mu * g[0] * (1.0 - 1e-3);
    if (stuck && sticks) {
      const Vec3 slip = c.point - c.start - tools[static_cast<size_t>(c.tool)].motion_at(c.point);
      violation = std::max(violation, (slip - c.normal * c.normal.dot(slip)).norm());
    }
  }
}

// The forces project_forces() found become the contact points' forces, with the motion they
// predict.
void ContactSolver::store_forces() {
  const int C = static_cast<int>(contacts_.size());
  Eigen::Map<const Eigen::VectorXd> force(force_c_.data(), 3 * C), motion(motion_c_.data(), 3 * C);
  for (int a = 0; a < C; ++a) {
    ContactPoint& c = contacts_[static_cast<size_t>(a)];
    c.force = force.segment<3>(3 * a);
    c.predicted = motion.segment<3>(3 * a);
  }
}

// The step's end: the state's results, the deepest penetration, the forces on the tools, the
// contact forces as the nodes' reactions.
void ContactSolver::end_constraint_step(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                        SimState& s, ContactReport& rep) {
  solver_->finish_step(s);
  const auto t0 = Clock::now();
  rep.max_penetration = deepest_surface_point(tools, s.x, rep);
  rep.collision_ms += ms_since(t0);
  // The forces of the organ on the tools, and the contact forces as the nodes' reactions.
  tool_force_.assign(tools.size(), Vec3::Zero());
  for (const ContactPoint& c : contacts_) tool_force_[static_cast<size_t>(c.tool)] -= c.force;
  for (const Vec3& f : tool_force_) rep.force += f;
  for (int i : contact_nodes_) {
    if (contact_force_.row(i).squaredNorm() == 0.0) continue;
    // (a node held on every axis, e.g. grasped, takes its share of a triangle point's force
    // through what holds it: it is not held by the tool)
    if (on_every_axis(base.prescribed, i) || on_every_axis(m.held, i)) continue;
    active_[static_cast<size_t>(i)] = 1;
    held_.push_back(i);
    s.reaction.row(i) = contact_force_.row(i);
    const double a = s.area_vectors.row(i).norm();
    s.reaction_pressure[i] = a > 0 ? contact_force_.row(i).norm() / a : 0.0;
  }
  std::sort(held_.begin(), held_.end());
  rep.nodes = static_cast<int>(held_.size());
}

void ContactSolver::save_state(std::string& out) const {
  auto put = [&](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
  const std::int64_t count = static_cast<std::int64_t>(contacts_.size());
  put(&compliance_scale_, sizeof compliance_scale_);
  put(&count, sizeof count);
  for (const ContactPoint& c : contacts_) {
    const std::int32_t ints[5] = {c.tool, c.triangle, c.node[0], c.node[1], c.node[2]};
    put(ints, sizeof ints);
    const std::int32_t n = c.count;
    put(&n, sizeof n);
    put(c.weight, sizeof c.weight);
    put(c.force.data(), 3 * sizeof(double));
  }
}

bool ContactSolver::load_state(std::string_view in, size_t& pos, int nodes, int triangles, std::string& error) {
  auto get = [&](void* p, size_t n) {
    if (in.size() < pos || in.size() - pos < n) return false;
    std::memcpy(p, in.data() + pos, n);
    pos += n;
    return true;
  };
  std::int64_t count = -1;
  double scale = 1.0;
  if (!get(&scale, sizeof scale) || !get(&count, sizeof count) || count < 0 || !(scale > 0.0) ||
      count > static_cast<std::int64_t>(nodes) + triangles) {
    error = "state snapshot: the contact state is truncated or damaged";
    return false;
  }
  contacts_.clear();
  for (std::int64_t k = 0; k < count; ++k) {
    ContactPoint c;
    std::int32_t ints[5], n = 0;
    if (!get(ints, sizeof ints) || !get(&n, sizeof n) || !get(c.weight, sizeof c.weight) ||
        !get(c.force.data(), 3 * sizeof(double)) || n < 1 || n > 3 || ints[0] < 0 || ints[1] < -1 ||
        ints[1] >= triangles) {
      error = "state snapshot: the contact state is truncated or damaged";
      return false;
    }
    c.tool = ints[0];
    c.triangle = ints[1];
    c.count = n;
    for (int v = 0; v < 3; ++v) {
      if (ints[2 + v] < 0 || ints[2 + v] >= nodes) {
        error = "state snapshot: the contact state is truncated or damaged";
        return false;
      }
      c.node[v] = ints[2 + v];
    }
    contacts_.push_back(c);
  }
  compliance_scale_ = scale;
  return true;
}

}  // namespace vdm
