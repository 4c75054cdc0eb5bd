#pragma once
// The organ models a scene can pick instead of VDM's engine (organ.model vdm_core, fem or
// mass_spring), built once per prepared scene (the FEM's tet mesh by gmsh): every simulation
// of the scene (a colour-range pass, the run, a benchmark repeat) steps a solver of its own on
// a copy, so that none starts where another ended.
#include <memory>
#include <string>

#include "app/scene/scene.hpp"
#include "engine/core/elastic_core.hpp"
#include "engine/fem/fem_model.hpp"
#include "engine/mass_spring.hpp"
#include "engine/organ_solver.hpp"
#include "engine/tissue_model.hpp"

namespace vdmsim {

struct ReferenceModel {
  vdm::ModelKind kind = vdm::ModelKind::vdm;  // vdm: none
  vdm::fem::FemModel fem;                     // kind fem
  vdm::MassSpringModel mass_spring;           // kind mass_spring
  vdm::core::CoreModel core;                  // kind vdm_core
  double dt = 0;                              // the scene's time step
};

// The scene's reference model on `model`'s surface with its fixed entries (nothing for vdm).
// False with a message on failure.
bool build_reference_model(const SceneDef& scene, const vdm::TissueModel& model, ReferenceModel& out,
                           std::string& error);

// A solver of its own on a copy of the reference model; null for vdm.
std::unique_ptr<vdm::OrganSolver> make_organ_solver(const ReferenceModel& reference);

}  // namespace vdmsim
