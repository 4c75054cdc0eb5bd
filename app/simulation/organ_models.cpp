#include "app/simulation/organ_models.hpp"

#include "app/simulation/tet_mesher.hpp"
#include "engine/fem/fem_model.hpp"

namespace vdmsim {

bool make_organ_solver(const SceneDef& s, const vdm::TissueModel& m, std::unique_ptr<vdm::OrganSolver>& out,
                       std::string& error) {
  out.reset();
  if (s.model == "fem") {
    vdm::fem::FemDef def;
    if (!tetrahedralize(m.rest, s.tet_size, def.mesh, error)) return false;
    def.young_modulus = s.young_modulus;
    def.poisson_ratio = s.poisson_ratio;
    def.density = s.density;
    def.gravity = s.gravity;
    def.use_gravity = s.has(Effect::gravity);
    def.fixed = m.held;
    vdm::fem::FemModel fm;
    if (!vdm::fem::build_fem_model(def, fm, error)) return false;
    out = vdm::make_fem_solver(std::move(fm), s.dt);
  } else if (s.model == "mass_spring") {
    vdm::MassSpringDef def;
    def.positions = m.rest.positions;
    def.triangles = m.rest.triangles;
    def.young_modulus = s.young_modulus;
    def.thickness = s.thickness;
    def.volume_modulus = s.volume_modulus;
    def.fixed = m.held;
    vdm::MassSpringModel msm;
    if (!vdm::build_mass_spring_model(def, msm, error)) return false;
    out = vdm::make_mass_spring_solver(std::move(msm), s.dt);
  }
  return true;
}

}  // namespace vdmsim
