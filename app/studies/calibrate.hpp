#pragma once
// Fits VDM's moduli (bulk B and connectivity B_ij) to an FEM reference by least squares:
// the same load cases run on both, residuals are the surface displacement differences
// (relative to the largest FEM displacement of the case, every case weighted alike) fix the
// ratio B_ij / B (driven by prescribed motion, VDM's displacements depend on nothing else);
// the work of the driven nodes (reaction . displacement) then fixes the scale, in closed form.
#include <functional>
#include <string>
#include <vector>

#include "app/studies/model_compare.hpp"

namespace vdmsim {

struct CalibrationResult {
  VdmParams params;                    // fitted bulk and connectivity
  double cost = 0;                     // final displacement cost (sum over cases of mean squares)
  double rms_displacement = 0;         // RMS displacement difference / largest FEM displacement
  double rms_work = 0;                 // RMS work difference / largest FEM work
  int evaluations = 0;                 // VDM runs of all cases
  std::vector<double> mean_relative_difference;  // per case, as mean_relative_difference()
};

// One line per finished piece of work (an FEM case, a VDM evaluation), for a progress display.
using CalibrationProgress = std::function<void(const std::string& line)>;

CalibrationResult calibrate_vdm(const vdm::SurfaceMesh& surface, const std::vector<LoadCase>& cases,
                                const std::vector<CaseResult>& fem, const VdmParams& start,
                                const CalibrationProgress& progress = nullptr);

// The residuals of VDM with `params` on the cases against the FEM runs (params, cost,
// rms_displacement, rms_work, mean_relative_difference; evaluations = 1).
CalibrationResult evaluate_vdm(const vdm::SurfaceMesh& surface, const std::vector<LoadCase>& cases,
                               const std::vector<CaseResult>& fem, const VdmParams& params);

// An organ calibrated against the FEM on its default load cases: the fit, and the documented
// E, nu rule (engine/elastic_moduli.hpp) evaluated on the same cases.
struct OrganCalibration {
  CalibrationResult fit, rule;
};
// False (nothing run) when the organ's top patch holds no node to drive.
bool calibrate_organ(const vdm::SurfaceMesh& surface, const vdm::fem::TetMesh& tets, double young, double poisson,
                     int steps, OrganCalibration& out, const CalibrationProgress& progress = nullptr);

// Default load cases for any organ: the lowest `base` fraction of its height held, the top
// patch (nodes within `patch` of the height from the top and within `patch` x the size of
// the top's centre) pressed down, and pulled sideways along x, by `depth` x the height each,
// over `steps`. Tracks every surface node.
std::vector<LoadCase> organ_load_cases(const vdm::SurfaceMesh& surface, int steps, double depth = 0.05,
                                       double base = 0.1, double patch = 0.2);

// Writes the fitted parameters as a scene's organ.material block (YAML).
bool write_calibration_yaml(const std::string& path, const CalibrationResult& r, double young, double poisson,
                            const std::string& source, std::string& error);

}  // namespace vdmsim
