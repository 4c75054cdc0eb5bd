#include "engine/organ_solver.hpp"

#include <chrono>

#include "engine/fem/fem_state.hpp"
#include "engine/stopwatch.hpp"
#include "engine/warnings.hpp"

namespace vdm {
namespace {

class VdmSolver final : public OrganSolver {
 public:
  explicit VdmSolver(const TissueModel& m) : m_(m) {}
  ModelKind kind() const override { return ModelKind::vdm; }
  void step(const StepInput& in, SimState& s) override { vdm::step(m_, in, s); }

 private:
  const TissueModel& m_;
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

class FemSolver final : public OrganSolver {
 public:
  FemSolver(fem::FemModel m, double dt) : m_(std::move(m)), s_(fem::make_fem_state(m_)), dt_(dt) {}
  ModelKind kind() const override { return ModelKind::fem; }
  void step(const StepInput& in, SimState& s) override {
    const auto t0 = Clock::now();
    const size_t warned = s_.warnings.size();
    fem::step(m_, in, s_);
    publish(m_.mesh.surface.positions, s_.u.topRows(m_.ns), s_.reaction.topRows(m_.ns), dt_, s);
    s.volume = s_.volume;
    s.volume_rel_error = s_.volume_rel_error;
    s.pressure = s_.pressure;
    s.stats = StepStats{};
    s.stats.iterations = s_.stats.iterations;
    s.stats.nonlinear_iterations = s_.stats.iterations;
    s.stats.residual = s_.stats.residual;
    s.stats.converged = s_.stats.converged;
    s.stats.step_ms = s.stats.solve_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    for (size_t k = warned; k < s_.warnings.size() && s.warnings.size() < kMaxWarnings; ++k) s.warnings.push_back(s_.warnings[k]);
  }

 private:
  fem::FemModel m_;
  fem::FemState s_;
  double dt_;
};

class MassSpringSolver final : public OrganSolver {
 public:
  MassSpringSolver(MassSpringModel m, double dt) : m_(std::move(m)), s_(make_mass_spring_state(m_)), dt_(dt) {}
  ModelKind kind() const override { return ModelKind::mass_spring; }
  void step(const StepInput& in, SimState& s) override {
    const auto t0 = Clock::now();
    vdm::step(m_, in, s_);
    publish(m_.rest, s_.u, s_.reaction, dt_, s);
    s.volume = s_.volume;
    s.volume_rel_error = s_.volume_rel_error;
    s.pressure = s_.pressure;
    s.stats = StepStats{};
    s.stats.iterations = s.stats.nonlinear_iterations = s_.iterations;
    s.stats.residual = s_.residual;
    s.stats.converged = s_.converged;
    s.stats.step_ms = s.stats.solve_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (!s_.converged && s.warnings.size() < kMaxWarnings) s.warnings.emplace_back("mass_spring: a step did not converge");
  }

 private:
  MassSpringModel m_;
  MassSpringState s_;
  double dt_;
};

}  // namespace

const char* to_string(ModelKind k) {
  switch (k) {
    case ModelKind::vdm: return "vdm";
    case ModelKind::fem: return "fem";
    case ModelKind::mass_spring: return "mass_spring";
  }
  return "unknown";
}

bool parse_model_kind(const std::string& t, ModelKind& out) {
  if (t == "vdm") out = ModelKind::vdm;
  else if (t == "fem") out = ModelKind::fem;
  else if (t == "mass_spring") out = ModelKind::mass_spring;
  else return false;
  return true;
}

std::unique_ptr<OrganSolver> make_vdm_solver(const TissueModel& model) { return std::make_unique<VdmSolver>(model); }
std::unique_ptr<OrganSolver> make_fem_solver(fem::FemModel model, double dt) {
  return std::make_unique<FemSolver>(std::move(model), dt);
}
std::unique_ptr<OrganSolver> make_mass_spring_solver(MassSpringModel model, double dt) {
  return std::make_unique<MassSpringSolver>(std::move(model), dt);
}

}  // namespace vdm
