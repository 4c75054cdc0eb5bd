#include "engine/organ_solver.hpp"

#include <chrono>

#include "engine/core/core_snapshot.hpp"
#include "engine/core/core_stress.hpp"
#include "engine/core/elastic_core.hpp"
#include "engine/fem/fem_state.hpp"
#include "engine/geometry.hpp"
#include "engine/step_workspace.hpp"
#include "engine/stiffness.hpp"
#include "engine/stopwatch.hpp"
#include "engine/warnings.hpp"

namespace vdm {
namespace {

class VdmSolver final : public OrganSolver {
 public:
  explicit VdmSolver(const TissueModel& m) : m_(m) {}
  ModelKind kind() const override { return ModelKind::vdm; }
  void step(const StepInput& in, SimState& s) override { vdm::step(m_, in, s); }
  void trial_step(const StepInput& in, SimState& s, StepResults results) override { vdm::step(m_, in, s, results); }
  void finish_step(SimState& s) override { finish_step_results(m_, s); }
  void rewind(SimState& s) override { rewind_step(m_, s); }
  // The engine keeps the start's u (the whole step's when it was done in parts).
  const NodeMat& start_u(const SimState& s) const override { return s.work->start.u; }
  bool takes_springs() const override { return true; }
  // Only the structured solver stops at a given residual (the direct solver is exact, the
  // paper's BiCGSTAB keeps the settings' tolerance).
  bool takes_tolerance() const override { return m_.solver.method == SolverMethod::structured; }
  const AxisStiffness& contact_stiffness(const TissueModel&, const SimState& s) override { return s.work->K; }
  long contact_stiffness_version(const SimState& s) const override { return s.stats.total_refreshes; }
  // Everything the engine carries is in the SimState (engine/state_snapshot.hpp).
  bool save_state(std::string&) const override { return true; }
  bool load_state(std::string_view, size_t&, std::string&) override { return true; }

 private:
  const TissueModel& m_;
};

// What a reference model shares: the common state's fields at the start of the step (what
// rewind() brings back), and VDM's rest stiffness of the surface for contact's compliance.
class ReferenceSolver : public OrganSolver {
 public:
  void trial_step(const StepInput& in, SimState& s, StepResults) override { step(in, s); }
  void finish_step(SimState&) override {}
  void rewind(SimState& s) override {
    s.u = start_.u;
    s.x = start_.x;
    s.velocity = start_.velocity;
    s.step = start_.step;
    s.time = start_.time;
  }
  const NodeMat& start_u(const SimState& s) const override { return start_.u.rows() == s.u.rows() ? start_.u : s.u; }
  bool takes_springs() const override { return false; }  // their steps could not take springs implicitly
  bool takes_tolerance() const override { return false; }
  const AxisStiffness& contact_stiffness(const TissueModel& surface, const SimState&) override {
    if (rest_K_.diagonal.rows() != surface.n) {  // once: the rest geometry
      NodeMat area(surface.n, 3);
      distributed_area_vectors(surface.rest.positions, surface.rest.triangles, area);
      Vec volumes(surface.n), norms = area.rowwise().norm(), scratch(surface.n);
      const VolumeScale how = distributed_volumes(area, surface.rest_volume, volumes);
      rest_K_.weight = Vec::Zero(static_cast<Eigen::Index>(surface.edges.size()));
      rest_K_.diagonal = NodeMat::Zero(surface.n, 3);
      assemble_stiffness(surface, area, norms, volumes, how, Vec(), rest_K_, scratch);
    }
    return rest_K_;
  }
  long contact_stiffness_version(const SimState&) const override { return 0; }

 protected:
  // Called by step() before it solves: where this step starts.
  void remember_start(const SimState& s) {
    start_.u = s.u;
    start_.x = s.x;
    start_.velocity = s.velocity;
    start_.step = s.step;
    start_.time = s.time;
  }

 private:
  struct Start {
    NodeMat u, x, velocity;
    long step = -1;
    double time = 0;
  } start_;
  AxisStiffness rest_K_;
};

// Copies a surface result into the common state and advances its clock.
void publish(const NodeMat& rest, const NodeMat& u_surface, const NodeMat& reaction_surface, double dt, SimState& s) {
  s.velocity = (u_surface - s.u) / dt;
  s.u = u_surface;
  s.x = rest + s.u;
  s.reaction = reaction_surface;
  s.step += 1;
  s.time += dt;
}

// A reference model's step summary, copied into the common state with the step's time.
struct ReferenceStep {
  double volume = 0, volume_rel_error = 0, pressure = 0;
  int iterations = 0;
  double residual = 0, change = 0;
  int factorizations = 0;
  bool converged = true;
};

void publish_step(const ReferenceStep& r, Clock::time_point t0, SimState& s) {
  s.volume = r.volume;
  s.volume_rel_error = r.volume_rel_error;
  s.pressure = r.pressure;
  s.stats = StepStats{};
  s.stats.iterations = s.stats.nonlinear_iterations = r.iterations;
  s.stats.residual = r.residual;
  s.stats.nonlinear_change = r.change;
  s.stats.factorizations = r.factorizations;
  s.stats.converged = r.converged;
  s.stats.step_ms = s.stats.solve_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The warnings a model added since it had `warned`, up to the state's limit.
void copy_warnings(const std::vector<std::string>& from, size_t warned, SimState& s) {
  for (size_t k = warned; k < from.size() && s.warnings.size() < kMaxWarnings; ++k) s.warnings.push_back(from[k]);
}

class FemSolver final : public ReferenceSolver {
 public:
  FemSolver(fem::FemModel m, double dt) : m_(std::move(m)), s_(fem::make_fem_state(m_)), dt_(dt) {}
  ModelKind kind() const override { return ModelKind::fem; }
  void step(const StepInput& in, SimState& s) override {
    const auto t0 = Clock::now();
    remember_start(s);
    const size_t warned = s_.warnings.size();
    fem::step(m_, in, s_);
    publish(m_.mesh.surface.positions, s_.u.topRows(m_.ns), s_.reaction.topRows(m_.ns), dt_, s);
    ReferenceStep r;
    r.volume = s_.volume;
    r.volume_rel_error = s_.volume_rel_error;
    r.pressure = s_.pressure;
    r.iterations = s_.stats.iterations;
    r.residual = s_.stats.residual;
    r.converged = s_.stats.converged;
    publish_step(r, t0, s);
    copy_warnings(s_.warnings, warned, s);
  }

 private:
  fem::FemModel m_;
  fem::FemState s_;
  double dt_;
};

class MassSpringSolver final : public ReferenceSolver {
 public:
  MassSpringSolver(MassSpringModel m, double dt) : m_(std::move(m)), s_(make_mass_spring_state(m_)), dt_(dt) {}
  ModelKind kind() const override { return ModelKind::mass_spring; }
  void step(const StepInput& in, SimState& s) override {
    const auto t0 = Clock::now();
    remember_start(s);
    vdm::step(m_, in, s_);
    publish(m_.rest, s_.u, s_.reaction, dt_, s);
    ReferenceStep r;
    r.volume = s_.volume;
    r.volume_rel_error = s_.volume_rel_error;
    r.pressure = s_.pressure;
    r.iterations = s_.iterations;
    r.residual = s_.residual;
    r.converged = s_.converged;
    publish_step(r, t0, s);
    if (!s_.converged && s.warnings.size() < kMaxWarnings) s.warnings.emplace_back("mass_spring: a step did not converge");
  }

 private:
  MassSpringModel m_;
  MassSpringState s_;
  double dt_;
};

class CoreSolver final : public ReferenceSolver {
 public:
  CoreSolver(core::CoreModel m, double dt) : m_(std::move(m)), s_(core::make_core_state(m_)), dt_(dt) {}
  ModelKind kind() const override { return ModelKind::vdm_core; }
  void step(const StepInput& in, SimState& s) override {
    solve(in, s, nullptr);
    finish_step(s);
  }
  // Contact solves a step several times: the results only for the one it keeps.
  void trial_step(const StepInput& in, SimState& s, StepResults) override { solve(in, s, nullptr); }
  // With inertia the core keeps where its step started: the step solved again starts there.
  void rewind(SimState& s) override {
    ReferenceSolver::rewind(s);
    core::rewind(s_);
  }
  bool solves_force_laws() const override { return true; }
  bool trial_step_with(const StepInput& in, SimState& s, SurfaceForceLaw& law) override {
    solve(in, s, &law);
    return true;
  }
  bool joint_begin(const StepInput& in, SimState& s, SurfaceForceLaw* law) override {
    joint_t0_ = Clock::now();
    remember_start(s);
    joint_warned_ = s_.warnings.size();
    if (core::begin_step(m_, in, s_, law)) return true;
    end_solve(s, joint_t0_, joint_warned_);
    return false;
  }
  void joint_solve() override { core::solve_iteration(m_, s_); }
  const NodeMat& joint_surface() const override { return core::iteration_surface(s_); }
  NodeMat& joint_forces() override { return core::iteration_forces(s_); }
  void joint_forces_changed() override {
    core::forces_changed(m_, s_);
    core::mixing_residual(m_, s_);
  }
  bool joint_converged() override { return core::iteration_converged(m_, s_); }
  bool joint_advance(bool stop) override { return core::advance_iteration(m_, s_, stop); }
  double joint_tolerance() const override { return m_.settings.tolerance * m_.size; }
  void joint_end(SimState& s) override {
    core::end_step(m_, s_);
    end_solve(s, joint_t0_, joint_warned_);
  }
  // The step's results at its surface, as VDM's: the area vectors A_i at the current
  // geometry, the contact pressure |reaction_i| / |A_i| on nodes with a constrained entry
  // (constraint contact then writes its own nodes' over the same A_i), and with
  // compute_stress the surface's strain and stress (engine/core/core_stress.hpp).
  void finish_step(SimState& s) override {
    const auto t0 = Clock::now();
    distributed_area_vectors(s.x, m_.surface.triangles, s.area_vectors);
    for (int i = 0; i < m_.ns; ++i) {
      const double a = s.area_vectors.row(i).norm(), f = s.reaction.row(i).norm();
      s.reaction_pressure[i] = a > 0 && f > 0 ? f / a : 0.0;
    }
    if (m_.compute_stress && surface_stress_) core::core_surface_stress(m_, s_, strain_, s.stress, s.strain);
    s.stats.stress_ms = ms_since(t0);
    s.stats.step_ms += s.stats.stress_ms;
  }
  void set_surface_stress(bool on) override { surface_stress_ = on; }
  bool surface_compliance(const std::vector<int>& nodes, Eigen::MatrixXd& C) override {
    core::surface_compliance(m_, s_, nodes, C);
    return true;
  }
  // The core's state. The rest is not carried between steps: the start that rewind() goes back
  // to is taken again by every solve before anything reads it, strain_ is the stress pass's
  // scratch, and the rest stiffness is built again from the rest shape when asked for.
  bool save_state(std::string& out) const override {
    core::save_core_state(m_, s_, out);
    return true;
  }
  bool load_state(std::string_view in, size_t& pos, std::string& error) override {
    return core::load_core_state(m_, in, pos, s_, error);
  }

 private:
  void solve(const StepInput& in, SimState& s, SurfaceForceLaw* law) {
    const auto t0 = Clock::now();
    remember_start(s);
    const size_t warned = s_.warnings.size();
    core::step(m_, in, s_, law);
    end_solve(s, t0, warned);
  }
  // The core's step into the common state.
  void end_solve(SimState& s, Clock::time_point t0, size_t warned) {
    publish(m_.surface.positions, s_.u, s_.reaction, dt_, s);
    ReferenceStep r;
    r.volume = s_.volume;
    r.volume_rel_error = s_.volume_rel_error;
    r.pressure = s_.pressure;
    r.iterations = s_.stats.iterations;
    r.change = s_.stats.change;
    r.factorizations = s_.stats.factorizations;
    r.converged = s_.stats.converged;
    publish_step(r, t0, s);
    copy_warnings(s_.warnings, warned, s);
  }

  core::CoreModel m_;
  core::CoreState s_;
  core::CoreStrain strain_;
  bool surface_stress_ = true;
  double dt_;
  Clock::time_point joint_t0_;
  size_t joint_warned_ = 0;
};

}  // namespace

std::unique_ptr<OrganSolver> make_vdm_solver(const TissueModel& model) { return std::make_unique<VdmSolver>(model); }
std::unique_ptr<OrganSolver> make_fem_solver(fem::FemModel model, double dt) {
  return std::make_unique<FemSolver>(std::move(model), dt);
}
std::unique_ptr<OrganSolver> make_core_solver(core::CoreModel model, double dt) {
  return std::make_unique<CoreSolver>(std::move(model), dt);
}
std::unique_ptr<OrganSolver> make_mass_spring_solver(MassSpringModel model, double dt) {
  return std::make_unique<MassSpringSolver>(std::move(model), dt);
}

}  // namespace vdm
