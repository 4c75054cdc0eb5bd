#pragma once
// Loading organ surfaces from files into the engine's plain arrays, welded, cleaned and
// validated: OBJ and PLY by our own readers (app/obj_reader, app/ply_reader), STL, glTF/GLB and
// anything else assimp reads (except PLY) through assimp.
#include <string>

#include "engine/mesh_topology.hpp"
#include "engine/types.hpp"

namespace vdmsim {

struct MeshLoadResult {
  vdm::SurfaceMesh mesh;
  bool ok = false;
  vdm::MeshProblem problem = vdm::MeshProblem::none;  // when the mesh was read but is unusable
  std::string error;          // "<path>: <what is wrong>" when !ok
  int dropped_nodes = 0;      // unreferenced nodes removed
  int welded_nodes = 0;       // coincident nodes merged
  bool flipped = false;       // the surface was inward and has been turned outward
};

struct MeshLoadOptions {
  double scale = 1.0;         // multiply coordinates (mesh units -> metres)
  bool validate = true;       // run the organ-surface checks
  long long max_file_bytes = 512LL << 20;  // refuse larger files before parsing
};

MeshLoadResult load_surface_mesh(const std::string& path, const MeshLoadOptions& options = {});

// What every command that loads an organ says, as a warning, when its surface was inward and
// has been flipped (MeshLoadResult::flipped): "<path>: the surface is oriented inward ...".
std::string flipped_surface_note(const std::string& path);

// Writes a Wavefront OBJ (positions and triangles, full precision). False with a message
// naming the file on failure; `at_run_time`, when given, is set when the file opened but the
// disk failed (no space left, an I/O error): a failure at run time (exit 1), not a bad path.
bool save_obj(const vdm::SurfaceMesh& mesh, const std::string& path, const std::string& header,
              std::string& error, bool* at_run_time = nullptr);

}  // namespace vdmsim
