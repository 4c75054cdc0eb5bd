#pragma once
// Where the program finds its own files at run time. An installed vdmsim (PREFIX/bin/vdmsim)
// finds them beside itself: the assimp module in PREFIX/lib/vdmsim/, the example scenes and
// meshes in PREFIX/share/vdmsim/ (the layout of cmake/install.cmake). A vdmsim run from its
// build tree, where those do not exist, uses the build and source trees it was built from.
#include <string>

namespace vdmsim {

// The folder of the running executable (/proc/self/exe), or "" when it cannot be read.
std::string executable_dir();

// The vdmsim_assimp module (meshes other than OBJ and PLY): the installed one beside the
// executable when it exists, otherwise the one in the build tree.
std::string assimp_module_path();

// The folder holding scenes/ and meshes/ (the example scenes and the project's livers): the
// installed PREFIX/share/vdmsim when it exists, otherwise the source tree's assets/.
std::string data_dir();

}  // namespace vdmsim
