#include "app/simulation/organ_models.hpp"

#include "app/simulation/core_cell.hpp"
#include "app/simulation/tet_mesher.hpp"

namespace vdmsim {

bool build_reference_model(const SceneDef& s, const vdm::TissueModel& m, ReferenceModel& out, std::string& error) {
  out = ReferenceModel{};
  out.kind = s.model;
  out.dt = s.dt;
  if (s.model == vdm::ModelKind::fem) {
    vdm::fem::FemDef def;
    if (!tetrahedralize(m.rest, s.tet_size, def.mesh, error)) return false;
    def.young_modulus = s.young_modulus;
    def.poisson_ratio = s.poisson_ratio;
    def.density = s.density;
    def.gravity = s.gravity;
    def.use_gravity = s.has(Effect::gravity);
    def.fixed = m.held;
    if (!vdm::fem::build_fem_model(def, out.fem, error)) return false;
  } else if (s.model == vdm::ModelKind::vdm_core) {
    vdm::core::CoreDef def;
    def.surface = m.rest;
    def.young_modulus = s.young_modulus;
    def.cell_size = core_cell_size(s, m.rest);
    def.density = s.density;
    def.gravity = s.gravity;
    def.use_gravity = s.has(Effect::gravity);
    def.use_inertia = s.has(Effect::inertia);
    def.damping = s.damping;
    def.dt = s.dt;
    def.compute_stress = s.has(Effect::stress);
    def.fixed = m.held;
    if (!vdm::core::build_core_model(def, out.core, error)) return false;
  } else if (s.model == vdm::ModelKind::mass_spring) {
    vdm::MassSpringDef def;
    def.positions = m.rest.positions;
    def.triangles = m.rest.triangles;
    def.young_modulus = s.young_modulus;
    def.thickness = s.thickness;
    def.volume_modulus = s.volume_modulus;
    def.fixed = m.held;
    if (!vdm::build_mass_spring_model(def, out.mass_spring, error)) return false;
  }
  return true;
}

std::unique_ptr<vdm::OrganSolver> make_organ_solver(const ReferenceModel& r) {
  switch (r.kind) {
    case vdm::ModelKind::fem: return vdm::make_fem_solver(r.fem, r.dt);
    case vdm::ModelKind::mass_spring: return vdm::make_mass_spring_solver(r.mass_spring, r.dt);
    case vdm::ModelKind::vdm_core: return vdm::make_core_solver(r.core, r.dt);
    case vdm::ModelKind::vdm: break;
  }
  return nullptr;
}

}  // namespace vdmsim
