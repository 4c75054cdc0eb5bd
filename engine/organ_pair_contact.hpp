#pragma once
// Organs against organs: contact (no node of one organ enters another, with Coulomb friction)
// and ties (attachments: a node of one organ held to a material point of another's surface by
// a spring, which tears above a force).
//
// Contact: each node of an organ within `reach` of another organ's surface (or inside it) is a
// contact point (one-sided: of two organs, the nodes of the finer surface, by its mean edge at
// rest, against the coarser surface; the coarser one's nodes may then enter the finer by about
// the sagitta of its edges, edge^2 / 8 R on a curvature radius R) against the closest point of that surface (a triangle, barycentric weights).
// The point's force pushes its node out along the other surface's normal there (interpolated
// from its vertex normals: it turns continuously from one triangle to the next) and, by
// friction, against its slip over the step relative to that surface; the other organ's
// triangle corners take the opposite force (Newton's third law). Friction acts on points that
// were pressed at the step's start (a point that touches first slides freely in that step).
//
// The forces come from a projected Gauss-Seidel on the points' relative compliance
// W = sum over organs of J C J^T, C each organ's own compliance at the nodes involved
// (OrganSolver::surface_compliance, at its last solve): the linear model of how far each point
// would move under the forces. The caller iterates: solve every organ under its forces, find
// the points at the solved positions, correct the forces, until the organs' iterations have
// converged (the same scheme as one organ's constraint contact around its solves). Each node
// keeps its force from one correction to the next and from step to step (the warm start).
#include <array>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "engine/types.hpp"

namespace vdm {

class OrganSolver;

// A tie of an attachment: node `node` of organ `owner` held to the point (corner, weight) of
// organ `other`'s surface at `offset` from it (its rest offset), by a spring of `stiffness`
// (N/m) in every direction, which lets go (tears) when its force passes `tear` (N).
struct OrganTie {
  int owner = 0, node = 0, other = 0;
  int corner[3] = {0, 0, 0};
  double weight[3] = {1, 0, 0};
  Vec3 offset = Vec3::Zero();
  double stiffness = 0;
  double tear = std::numeric_limits<double>::infinity();
};

class OrganPairContact {
 public:
  struct Point {
    int owner = 0, node = 0;     // the organ and node pushed out (or held)
    int other = 0, triangle = 0; // the surface it is held out of (or to), its triangle there
    int corner[3] = {0, 0, 0};   // that triangle's nodes
    double weight[3] = {1, 0, 0};
    Vec3 normal = Vec3::UnitZ(); // contact: the other surface's outward normal at the point
    double gap = 0;              // contact: signed distance from the other surface (m)
    int tie = -1;                // a tie's index; -1: a contact point
  };

  // For organs with `nodes[i]` nodes each and mean edges `edge[i]` at rest (m), friction
  // coefficient `friction` between organs.
  OrganPairContact(const std::vector<int>& nodes, const std::vector<double>& edge, double friction,
                   std::vector<OrganTie> ties = {});

  // A new step from the organs' positions `start` (kept for the slips).
  void begin_step(const std::vector<const NodeMat*>& start);
  // The points at positions x[i] of surfaces triangles[i]: every node within `reach` (m) of
  // another organ's surface or inside it (up to a few cells of the surface's edges deep),
  // every point found earlier in the step, measured again, and every tie not torn.
  void find_points(const std::vector<const NodeMat*>& x, const std::vector<const TriMat*>& triangles, double reach);
  const std::vector<Point>& points() const { return points_; }

  // Corrects the points' forces so that, on the organs' linear response, every gap closes to at
  // least zero with no pulling force, pressed points stick within their friction cone or slip
  // on it, and ties follow their springs. An organ whose solver is null does not yield (its
  // surface moves as its caller sets it: no compliance). False when an organ's solver gives no
  // compliance.
  // `violation`: the deepest penetration before the correction (m); `change`: the largest
  // move the correction predicts for a point (m).
  bool correct(const std::vector<OrganSolver*>& solvers, double& violation, double& change);

  // Organ i's forces from the others put into `force` in place of those this put there last
  // in this step.
  void apply(int organ, NodeMat& force);
  // Organ i waits (is not solved, and its solver's answer does not take the forces): its
  // positions as the contact sees them, `answer` (its solver's, with the forces as apply() last
  // put them) moved at the points' nodes by its compliance times the change of its forces
  // since then. Call after correct(); pass the result to the next find_points().
  const NodeMat& predict(int organ, const NodeMat& answer);
  // The step is over: ties whose force passed their tear force let go (from the next step on),
  // and the points pressed now are those that carry friction into the next step.
  void end_step();

  // The total force the other organs put on organ i by contact, and by ties (N).
  Vec3 contact_force(int organ) const;
  Vec3 tie_force(int organ) const;
  // Ties: how many, how many have torn, and the largest force any holds now (N).
  int ties() const { return static_cast<int>(ties_.size()); }
  int torn() const;
  // Whether organs i and j are tied by a tie that holds.
  bool tied(int i, int j) const;
  double largest_tie_force() const;
  // Adds, per node, the forces the other organs put on organ i now (contact and ties) to `force`.
  void add_forces(int organ, NodeMat& force) const;

  // What a step carries to the next (forces, pressed points, torn ties), appended to `out`;
  // load_state() reads it back (false with `error` when it does not fit these organs).
  void save_state(std::string& out) const;
  bool load_state(std::string_view in, size_t& pos, std::string& error);

 private:
  // A point's normal and gap at node position p, its closest point's weights set.
  void measure(Point& point, const Vec3& p, const NodeMat& x_other, const TriMat& t_other);
  Vec3& force_of(const Point& p) { return p.tie >= 0 ? tie_lambda_[static_cast<size_t>(p.tie)] : lambda_[static_cast<size_t>(p.owner)][static_cast<size_t>(p.node)]; }
  const Vec3& force_of(const Point& p) const {
    return p.tie >= 0 ? tie_lambda_[static_cast<size_t>(p.tie)] : lambda_[static_cast<size_t>(p.owner)][static_cast<size_t>(p.node)];
  }

  // Whether organ i's nodes are held out of organ j's surface (the finer against the coarser).
  bool slave(int i, int j) const;
  std::vector<int> nodes_;
  std::vector<double> edge_;
  double friction_ = 0;
  std::vector<OrganTie> ties_;
  std::vector<Vec3> tie_lambda_;             // per tie, its force on its node (N)
  std::vector<char> tie_torn_;
  std::vector<Point> points_;
  std::vector<NodeMat> start_;               // per organ, its positions at the step's start
  std::vector<const NodeMat*> x_;            // per organ, its positions at the last find_points
  std::vector<NodeMat> applied_;             // per organ, its forces as apply() last put them
  std::vector<std::vector<Vec3>> lambda_;    // per organ, per node: its contact force (N)
  std::vector<std::vector<char>> pressed_;   // per organ, per node: pressed at the step's start
  // Per organ, its surface's vertex normals where a point needs them (normal_at): the vertex's
  // triangles (ring_start_, ring_), and the find_points call each normal was computed in.
  std::vector<NodeMat> normals_;
  std::vector<std::vector<int>> ring_start_, ring_, normal_call_;
  int call_ = 0;
  // Per organ that other organs are held out of, the uniform grid of its triangles: cell c's
  // triangles are items[start[c] .. start[c + 1]), each binned by its box grown by
  // kGridSlack; kept while no node has moved more than that since `built` (begin_step
  // drops it).
  struct Grid {
    bool valid = false;
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
    double cell = 0;
    Eigen::Array3i dims = Eigen::Array3i::Zero();
    std::vector<int> start, fill, items;
    NodeMat built;
  };
  std::vector<Grid> grids_;
  void build_grid(const NodeMat& x, const TriMat& t, double reach, Grid& g);
  // Organ j's unit vertex normal at node v, at positions x (as distributed_area_vectors sums it).
  Vec3 normal_at(int j, int v, const NodeMat& x, const TriMat& t);
  std::vector<Eigen::MatrixXd> compliance_;  // per organ, at node_list_[organ]
  std::vector<std::vector<int>> compliance_nodes_;  // per organ, the nodes compliance_ is at
  std::vector<char> compliance_valid_;       // per organ: compliance_ is this step's
  std::vector<NodeMat> predicted_;           // per organ, predict()'s positions
  NodeMat pending_;                          // predict()'s forces on an organ
  // Scratch of find_points(), correct() and predict(), grown to the most points seen and never
  // shrunk, so that a step allocates nothing once warm (the matrices are used through their
  // top-left corners).
  struct Entry {
    int organ, slot;
    double c;
  };
  std::vector<char> measured_;
  std::vector<std::array<Entry, 4>> entries_;
  std::vector<Vec3> residual_;
  std::vector<Eigen::Matrix3d> frame_;
  std::vector<double> normal_inverse_;
  std::vector<Eigen::Matrix2d> tangent_inverse_;
  Eigen::MatrixXd W_, tie_block_;
  Eigen::VectorXd lambda_scratch_, moved_, tie_rhs_, tie_next_, tie_moved_, tie_residual_, force_change_;
  void reserve_scratch(size_t points, size_t ties);
  std::vector<std::vector<int>> node_list_, node_slot_;
};

}  // namespace vdm
