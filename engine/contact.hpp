#pragma once
// Contact between the organ surface and rigid instruments (vdm-model.md section 5). Three
// methods, one file each; this class picks one per scene and owns their state:
//  - constraint (engine/contact_constraint.cpp, the default): non-penetration at surface
//    points with Coulomb friction (sliding and sticking);
//  - kinematic (engine/contact_kinematic.cpp): nodes that penetrate an instrument are
//    projected onto its surface and held there as prescribed displacements for the step;
//    nodes whose reaction would pull the instrument (adhesion) are released and the step
//    solved again (active set): the tissue sticks;
//  - penalty (engine/contact_penalty.cpp): frictionless springs on samples of the surface
//    triangles, solved implicitly.
// Broad phase: the organ's bounding-volume tree (engine/contact_broad_phase.hpp). Narrow
// phase: exact point-versus-shape signed distance (engine/tool_shape.hpp). Once warmed up (the
// same number and kinds of tools), a step allocates nothing in the contact code.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "engine/capsule_probe.hpp"
#include "engine/contact_broad_phase.hpp"
#include "engine/contact_compliance.hpp"
#include "engine/contact_settings.hpp"
#include "engine/push_out.hpp"
#include "engine/sim_state.hpp"
#include "engine/surface_force_law.hpp"
#include "engine/tool_shape.hpp"

namespace vdm {

class OrganSolver;

struct ContactReport {
  int nodes = 0;                   // nodes held by instruments after the step
  Vec3 force = Vec3::Zero();       // total force of the organ on the instruments (N)
  double max_penetration = 0.0;    // deepest free node inside an instrument after the step (m)
  int solves = 0;                  // engine solves this step (active-set iterations)
  int iterations = 0;              // linear-solver iterations summed over those solves
  bool converged = true;           // the active set stopped changing within the cap
  long queries = 0;                // FCL collision queries this step
  long refit_boxes = 0;            // boxes of the organ's tree refitted this step
  double collision_ms = 0.0;       // broad + narrow phase time
};

// A surface point in contact with a tool: a node, or a point inside a triangle (its
// barycentric weights on the triangle's nodes).
struct ContactPoint {
  int tool = 0;
  int triangle = -1;  // -1: a node contact (node[0])
  int node[3] = {0, 0, 0};
  double weight[3] = {1, 0, 0};
  int count = 1;                // nodes used
  Vec3 start = Vec3::Zero();    // the point at the step's start (m)
  Vec3 point = Vec3::Zero();    // the point now
  Vec3 surface = Vec3::Zero();  // the closest point of the tool's surface
  Vec3 normal = Vec3::UnitZ();  // the tool's outward normal there
  double gap = 0;               // signed distance to the tool (negative: inside)
  Vec3 force = Vec3::Zero();    // the tool's force on the organ there (N)
  Vec3 solved = Vec3::Zero();     // the point after the last solve
  Vec3 predicted = Vec3::Zero();  // how far the next solve should move it, by the compliance
};

class ContactSolver final : private SurfaceForceLaw {
 public:
  ContactSolver(const TissueModel& model, ContactSettings settings = {});
  ~ContactSolver();
  // One step with contact: `base` holds the scene's own loads and prescribed motion (it is
  // not modified); the instruments' constraints are added on top. Nodes whose motion `base`
  // prescribes on all three axes (grasped, scripted) take no part in contact.
  void step(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools, SimState& state,
            ContactReport& report);
  // The same, borrowing `base` (kinematic contact): each solve sets the held nodes' rows in
  // it and puts them back after, instead of working on a copy (saves copying the scene's
  // loads and constraints every step). On return `base` is as it was.
  void step(const TissueModel& model, StepInput& base, const std::vector<ToolShape>& tools, SimState& state,
            ContactReport& report);
  void step(const TissueModel& model, const StepInput& base, const std::vector<Capsule>& tools, SimState& state,
            ContactReport& report);
  // Steps the organ with `solver` (fem, mass_spring: the scene's organ model) instead of the
  // VDM engine on the model it was made with; null: that engine again. Contact reaches the
  // organ only through its OrganSolver (solve, rewind, the step's start).
  void set_solver(OrganSolver* solver);
  // Constraint contact on a model whose step a caller iterates together with other organs'
  // (OrganSolver::joint_begin): begin_joint() gives the input to begin the model's step with
  // and joint_law() the law to give it; the caller drives the iteration, then end_joint().
  // One solve: points that the solved surface meets where none was join the next step.
  const StepInput& begin_joint(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                               SimState& state, ContactReport& report);
  SurfaceForceLaw& joint_law() { return *this; }
  void end_joint(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools, SimState& state,
                 ContactReport& report);
  // Per-node flag: held by an instrument after the last step.
  const std::vector<char>& active() const { return active_; }
  // What the next step carries over from the last (constraint contact: its contact points'
  // forces, the warm start, and the compliance's fitted scale), appended to `out`; read back
  // by load_state() (false, with `error`, when it does not fit a model of `nodes` nodes and
  // `triangles` triangles). Nothing for the other methods: they carry nothing over.
  void save_state(std::string& out) const;
  bool load_state(std::string_view in, size_t& pos, int nodes, int triangles, std::string& error);
  // Per tool of the last step (in the order of its `tools`): the force of the organ on it (N).
  // Their sum is the report's force (with penalty contact, up to rounding: summed in another order).
  const std::vector<Vec3>& tool_forces() const { return tool_force_; }

 private:
  // Appends to `found` the nodes (with `triangles`: the triangles) whose triangles overlap
  // tool k (inflated by `pad`, m) and that mark_ (triangle_mark_) has not flagged yet,
  // flagging them; the tree as last refitted.
  void broad_phase(const ToolShape& t, size_t k, double pad, std::vector<int>& found, ContactReport& report,
                   bool triangles = false);
  void step_any(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools, SimState& state,
                ContactReport& report, StepInput* borrowed);
  // `borrowed`: base itself, changed for each solve and put back (null: a copy in input_).
  void step_kinematic(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                      SimState& state, ContactReport& report, StepInput* borrowed);
  void step_penalty(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                    SimState& state, ContactReport& report);
  void step_constraint(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                       SimState& state, ContactReport& report);
  // Constraint contact on a model that solves it inside its own iteration
  // (OrganSolver::trial_step_with; engine/contact_constraint_within.cpp): this solver is the
  // model's SurfaceForceLaw.
  void step_constraint_within(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                              SimState& state, ContactReport& report);
  // Constraint contact inside the model's iteration: the step's start (begin_within), and the
  // input of a solve from the base's forces and the contact points' as they stand.
  void begin_within(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools, SimState& state,
                    ContactReport& report);
  const StepInput& within_input(const TissueModel& model, const StepInput& base);
  bool update(const NodeMat& x, ComplianceSource& compliance, NodeMat& force) override;
  // Frictionless, and not in a joint step (where the other organs' forces change between the
  // model's iterations beside the law's).
  bool conservative() const override { return settings_.friction == 0 && !within_.joint; }
  // The parts of a constraint step: the contact points at the step's start (and the
  // tolerance); measured at positions x; in their fixed order; the nodes they use; the forces
  // on the linear model (project_forces: see there); those forces kept; the step's results.
  // With `carry`, the last step's points that held a force and still touch their tool start
  // the step as they were (the same triangle points, the same forces), and only new points
  // are found; else the points are found afresh, each triangle's taking the sum of its last
  // forces.
  void begin_constraint_step(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                             SimState& state, ContactReport& report, bool carry = false);
  void measure_contacts(const std::vector<ToolShape>& tools, const NodeMat& x);
  void sort_contacts();
  void collect_contact_nodes();
  void project_forces(const std::vector<ToolShape>& tools, bool exact, double scale, double& violation, double& change,
                      int rounds = 1);
  void store_forces();
  void end_constraint_step(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                           SimState& state, ContactReport& report);
  // Adds the contact points of `tools` at positions x not yet in contacts_: nodes and
  // triangle points closer to a tool than `limit` times its size (negative: inside). With
  // `warm`, each takes the force its match had at the end of the last step. Returns how many
  // it put in (some may take the place of a point left behind: takes_another_point).
  int find_contact_points(const TissueModel& model, const StepInput& base, const std::vector<ToolShape>& tools,
                           const NodeMat& x, const NodeMat& start, double limit, bool warm, ContactReport& report);
  // The deepest point of the surface inside a tool (m), over every triangle near one.
  double deepest_surface_point(const std::vector<ToolShape>& tools, const NodeMat& x, ContactReport& report);
  // The scene's own prescribed motion (grasp, scripted regions) into input_.
  void copy_scene_constraints(const TissueModel& model, const StepInput& base);
  // Penalty forces on the nodes at positions x (penalty_force_) and the per-axis spring
  // stiffness that bounds their Jacobian (penalty_spring_). Returns the deepest sample (m).
  // With `per_tool`, also each tool's share of the force on the nodes `base` does not drive.
  double penalty_forces(const std::vector<ToolShape>& tools, const NodeMat& x, ContactReport& report,
                        const StepInput* base = nullptr, std::vector<Vec3>* per_tool = nullptr);
  // Refits the organ's tree to positions x (nothing to do when they are those of the last refit).
  void refit(const NodeMat& x) { broad_.refit(x); }

  ContactSettings settings_;
  ContactBroadPhase broad_;
  const TriMat* triangles_ = nullptr;
  StepInput input_;
  std::unique_ptr<OrganSolver> own_solver_;  // the VDM engine on the model
  OrganSolver* solver_ = nullptr;             // the one used: own_solver_ or set_solver()'s
  std::vector<char> active_, mark_;  // mark_: nodes the broad phase found already
  std::vector<int> held_;       // the nodes flagged in active_
  std::vector<int> holder_;     // per node: the tool that holds it (while flagged in active_)
  std::vector<Vec3> tool_force_;
  // The input rows of the held nodes before a solve set them (put back after it).
  std::vector<Eigen::Matrix<std::uint8_t, 1, 3>> saved_flags_;
  std::vector<Eigen::RowVector3d> saved_u_;
  std::vector<double> close_d_;  // a node's distance to each tool, closest points and normals
  std::vector<Vec3> close_p_, close_n_;
  // Per held node (in held_'s order): its held position (m) and contact normal. Kept with
  // held_ rather than as N x 3 arrays: a handful of nodes are held at a time (-2 MB at 40k).
  std::vector<Eigen::RowVector3d> held_target_, held_normal_;
  std::vector<int> candidates_;
  std::vector<char> triangle_mark_;       // triangles the broad phase found already
  NodeMat penalty_force_, penalty_spring_, iterate_;  // penalty (N x 3)
  // Anderson acceleration of the penalty iteration: the last differences of the solves'
  // results (G) and residuals (F = G - u), a ring of kAnderson.
  static constexpr int kAnderson = 5;
  NodeMat anderson_dg_[kAnderson], anderson_df_[kAnderson];
  NodeMat last_g_, last_f_, residual_, x_iterate_;
  std::vector<ToolShape> capsule_tools_;  // the Capsule overload's tools
  // Constraint contact.
  std::vector<ContactPoint> contacts_, last_contacts_;
  std::vector<int> node_tool_, triangle_tool_;  // per node / triangle: the tool of its contact point, or -1
  std::vector<int> contact_nodes_, node_slot_;  // the nodes the contacts use; node -> index there (or -1)
  std::vector<int> compliance_nodes_;           // the nodes of the last compliance computed
  long compliance_refreshes_ = -1;              // the engine's refresh count then
  PatchCompliance compliance_;
  // The organ's exact compliance at contact_nodes_ (3n x 3n), when its model gives one
  // (OrganSolver::surface_compliance): then it takes the patch's place, its scale fitted at
  // every correction.
  Eigen::MatrixXd exact_compliance_;
  bool exact_compliance_used_ = false;
  // The Gauss-Seidel's arrays, in vectors that keep their capacity (Eigen's resize would
  // allocate whenever the number of contacts changes): the compliance between the contact
  // points in world axes and in their frames (3C x 3C, the Delassus operator); per round the
  // residuals, forces and predicted residuals in the frames; the forces found and the motion
  // they predict in world axes; each point's frame (n, t1, t2) in the last round.
  std::vector<double> compliance_c_, delassus_, residual_c_, lambda_c_, change_c_, force_c_, motion_c_;
  std::vector<Eigen::Matrix3d> frames_;
  double compliance_scale_ = 1.0;               // fitted: the organ's compliance over the patch's
  double contact_tolerance_ = 0.0;              // this step's, m (ContactSettings::constraint_tolerance x the smallest tool)
  // What update() needs of the step it runs in (step_constraint_within).
  struct WithinStep {
    const TissueModel* model = nullptr;
    const StepInput* base = nullptr;
    const std::vector<ToolShape>* tools = nullptr;
    const SimState* state = nullptr;
    ContactReport* report = nullptr;
    bool joint = false;  // begin_joint ... end_joint
  } within_;
  std::vector<Eigen::RowVector3d> old_force_;  // update(): the contact nodes' forces before it
  // The most rounds project_forces() takes inside the model's iteration (relinearising the laws
  // at the points' predicted positions), and this step's: one after a solve that did not
  // converge with more (step_constraint_within).
  static constexpr int kGeometryRounds = 4;
  int rounds_ = 1;
  NodeMat contact_force_;                        // N x 3
};

}  // namespace vdm
