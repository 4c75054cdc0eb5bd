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
#include "engine/organ_solver.hpp"
#include "engine/sim_state.hpp"
#include "tools_scripted/grasp.hpp"

namespace vdmsim {

// Time spent in each stage, summed over the frames so far (ms).
struct StageTimes {
  double loads = 0, assemble = 0, solve = 0, stress = 0, grasp = 0, collision = 0;
  long collision_queries = 0;
};

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

  const vdm::SimState& state() const { return state_; }
  double time() const { return time_; }
  // Whether the last frame took a step (all but an inertial scene's frame 0).
  bool frame_stepped() const { return frame_stepped_; }
  double frame_step_ms() const { return frame_step_ms_; }   // engine time of the last frame
  int frame_iterations() const { return frame_iterations_; }
  int frame_fallbacks() const { return frame_fallbacks_; }  // solves redone by the direct solver
  bool contact_simulated() const { return contact_ != nullptr; }
  const vdm::ContactReport& contact_report() const { return report_; }
  // Whether the instruments can push or hold the organ (contact or grasp listed, and some
  // instrument): the forces below are then measured.
  bool forces_simulated() const { return contact_ != nullptr || !grasps_.empty(); }
  // Per instrument (the scene's order), the force of the organ on it at the end of the last
  // frame (N): its contact (probe, or grasper's jaws and shaft) and its grasped nodes'
  // reactions. total_force() is their sum.
  const std::vector<vdm::Vec3>& instrument_forces() const { return instrument_force_; }
  vdm::Vec3 total_force() const;
  // Per instrument, the largest |force| of any frame so far (N).
  const std::vector<double>& peak_forces() const { return peak_force_; }
  // Contact steps so far (sub-steps included) whose active set was still changing at the cap,
  // and the linear-solver iterations of every contact solve so far.
  long unconverged_contact_steps() const { return unconverged_steps_; }
  long contact_iterations() const { return contact_iterations_; }
  // Why the last frame's results cannot be trusted, or empty: a non-finite value among those a
  // run writes (displacement, volume, pressure, residual, stress, reactions, forces), a
  // displacement larger than twice the organ's size (a material or load far out of range), two
  // holds (graspers, organ.prescribed) moving the same node to places far apart, or a probe's
  // tip far inside the organ (contact could not push it away: a rigid organ?).
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
  const PreparedScene& ps_;
  std::vector<const tools::InstrumentDef*> probes_, graspers_;
  std::vector<size_t> probe_index_, grasper_index_;  // their places in the scene's instruments
  std::vector<tools::Grasp> grasps_;
  std::unique_ptr<vdm::OrganSolver> organ_;  // organ.model vdm_core, fem or mass_spring: this run's own
  std::unique_ptr<vdm::ContactSolver> contact_;
  std::vector<vdm::ToolShape> tools_;  // probes' shapes, then two jaw boxes per grasper
  vdm::ContactReport report_;
  vdm::SimState state_;
  vdm::StepInput input_;
  StageTimes times_;
  double time_ = 0, frame_step_ms_ = 0;
  bool frame_stepped_ = false;
  int frame_iterations_ = 0, frame_fallbacks_ = 0;
  std::vector<vdm::Vec3> instrument_force_;
  std::vector<double> peak_force_;
  long unconverged_steps_ = 0, contact_iterations_ = 0;
  double organ_size_ = 0;  // the rest surface's bounding-box diagonal (m), for unsound()
  // Holds of the same node against each other, found by advance(): the node's holders
  // (per node: -1 none, k >= 0 instruments[k], <= -2 organ.prescribed[-2 - k]) and the
  // message of the farthest apart this frame (empty: none).
  std::vector<int> holder_;
  std::vector<std::pair<int, vdm::Vec3>> earlier_hold_;  // (node, its earlier holder's target)
  double conflict_gap_ = 0;
  std::string conflict_;
  void note_hold(int node, int holder, const vdm::Vec3& before, const vdm::Vec3& after);
  std::string deep_probe() const;
  std::string deep_probe_cause(size_t probe) const;
  // The forces of the frame just simulated (instrument_force_, peak_force_).
  void measure_forces();
};

}  // namespace vdmsim
