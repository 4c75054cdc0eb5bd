#pragma once
// The organ models a scene can pick (organ.model), one row each: a struct below says everything
// the program knows about a model beyond its solver in the engine. Its data (the organ keys it
// uses, how its material is given, whether it computes surface stress, the contact it takes) is
// read through organ_model(); its functions (checking the placed organ, building its reference
// model, making its solver, its lines of run.json) are declared here, defined in
// app/simulation/organ_models.cpp and app/run/model_material_json.cpp, and reached through
// organ_model_run() (app/simulation/organ_models.hpp). The split keeps the scene reader free of
// the engine's solvers (the sweep fuzzer links it alone, tests/CMakeLists.txt).
//
// To add a model (docs/developing.md, "Adding an organ model"): its ModelKind and name
// (engine/organ_solver.hpp, engine/setting_names.cpp), a row here in OrganModelRows, its functions.
#include <array>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "engine/contact_settings.hpp"
#include "engine/organ_solver.hpp"

namespace vdmsim {

// The model a scene gets without organ.model, unless its material is given by VDM's moduli
// (those select vdm, app/scene/scene.cpp).
inline constexpr vdm::ModelKind kDefaultOrganModel = vdm::ModelKind::vdm_core;

struct SceneDef;
struct OrganDef;
struct PreparedOrgan;
struct SceneProblem;
struct PreparedScene;
struct ReferenceModel;

using ContactMethod = vdm::ContactSettings::Method;

// What every row declares (each row defines the same members):
//   kind                the engine's model (its name: vdm::to_string(kind))
//   keys                the organ keys that only some models use, those this one does (paths of
//                       scene_keys.hpp): a scene's key that another row lists and this one does
//                       not is warned as ignored (in the scene reference's order)
//   material            the keys its material is given by (`check` names their defaults when a
//                       scene gives no material)
//   vdm_moduli          its material is VDM's moduli (bulk and connectivity, or E and nu mapped
//                       to them), checked for conditioning; else E is its stiffness
//   surface_stress      it computes stress at the surface (stress views, --export-mesh)
//   penalty_contact     it takes penalty contact (StepInput's springs)
//   inertia             its steps take the inertia effect (else they are static)
//   contact             its contact method when the scene names none
//   check_placed        appends the problems of its own settings on the placed organ
//   build               builds its reference model on the organ's surface (false with a message)
//   make_solver         a solver of its own on a copy of the reference model; null: vdm::step
//   write_run_json      its part of an organ's run.json entry: `"material": {...}` (the material
//                       it used), or nothing

// The Volume Distribution Method on the organ's surface (the paper's engine, with the membrane
// capsule by default): vdm::step on the tissue model itself.
struct VdmRow {
  static constexpr vdm::ModelKind kind = vdm::ModelKind::vdm;
  static constexpr std::array keys{"organ.material.connectivity_modulus", "organ.material.capsule",
                                   "organ.material.bending_modulus", "organ.material.bulk_modulus",
                                   "organ.material.poisson_ratio", "simulation.solver"};
  static constexpr std::array material{"organ.material.bulk_modulus", "organ.material.connectivity_modulus"};
  static constexpr bool vdm_moduli = true;
  static constexpr bool surface_stress = true;
  static constexpr bool penalty_contact = true;
  static constexpr bool inertia = true;
  static constexpr ContactMethod contact = ContactMethod::constraint;
  static void check_placed(const SceneDef& scene, const OrganDef& def, const vdm::SurfaceMesh& organ,
                           std::vector<SceneProblem>& problems);
  static bool build(const SceneDef& scene, const OrganDef& def, const vdm::TissueModel& model, ReferenceModel& out,
                    std::string& error);
  static std::unique_ptr<vdm::OrganSolver> make_solver(const ReferenceModel& reference);
  static void write_run_json(const OrganDef& def, const PreparedOrgan& organ, std::ostream& js);
};

// VDM's surface and pressure on an elastic core (engine/core) in place of the bulk term.
struct VdmCoreRow {
  static constexpr vdm::ModelKind kind = vdm::ModelKind::vdm_core;
  static constexpr std::array keys{"organ.cell_size", "organ.material.poisson_ratio"};
  static constexpr std::array material{"organ.material.young_modulus", "organ.material.poisson_ratio"};
  static constexpr bool vdm_moduli = false;
  static constexpr bool surface_stress = true;
  static constexpr bool penalty_contact = false;
  static constexpr bool inertia = true;
  // Contact points with Coulomb friction, as on vdm: tissue slides under an instrument.
  static constexpr ContactMethod contact = ContactMethod::constraint;
  static void check_placed(const SceneDef& scene, const OrganDef& def, const vdm::SurfaceMesh& organ,
                           std::vector<SceneProblem>& problems);
  static bool build(const SceneDef& scene, const OrganDef& def, const vdm::TissueModel& model, ReferenceModel& out,
                    std::string& error);
  static std::unique_ptr<vdm::OrganSolver> make_solver(const ReferenceModel& reference);
  static void write_run_json(const OrganDef& def, const PreparedOrgan& organ, std::ostream& js);
};

// The FEM reference: corotational linear tetrahedra meshed by gmsh.
struct FemRow {
  static constexpr vdm::ModelKind kind = vdm::ModelKind::fem;
  static constexpr std::array keys{"organ.material.poisson_ratio", "organ.tet_size"};
  static constexpr std::array material{"organ.material.young_modulus", "organ.material.poisson_ratio"};
  static constexpr bool vdm_moduli = false;
  static constexpr bool surface_stress = false;
  static constexpr bool penalty_contact = false;
  static constexpr bool inertia = false;
  // Constraint contact converges on the FEM without friction only (docs/reference-models.md).
  static constexpr ContactMethod contact = ContactMethod::kinematic;
  static void check_placed(const SceneDef& scene, const OrganDef& def, const vdm::SurfaceMesh& organ,
                           std::vector<SceneProblem>& problems);
  static bool build(const SceneDef& scene, const OrganDef& def, const vdm::TissueModel& model, ReferenceModel& out,
                    std::string& error);
  static std::unique_ptr<vdm::OrganSolver> make_solver(const ReferenceModel& reference);
  static void write_run_json(const OrganDef& def, const PreparedOrgan& organ, std::ostream& js);
};

// The mass-spring reference: springs on the surface edges and an optional volume spring.
struct MassSpringRow {
  static constexpr vdm::ModelKind kind = vdm::ModelKind::mass_spring;
  static constexpr std::array keys{"organ.material.thickness", "organ.material.volume_modulus"};
  static constexpr std::array material{"organ.material.young_modulus", "organ.material.thickness"};
  static constexpr bool vdm_moduli = false;
  static constexpr bool surface_stress = false;
  static constexpr bool penalty_contact = false;
  static constexpr bool inertia = false;
  static constexpr ContactMethod contact = ContactMethod::kinematic;
  static void check_placed(const SceneDef& scene, const OrganDef& def, const vdm::SurfaceMesh& organ,
                           std::vector<SceneProblem>& problems);
  static bool build(const SceneDef& scene, const OrganDef& def, const vdm::TissueModel& model, ReferenceModel& out,
                    std::string& error);
  static std::unique_ptr<vdm::OrganSolver> make_solver(const ReferenceModel& reference);
  static void write_run_json(const OrganDef& def, const PreparedOrgan& organ, std::ostream& js);
};

template <class... Rows>
struct RowList {};
// Every model, in the order messages and the scene reference name them.
using OrganModelRows = RowList<VdmRow, VdmCoreRow, FemRow, MassSpringRow>;

// A row's data, as the scene reader, `check` and the simulation ask for it.
struct OrganModel {
  vdm::ModelKind kind = kDefaultOrganModel;
  std::vector<std::string> keys, material;
  bool vdm_moduli = false, surface_stress = false, penalty_contact = false, inertia = false;
  ContactMethod contact = ContactMethod::kinematic;

  const char* name() const { return vdm::to_string(kind); }
  // Whether the model uses the organ key `path`: every key but those only other models use.
  bool uses(const std::string& path) const;
};

// Every model's row, in OrganModelRows' order.
const std::vector<OrganModel>& organ_models();
// The row of `kind` (every ModelKind has one).
const OrganModel& organ_model(vdm::ModelKind kind);
// The models' names in the table's order; those of the models with `flag` set.
std::vector<std::string> organ_model_names();
std::vector<std::string> organ_model_names(bool OrganModel::*flag);
// The organ keys that only some models use (every row's keys), in the scene reference's order.
std::vector<std::string> model_specific_keys();
// "a", "a or b", "a, b or c".
std::string or_list(const std::vector<std::string>& words);

}  // namespace vdmsim
