#pragma once
// How many YAML documents a text holds, counted from their markers ('---', '...') without
// yaml-cpp's LoadAll, which loops forever on some inputs (the fuzz passes found ",p, 2" for scenes
// and ",as\x96: ." for sweep files): a reader counts the documents, then parses the one it
// takes with YAML::Load.
#include <string>

namespace vdmsim {

// The number of documents in `text` (1 for an empty text); `second_line` is the 1-based line where
// the second one starts (0 when there is none).
int count_yaml_documents(const std::string& text, int& second_line);

}  // namespace vdmsim
