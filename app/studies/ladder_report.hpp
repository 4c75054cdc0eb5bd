#pragma once
// What `vdmsim accuracy --ladder` writes: ladder.csv (one row per rung) and ladder.png (per
// case, each model's error against the reference FEM over its time per step, log-log).
#include <string>
#include <vector>

#include "app/studies/ladder_errors.hpp"

namespace vdmsim {

bool write_ladder_csv(const std::string& path, const std::vector<LadderRow>& rows, std::string& error);
bool write_ladder_plot(const std::string& path, const std::vector<LadderRow>& rows, std::string& error);

// The case's reference row (null when it is not among `rows`).
const LadderRow* ladder_reference(const std::vector<LadderRow>& rows, const std::string& test_case);

}  // namespace vdmsim
