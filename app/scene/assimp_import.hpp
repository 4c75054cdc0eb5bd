#pragma once
// Meshes in the formats that assimp reads (STL, glTF, OFF, ...; not OBJ or PLY, which have
// readers of their own). assimp lives in a module of its own (vdmsim_assimp), opened
// (dlopen) on the first such mesh rather than linked: linked, it and the libraries behind it
// (draco, minizip) were loaded into every vdmsim process, about 4 MB resident, though a run
// of the committed scenes reads only OBJ files.
#include <array>
#include <string>
#include <vector>

#include "engine/types.hpp"

namespace vdmsim {

// Every triangle of every mesh in the file, in world coordinates (polygons as fans; an index
// past its mesh's vertices becomes -1). False with a message (not found, not readable, no
// module) otherwise.
bool read_with_assimp(const std::string& path, std::vector<vdm::Vec3>& points, std::vector<std::array<int, 3>>& tris,
                      std::string& error);

}  // namespace vdmsim

// The module's one entry point (C linkage: found by dlsym).
extern "C" bool vdmsim_assimp_read(const char* path, std::vector<vdm::Vec3>* points,
                                   std::vector<std::array<int, 3>>* tris, std::string* error);
