#pragma once
// A direct Wavefront OBJ reader: keeps the file's vertex order (so node indices in scenes
// mean what the file says) and full double precision. Polygons are fanned into triangles.
#include <string>

#include "engine/types.hpp"

namespace vdmsim {

// Reads `path` into `mesh` (all vertices, in file order). On failure returns false and sets
// `error` to "line N: what is wrong" (the caller adds the file name).
bool read_obj(const std::string& path, vdm::SurfaceMesh& mesh, std::string& error);

}  // namespace vdmsim
