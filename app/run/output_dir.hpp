#pragma once
// The output folder of a run, a study or a generated file.
#include <string>

namespace vdmsim {

// Creates `dir` (and parents) and checks it can be written; false with a message otherwise.
bool prepare_output_dir(const std::string& dir, std::string& error);

}  // namespace vdmsim
