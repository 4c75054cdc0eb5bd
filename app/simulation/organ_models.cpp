#include "app/simulation/organ_models.hpp"

#include <algorithm>

#include "app/simulation/core_cell.hpp"
#include "app/simulation/tet_budget.hpp"
#include "app/simulation/tet_mesher.hpp"

namespace vdmsim {

// vdm: the tissue model is the model; vdm::step solves it.
void VdmRow::check_placed(const SceneDef&, const OrganDef&, const vdm::SurfaceMesh&, std::vector<SceneProblem>&) {}
bool VdmRow::build(const SceneDef&, const OrganDef&, const vdm::TissueModel&, ReferenceModel&, std::string&) {
  return true;
}
std::unique_ptr<vdm::OrganSolver> VdmRow::make_solver(const ReferenceModel&) { return nullptr; }

void VdmCoreRow::check_placed(const SceneDef& s, const OrganDef& o, const vdm::SurfaceMesh& organ,
                                std::vector<SceneProblem>& problems) {
  check_core_cell(s, o, organ, problems);
  // Nothing in the core anchors the organ (unlike vdm's bulk term): static steps under a load
  // have no equilibrium when no region holds it.
  if (o.fixed.empty() && o.prescribed.empty() && !s.has(Effect::inertia) &&
      (s.has(Effect::gravity) || !o.loads.empty()))
    problems.push_back({s.file, o.field + ".fixed",
                        "nothing holds the organ: on organ.model vdm_core a static step under gravity or loads has no "
                        "equilibrium (the organ would fall away); fix a region (organ.fixed: where it rests or hangs) "
                        "or add the inertia effect",
                        false});
}
bool VdmCoreRow::build(const SceneDef& s, const OrganDef& o, const vdm::TissueModel& m, ReferenceModel& out,
                          std::string& error) {
  vdm::core::CoreDef def;
  def.surface = m.rest;
  def.young_modulus = o.young_modulus;
  def.cell_size = core_cell_size(s, o, m.rest);
  def.density = o.density;
  def.gravity = s.gravity;
  def.use_gravity = s.has(Effect::gravity);
  def.use_inertia = s.has(Effect::inertia);
  def.damping = o.damping;
  def.dt = s.dt;
  def.compute_stress = s.has(Effect::stress);
  def.fixed = m.held;
  return vdm::core::build_core_model(def, out.core, error);
}
std::unique_ptr<vdm::OrganSolver> VdmCoreRow::make_solver(const ReferenceModel& r) {
  return vdm::make_core_solver(r.core, r.dt);
}

void FemRow::check_placed(const SceneDef& s, const OrganDef& o, const vdm::SurfaceMesh& organ,
                                std::vector<SceneProblem>& problems) {
  std::string error;
  if (!check_tet_budget(organ, o.tet_size, error)) problems.push_back({s.file, o.field + ".tet_size", error, false});
}
bool FemRow::build(const SceneDef& s, const OrganDef& o, const vdm::TissueModel& m, ReferenceModel& out,
                          std::string& error) {
  vdm::fem::FemDef def;
  if (!tetrahedralize(m.rest, o.tet_size, def.mesh, error)) return false;
  def.young_modulus = o.young_modulus;
  def.poisson_ratio = o.poisson_ratio;
  def.density = o.density;
  def.gravity = s.gravity;
  def.use_gravity = s.has(Effect::gravity);
  def.fixed = m.held;
  return vdm::fem::build_fem_model(def, out.fem, error);
}
std::unique_ptr<vdm::OrganSolver> FemRow::make_solver(const ReferenceModel& r) {
  return vdm::make_fem_solver(r.fem, r.dt);
}

void MassSpringRow::check_placed(const SceneDef&, const OrganDef&, const vdm::SurfaceMesh&, std::vector<SceneProblem>&) {}
bool MassSpringRow::build(const SceneDef&, const OrganDef& o, const vdm::TissueModel& m, ReferenceModel& out,
                          std::string& error) {
  vdm::MassSpringDef def;
  def.positions = m.rest.positions;
  def.triangles = m.rest.triangles;
  def.young_modulus = o.young_modulus;
  def.thickness = o.thickness;
  def.volume_modulus = o.volume_modulus;
  def.fixed = m.held;
  return vdm::build_mass_spring_model(def, out.mass_spring, error);
}
std::unique_ptr<vdm::OrganSolver> MassSpringRow::make_solver(const ReferenceModel& r) {
  return vdm::make_mass_spring_solver(r.mass_spring, r.dt);
}

namespace {

template <class Row>
OrganModelRun run_of() {
  return {Row::kind, &Row::check_placed, &Row::build, &Row::make_solver, &Row::write_run_json};
}

template <class... Rows>
std::vector<OrganModelRun> runs_of(RowList<Rows...>) {
  return {run_of<Rows>()...};
}

}  // namespace

const OrganModelRun& organ_model_run(vdm::ModelKind kind) {
  static const std::vector<OrganModelRun> runs = runs_of(OrganModelRows{});
  const auto it = std::find_if(runs.begin(), runs.end(), [&](const OrganModelRun& r) { return r.kind == kind; });
  return it != runs.end() ? *it : runs.front();  // every ModelKind has a row (organ_model_table_test)
}

bool build_reference_model(const SceneDef& s, const OrganDef& o, const vdm::TissueModel& m, ReferenceModel& out,
                           std::string& error) {
  out = ReferenceModel{};
  out.kind = o.model;
  out.dt = s.dt;
  return organ_model_run(o.model).build(s, o, m, out, error);
}

std::unique_ptr<vdm::OrganSolver> make_organ_solver(const ReferenceModel& r) {
  return organ_model_run(r.kind).make_solver(r);
}

}  // namespace vdmsim
