#pragma once
// Instruments through ports (instruments[].port): once the organ is placed, every keyframe's tip
// (given, in port coordinates, or found on the surface) must lie past the port, on the organ's
// side of it, and within the instrument's length of it; the shaft then passes through the port
// at every keyframe and, the axis following the tip, between them.
#include <vector>

#include "app/scene/scene.hpp"

namespace vdmsim {

// Checks scene's ported instruments against the organ's placed surface (its bounding box's
// centre gives the side of each port the abdomen is on). An error per keyframe that fails, at
// the keyframe's position; false when there is one.
bool check_port_keyframes(const SceneDef& scene, const vdm::SurfaceMesh& placed, std::vector<SceneProblem>& problems);

}  // namespace vdmsim
