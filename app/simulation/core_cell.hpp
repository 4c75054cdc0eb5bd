#pragma once
// organ.cell_size of `model: vdm_core`, checked against the placed organ and the instruments
// before the elastic core is built: a cell that does not fit in the organ's box (the core would
// be a cell or two, its force off by orders of magnitude) or that gives more cells than the core
// takes is refused, naming organ.cell_size's line and column; a cell more than twice as wide as
// the smallest instrument is warned (a dent narrower than a few cells is resisted by the ties
// alone).
#include <vector>

#include "app/scene/scene.hpp"
#include "engine/types.hpp"

namespace vdmsim {

// The most cells the elastic core lays over the organ's box (engine/core: 2e7).
constexpr double kMaxCoreCells = 2e7;
// The default cell's bound on the core's size: about this many cubes inside the organ.
constexpr double kDefaultCoreCubes = 10000;

// The core's cell for `organ` (the surface of `def` as placed, m): its cell_size when the scene gives
// it; by default the organ's volume over its area (a third of a slab's thickness), no wider
// than the smallest instrument (a dent under it then spans a cell or more: the flat punch of
// AgainstTheFem is within 1-5 % of the FEM's force at one punch width per cell), and no finer
// than gives kDefaultCoreCubes cubes (the step's cost grows with them).
double core_cell_size(const SceneDef& scene, const OrganDef& def, const vdm::SurfaceMesh& organ);

// Appends the problems of `scene`'s cell for `organ` (the surface as placed, m) to `problems`
// (vdm_core's check of the placed organ, organ_model_table.hpp).
void check_core_cell(const SceneDef& scene, const OrganDef& def, const vdm::SurfaceMesh& organ,
                     std::vector<SceneProblem>& problems);

}  // namespace vdmsim
