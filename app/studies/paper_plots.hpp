#pragma once
// The paper's figures as PNG plots (render/plot): cube stress at A, B, C over the steps
// (Fig. 3), anisotropy displacements and volume (Fig. 6), the beam comparison with FEM
// (Figs. 7-9).
#include <string>
#include <vector>

#include "app/studies/paper_beam.hpp"
#include "app/studies/paper_cube.hpp"

namespace vdmsim {

bool write_cube_stress_plot(const std::string& path, const CubeResult& r, const CubeCompression& cfg, std::string& error);
bool write_anisotropy_plot(const std::string& path, const std::vector<AnisotropyCase>& cases,
                           const std::vector<CubeResult>& results, const CubeCompression& cfg, std::string& error);

// beam-<case>.png: |u| of A, B, C over the steps, VDM solid and FEM dashed (paper Figs. 7-9).
bool write_beam_plot(const std::string& path, const BeamCaseResult& r, std::string& error);
// beam-volume.png: the volume change of every case over the steps, VDM solid, FEM dashed.
bool write_beam_volume_plot(const std::string& path, const std::vector<BeamCaseResult>& cases, std::string& error);

}  // namespace vdmsim
