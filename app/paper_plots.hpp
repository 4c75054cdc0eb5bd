#pragma once
// The paper's figures as PNG plots (render/plot): cube stress at A, B, C over the steps
// (Fig. 3), anisotropy displacements and volume (Fig. 6).
#include <string>
#include <vector>

#include "app/paper_cube.hpp"

namespace vdmsim {

bool write_cube_stress_plot(const std::string& path, const CubeResult& r, const CubeCompression& cfg, std::string& error);
bool write_anisotropy_plot(const std::string& path, const std::vector<AnisotropyCase>& cases,
                           const std::vector<CubeResult>& results, const CubeCompression& cfg, std::string& error);

}  // namespace vdmsim
