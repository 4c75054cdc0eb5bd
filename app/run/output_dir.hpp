#pragma once
// The output folder of a run, a study or a generated file, and its files written whole.
#include <filesystem>
#include <string>

namespace vdmsim {

// Creates `dir` (and parents) and checks it can be written; false with a message otherwise.
bool prepare_output_dir(const std::string& dir, std::string& error);

// Writes `body` to `path` atomically (a temporary file next to it, then a rename), so that a
// reader never sees half a file, nor an interrupted run a torn one. False with `error`.
bool write_file_atomically(const std::filesystem::path& path, const std::string& body, std::string& error);

}  // namespace vdmsim
