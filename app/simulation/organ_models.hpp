#pragma once
// The run-time half of the organ model table (app/scene/organ_model_table.hpp): each model's
// functions, reached by its kind, and the reference model they build once per prepared scene
// (the FEM's tet mesh by gmsh): every simulation of the scene (a colour-range pass, the run, a
// benchmark repeat) steps a solver of its own on a copy, so that none starts where another
// ended.
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "app/scene/scene.hpp"
#include "engine/core/elastic_core.hpp"
#include "engine/fem/fem_model.hpp"
#include "engine/mass_spring.hpp"
#include "engine/organ_solver.hpp"
#include "engine/tissue_model.hpp"

namespace vdmsim {

struct ReferenceModel {
  vdm::ModelKind kind = vdm::ModelKind::vdm;  // vdm: none (vdm::step on the tissue model)
  vdm::fem::FemModel fem;                     // kind fem
  vdm::MassSpringModel mass_spring;           // kind mass_spring
  vdm::core::CoreModel core;                  // kind vdm_core
  double dt = 0;                              // the scene's time step
};

// A row's functions (organ_model_table.hpp says what each does).
struct OrganModelRun {
  vdm::ModelKind kind;
  void (*check_placed)(const SceneDef& scene, const OrganDef& def, const vdm::SurfaceMesh& organ,
                       std::vector<SceneProblem>& problems);
  bool (*build)(const SceneDef& scene, const OrganDef& def, const vdm::TissueModel& model, ReferenceModel& out,
                std::string& error);
  std::unique_ptr<vdm::OrganSolver> (*make_solver)(const ReferenceModel& reference);
  void (*write_run_json)(const OrganDef& def, const PreparedOrgan& organ, std::ostream& js);
};

// The functions of `kind`'s row (every ModelKind has one).
const OrganModelRun& organ_model_run(vdm::ModelKind kind);

// The reference model of the scene's organ `def` on `model`'s surface with its fixed entries
// (nothing for vdm). False with a message on failure.
bool build_reference_model(const SceneDef& scene, const OrganDef& def, const vdm::TissueModel& model,
                           ReferenceModel& out, std::string& error);

// A solver of its own on a copy of the reference model; null for vdm.
std::unique_ptr<vdm::OrganSolver> make_organ_solver(const ReferenceModel& reference);

}  // namespace vdmsim
