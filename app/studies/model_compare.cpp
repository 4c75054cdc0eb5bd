#include "app/studies/model_compare.hpp"

#include <cmath>
#include <stdexcept>

#include "engine/core/elastic_core.hpp"
#include "engine/fem/fem_state.hpp"
#include "engine/organ_solver.hpp"
#include "engine/sim_state.hpp"
#include "engine/stopwatch.hpp"
#include "engine/tissue_model.hpp"

namespace vdmsim {
namespace {

using vdm::Clock;
using vdm::ms_since;

// Steps `solver` through the case on a SimState of `model`'s surface.
CaseResult drive(const vdm::TissueModel& model, vdm::OrganSolver& solver, const LoadCase& c) {
  vdm::SimState state = vdm::make_sim_state(model);
  vdm::StepInput input = vdm::make_step_input(model);
  CaseResult r;
  auto record = [&](double ms) {
    vdm::NodeMat u(c.tracked.size(), 3);
    for (size_t k = 0; k < c.tracked.size(); ++k) u.row(static_cast<Eigen::Index>(k)) = state.u.row(c.tracked[k]);
    r.u.push_back(u);
    r.volume_rel.push_back(state.volume_rel_error);
    double w = 0;
    for (int i : c.moved) w += state.reaction.row(i).dot(state.u.row(i));
    r.work.push_back(w);
    r.step_ms.push_back(ms);
  };
  record(0);
  for (int k = 0; k < c.steps(); ++k) {
    for (size_t j = 0; j < c.moved.size(); ++j) {
      input.prescribed.row(c.moved[j]).setOnes();
      input.prescribed_u.row(c.moved[j]) = c.targets[static_cast<size_t>(k)].row(static_cast<Eigen::Index>(j));
    }
    const auto t0 = Clock::now();
    solver.step(input, state);
    r.converged = r.converged && state.stats.converged;
    record(ms_since(t0));
  }
  return r;
}

vdm::TissueModel surface_model(const vdm::SurfaceMesh& surface, const VdmParams& p, const LoadCase& c) {
  vdm::TissueDef def = vdm::default_tissue(surface);
  def.bulk = p.bulk;
  def.connectivity_modulus = p.connectivity;
  def.capsule = p.capsule;
  def.bending_modulus = p.bending;
  def.solver = p.solver;
  def.fixed = c.fixed;
  def.compute_stress = false;
  vdm::TissueModel m;
  std::string error;
  if (!vdm::build_tissue_model(def, m, error)) throw std::runtime_error("vdm model: " + error);
  return m;
}

}  // namespace

CaseResult run_vdm_case(const vdm::SurfaceMesh& surface, const VdmParams& p, const LoadCase& c) {
  const vdm::TissueModel m = surface_model(surface, p, c);
  auto solver = vdm::make_vdm_solver(m);
  return drive(m, *solver, c);
}

CaseResult run_core_case(const vdm::SurfaceMesh& surface, double young, double cell_size, const LoadCase& c,
                         double tie) {
  vdm::core::CoreDef def;
  def.surface = surface;
  def.young_modulus = young;
  def.cell_size = cell_size;
  def.tie = tie;
  def.fixed = c.fixed;
  vdm::core::CoreModel cm;
  std::string error;
  if (!vdm::core::build_core_model(def, cm, error)) throw std::runtime_error("core model: " + error);
  const vdm::TissueModel m = surface_model(surface, VdmParams{}, c);
  auto solver = vdm::make_core_solver(std::move(cm), 1.0);
  return drive(m, *solver, c);
}

CaseResult run_fem_case(const vdm::fem::TetMesh& mesh, double young, double poisson, const LoadCase& c,
                        const vdm::fem::FemSettings& settings) {
  vdm::fem::FemDef def;
  def.mesh = mesh;
  def.young_modulus = young;
  def.poisson_ratio = poisson;
  def.fixed = c.fixed;
  def.settings = settings;
  vdm::fem::FemModel fm;
  std::string error;
  if (!vdm::fem::build_fem_model(def, fm, error)) throw std::runtime_error("fem model: " + error);
  const vdm::TissueModel m = surface_model(mesh.surface, VdmParams{}, c);
  auto solver = vdm::make_fem_solver(std::move(fm), 1.0);
  return drive(m, *solver, c);
}

CaseResult run_mass_spring_case(const vdm::SurfaceMesh& surface, const vdm::MassSpringDef& params, const LoadCase& c) {
  vdm::MassSpringDef def = params;
  def.positions = surface.positions;
  def.triangles = surface.triangles;
  def.fixed = c.fixed;
  vdm::MassSpringModel msm;
  std::string error;
  if (!vdm::build_mass_spring_model(def, msm, error)) throw std::runtime_error("mass-spring model: " + error);
  const vdm::TissueModel m = surface_model(surface, VdmParams{}, c);
  auto solver = vdm::make_mass_spring_solver(std::move(msm), 1.0);
  return drive(m, *solver, c);
}

double mean_relative_difference(const CaseResult& a, const CaseResult& b) {
  double largest = 0;
  for (const auto& u : b.u) largest = std::max(largest, u.rowwise().norm().maxCoeff());
  double sum = 0;
  long count = 0;
  for (size_t k = 1; k < a.u.size() && k < b.u.size(); ++k)
    for (Eigen::Index i = 0; i < b.u[k].rows(); ++i) {
      const double db = b.u[k].row(i).norm(), da = a.u[k].row(i).norm();
      if (db <= 1e-9 * largest) continue;
      sum += std::abs(da - db) / db;
      ++count;
    }
  return count ? sum / count : 0.0;
}

}  // namespace vdmsim
