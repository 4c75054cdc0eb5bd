#pragma once
// The paper's comparison with FEM (section 4.3, vdm-model.md section 9): a beam along y,
// fixed at y = 0, its other end stretched (along y), bent (along x) or twisted (rotated in
// the xz-plane about the beam's axis) to large deformation over `steps`. The VDM surface is
// exactly the FEM mesh's boundary (make_box_tets), so both models are driven through the same
// nodes. Points A, B, C: on the top face's centre line (x = 0, z = +w/2) at y = L/4, L/2, 3L/4.
#include <string>
#include <vector>

#include "app/studies/calibrate.hpp"
#include "app/studies/model_compare.hpp"

namespace vdmsim {

enum class BeamCase { stretch, bend, twist };
const char* to_string(BeamCase c);

struct BeamConfig {
  double length = 0.1;          // m, along y
  double width = 0.02;          // m, square section
  int cells_across = 4;
  int cells_along = 20;
  int steps = 20;
  double stretch = 0.3;         // final end displacement along y / length
  double bend = 0.3;            // final end displacement along x / length
  double twist_deg = 90;        // final rotation of the end about the beam's axis
  double young = 3000;          // FEM E (Pa)
  double poisson = 0.45;        // FEM nu
  VdmParams vdm;                // moduli used when not calibrated
  bool calibrate = true;        // fit vdm's moduli to the FEM runs of all three cases
  vdm::fem::FemSettings fem;    // per-tet volumetric strain: this mesh does not lock (fem_test)
  BeamConfig();
};

struct BeamCaseResult {
  BeamCase which = BeamCase::stretch;
  CaseResult vdm, fem;
  double mean_relative_difference = 0;  // |u| at A, B, C over steps >= 1 (model_compare)
};

struct BeamStudy {
  BeamConfig config;
  VdmParams used;               // VDM moduli actually used
  CalibrationResult calibration;  // when config.calibrate
  std::vector<BeamCaseResult> cases;
};

// The beam's load case (surface nodes of make_box_tets; tracked nodes A, B, C).
LoadCase beam_load_case(const BeamConfig& config, BeamCase which);

// Runs FEM on every case in `which`, calibrates (when asked, on those cases), then VDM.
BeamStudy run_beam_study(const BeamConfig& config, const std::vector<BeamCase>& which);

// DIR/beam-<case>.csv: step,point,vdm_disp,fem_disp,vdm_volume_rel_error,fem_volume_rel_error
bool write_beam_csv(const std::string& path, const BeamCaseResult& r, std::string& error);

}  // namespace vdmsim
