#pragma once
// The simulation side of a scene run, one frame at a time: scripted loads and motions,
// grasping, contact (with sub-steps against tunnelling) and the VDM step. Only the effects
// the scene lists run. Deterministic: the same scene gives the same numbers every time.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "app/simulation/prepared_scene.hpp"
#include "engine/contact.hpp"
#include "engine/organ_pair_contact.hpp"
#include "engine/organ_solver.hpp"
#include "engine/sim_state.hpp"
#include "tools_scripted/grasp.hpp"

namespace vdmsim {

// Time spent in each stage, summed over the frames so far (ms).
struct StageTimes {
  double loads = 0, assemble = 0, solve = 0, stress = 0, grasp = 0, collision = 0;
  long collision_queries = 0;
};

// How far one organ may lie inside another before a run stops (m): contact between organs is
// not simulated; organs placed touching overlap by a little where their triangles cut corners.
constexpr double kOrganOverlap = 0.001;

// Contact between organs (vdm_core organs with constraint contact): nodes this close to
// another organ's surface are its contact points (m).
constexpr double kOrganContactReach = 0.002;

class SceneSimulation {
 public:
  explicit SceneSimulation(const PreparedScene& prepared);
  // Simulates frame f, the scene at time f dt; call it for f = 0, 1, 2, ... in turn. Frame 0
  // is the scene at t = 0, before the script moves anything: with inertia the initial
  // condition (the organ at rest, no step taken); quasi-static, the equilibrium under what
  // acts at t = 0, found by one step with the instruments held at their t = 0 poses (the rest
  // shape unless an instrument starts touching the organ, a grasper starts closed on it, or a
  // load or gravity acts at t = 0). Frame f >= 1 is one step from (f - 1) dt to f dt.
  void advance(int f);
  // The time of frame f (its time(), known without simulating it).
  static double frame_time(int f, double dt) { return f * dt; }

  // The organs in the scene's order; the first organ's state (the only one in the one-organ
  // form) and organ i's.
  size_t organ_count() const { return organs_.size(); }
  const vdm::SimState& state() const { return organs_.front().state; }
  const vdm::SimState& state(size_t organ) const { return organs_[organ].state; }
  // Whether an organ's engine could not do the last frame, and why (the first such organ's, with
  // its name when there are several).
  bool failed() const;
  std::string failure() const;
  // Every organ's warnings (with its name before each when there are several).
  std::vector<std::string> warnings() const;
  // Organ i's largest |volume_rel_error| over the frames so far.
  double max_volume_error(size_t organ) const { return organs_[organ].max_volume_error; }
  // Every organ's current positions in one N x 3 matrix, in the order of PreparedScene::surface
  // (the first organ's own state.x when it is the only one).
  const vdm::NodeMat& positions() const { return organs_.size() == 1 ? organs_.front().state.x : positions_; }
  double time() const { return time_; }
  // Whether the last frame took a step (all but an inertial scene's frame 0).
  bool frame_stepped() const { return frame_stepped_; }
  double frame_step_ms() const { return frame_step_ms_; }   // engine time of the last frame
  int frame_iterations() const { return frame_iterations_; }
  // Organ i's solver iterations in this simulation's steps so far (every solve; none while it
  // is followed).
  long organ_iterations(size_t organ) const { return organs_[organ].iterations; }
  int frame_fallbacks() const { return frame_fallbacks_; }  // solves redone by the direct solver
  bool contact_simulated() const { return contact_; }
  // Whether contact between organs is simulated, and the other organs' force on organ i (N).
  bool organ_contact_simulated() const { return pair_ != nullptr; }
  vdm::Vec3 organ_contact_force(size_t organ) const { return pair_ ? organ_force_[organ] : vdm::Vec3::Zero(); }
  // The same per node: the forces the other organs put on organ i after the last step (contact
  // and ties; zero without organ contact).
  vdm::NodeMat organ_contact_forces(size_t organ) const;
  // Organ i's surface (its positions, N x 3), per frame and per sub-step, appended to `out` by
  // every advance() from now on (`out` must outlive those calls). Null: none.
  using SubstepSurfaces = std::vector<std::vector<vdm::NodeMat>>;
  void record_organ_surface(size_t organ, SubstepSurfaces* out);
  // Organ i is not simulated: its surface follows `recorded` (as record_organ_surface() gives
  // it, from a run of the same scene), a surface that does not yield, which the other organs
  // meet through their contact and ties as they would meet the organ. A study runs one organ
  // alone this way, with its neighbour moving as it moved in the whole scene. A frame stepped
  // in another number of sub-steps than was recorded takes, at each sub-step, the recorded one
  // as far through the frame; past the list's end the organ stays where it is. The list must
  // outlive the advance() calls and is not part of save()'s snapshot. Null: simulated.
  void follow_recorded_surface(size_t organ, const SubstepSurfaces* recorded);
  // The attachments' ties: how many, and how many have torn.
  int organ_ties() const { return pair_ ? pair_->ties() : 0; }
  int organ_ties_torn() const { return pair_ ? pair_->torn() : 0; }
  // The last frame's contact over every organ (nodes, forces and solves summed, the deepest
  // penetration, converged when every organ's was), and organ i's own.
  const vdm::ContactReport& contact_report() const { return report_; }
  const vdm::ContactReport& contact_report(size_t organ) const { return organs_[organ].report; }
  // Whether the instruments can push or hold the organ (contact or grasp listed, and some
  // instrument): the forces below are then measured.
  bool forces_simulated() const { return contact_ || grasp_; }
  // Per instrument (the scene's order), the force of the organ on it at the end of the last
  // frame (N): its contact (probe, or grasper's jaws and shaft) and its grasped nodes'
  // reactions. total_force() is their sum.
  const std::vector<vdm::Vec3>& instrument_forces() const { return instrument_force_; }
  vdm::Vec3 total_force() const;
  // The same per organ: organ i's force on each instrument, and their sum.
  const std::vector<vdm::Vec3>& instrument_forces(size_t organ) const { return organs_[organ].force; }
  vdm::Vec3 total_force(size_t organ) const;
  // Per instrument, the largest |force| of any frame so far (N).
  const std::vector<double>& peak_forces() const { return peak_force_; }
  // Contact steps so far (sub-steps included, each organ's counted) whose active set was still changing at the cap,
  // and the linear-solver iterations of every contact solve so far.
  long unconverged_contact_steps() const { return unconverged_steps_; }
  long contact_iterations() const { return contact_iterations_; }
  // Why the last frame's results cannot be trusted, or empty: a non-finite value among those a
  // run writes (displacement, volume, pressure, residual, stress, reactions, forces), a
  // displacement larger than twice the organ's size (a material or load far out of range), two
  // holds (graspers, organ.prescribed) moving the same node to places far apart, or a probe's
  // tip far inside the organ (contact could not push it away: a rigid organ?), or two organs
  // passed into each other by more than kOrganOverlap.
  std::string unsound() const;
  const StageTimes& stage_times() const { return times_; }
  // A snapshot of the simulation between frames (the engine's state with its warm starts,
  // organ.model vdm_core's lattice state, the grasps, the contact's carry and the run's
  // tallies), appended to `out`, for resuming a run bit for bit. False when this run's state
  // cannot be saved (organ.model fem or mass_spring: a resume re-simulates instead).
  bool save(std::string& out) const;
  // Reads a snapshot written by save() for the same prepared scene.
  bool load(std::string_view in, std::string& error);
  // Every instrument's pose at time t (in the scene's order).
  std::vector<tools::InstrumentPose> poses(double t) const;

 private:
  // One organ's part of the simulation: its solver (organ.model's own, null for vdm), contact
  // and grasps against the scene's instruments, its state and step input, and the holds noted
  // on its nodes this frame.
  struct OrganRun {
    const PreparedOrgan* prepared = nullptr;
    const OrganDef* def = nullptr;
    std::unique_ptr<vdm::OrganSolver> solver;
    std::unique_ptr<vdm::ContactSolver> contact;
    vdm::ContactReport report;
    vdm::SimState state;
    vdm::StepInput input;
    std::vector<tools::Grasp> grasps;  // per grasper (when grasping is simulated)
    std::vector<vdm::Vec3> force;      // per instrument: this organ's force on it (N)
    double size = 0;                   // the rest surface's bounding-box diagonal (m), for unsound()
    double max_volume_error = 0;       // the largest |volume_rel_error| so far
    // Holds of the same node against each other, found by advance(): the node's holders
    // (per node: -1 none, k >= 0 instruments[k], <= -2 prescribed[-2 - k]).
    std::vector<int> holder;
    const SubstepSurfaces* followed = nullptr;  // follow_recorded_surface()
    vdm::NodeMat followed_x;                    // its surface at the end of this sub-step
    SubstepSurfaces* recorded = nullptr;        // record_organ_surface()
    long iterations = 0;                        // organ_iterations()
  };
  // A followed organ's surface at the end of sub-step j of n of frame f (followed_x).
  void set_followed_surface(OrganRun& o, int f, int j, int n);
  // After a (sub-)step: followed organs moved to their surfaces, and the surfaces of the organs
  // being recorded appended to their frame's lists.
  void end_substep();

  const PreparedScene& ps_;
  std::vector<const tools::InstrumentDef*> probes_, graspers_;
  std::vector<size_t> probe_index_, grasper_index_;  // their places in the scene's instruments
  std::vector<OrganRun> organs_;
  bool contact_ = false, grasp_ = false;  // contact and grasping simulated
  std::vector<vdm::ToolShape> tools_;  // probes' shapes, then two jaw boxes and a shaft per grasper
  vdm::ContactReport report_;
  vdm::NodeMat positions_;  // every organ's positions, with several organs
  StageTimes times_;
  double time_ = 0, frame_step_ms_ = 0;
  bool frame_stepped_ = false;
  int frame_iterations_ = 0, frame_fallbacks_ = 0;
  std::vector<vdm::Vec3> instrument_force_;
  std::vector<double> peak_force_;
  long unconverged_steps_ = 0, contact_iterations_ = 0;
  // The farthest apart of this frame's conflicting holds (its message; empty: none).
  std::vector<std::pair<int, vdm::Vec3>> earlier_hold_;  // (node, its earlier holder's target)
  double conflict_gap_ = 0;
  std::string conflict_;
  // Contact between the organs (null: not simulated) and the other organs' force on each.
  std::unique_ptr<vdm::OrganPairContact> pair_;
  std::vector<vdm::Vec3> organ_force_;
  std::vector<const vdm::NodeMat*> joint_x_;
  std::vector<const vdm::TriMat*> joint_triangles_;
  std::vector<vdm::OrganSolver*> joint_solvers_;
  std::vector<char> joint_active_;
  std::vector<char> joint_member_;  // this step: stepped with other organs (near them, or tied)
  // Per organ, in the step's iteration (step_joint): not solved this round; converged; every
  // cheaper organ converged; seen through its compliance; at its fixed point at its last solve.
  std::vector<char> joint_waiting_, joint_converged_, joint_ready_, joint_linear_, joint_fixed_;
  std::vector<vdm::NodeMat> joint_solved_x_;  // per organ, its answer at its last solve
  std::vector<size_t> joint_order_;  // the organs, cheapest (fewest nodes) first
  std::vector<vdm::Vec3> joint_lo_, joint_hi_;  // per organ, its grown box this step
  std::string rest_overlap_;  // organs inside each other at the first frame (with contact between organs)
  // Which organs step together this step (joint_member_).
  void find_joint_organs();
  // How far back from an instrument's tip along its axis it can meet an organ in a frame that
  // moves it from `before` to `now` (its collision shapes moving by at most `move`).
  double reach_into_organs(const tools::InstrumentDef& in, const tools::InstrumentPose& now,
                           const tools::InstrumentPose& before, double move) const;
  // Whether organ i was stepped with others this step.
  bool joint(size_t i) const { return pair_ && joint_member_[i]; }
  // One step of every organ with their iterations in lockstep: after each linear solve of
  // every organ (each with its instruments' contact law), the contact between the organs is
  // solved on their compliances at that linearisation and its forces put on both; the step
  // ends when every organ's iteration has converged.
  void step_joint();
  void note_hold(OrganRun& o, int node, int holder, const vdm::Vec3& before, const vdm::Vec3& after);
  // The scripted loads, motions and grasps of organ o at time t.
  void apply_script(OrganRun& o, double t);
  std::string unsound(const OrganRun& o) const;
  // positions_ from the organs' states (with several organs).
  void gather_positions();
  std::string deep_probe() const;
  std::string organs_overlap(bool placed = false) const;
  std::string deep_probe_cause(const OrganRun& o, size_t probe) const;
  // The forces of the frame just simulated (each organ's, instrument_force_, peak_force_).
  void measure_forces();
  // Where a message about organ o starts: "" with one organ, else its name and ": ".
  std::string organ_prefix(const OrganRun& o) const;
};

}  // namespace vdmsim
