#pragma once
// docs/scene-reference.md, printed from the scene reader's table of keys (scene_keys.hpp):
// `vdmsim scene-reference > docs/scene-reference.md`.
#include <ostream>

namespace vdmsim {

void write_scene_reference(std::ostream& out);

}  // namespace vdmsim
