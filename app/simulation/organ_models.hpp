#pragma once
// The reference organ models a scene can pick instead of VDM (organ.model fem or mass_spring).
#include <memory>
#include <string>

#include "app/scene/scene.hpp"
#include "engine/organ_solver.hpp"
#include "engine/tissue_model.hpp"

namespace vdmsim {

// The organ's solver for organ.model fem (tet mesh by gmsh) or mass_spring, on `model`'s
// surface with its fixed entries; null for vdm. False with a message on failure.
bool make_organ_solver(const SceneDef& scene, const vdm::TissueModel& model, std::unique_ptr<vdm::OrganSolver>& out,
                       std::string& error);

}  // namespace vdmsim
