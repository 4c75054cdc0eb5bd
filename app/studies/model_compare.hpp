#pragma once
// Runs the same quasi-static load case on the VDM engine and on the FEM reference (and on
// the mass-spring baseline), so that their surface displacements, volumes and end forces can
// be compared step by step. Used by `vdmsim paper beam-*`, `vdmsim calibrate` and the
// accuracy study.
#include <string>
#include <vector>

#include "engine/fem/fem_model.hpp"
#include "engine/mass_spring.hpp"
#include "engine/settings.hpp"
#include "engine/tissue_model.hpp"
#include "engine/types.hpp"

namespace vdmsim {

// A load case on an organ's surface nodes: `fixed` entries held at zero, `moved` nodes
// driven to targets[k] (one row per moved node) at step k = 1..steps.
struct LoadCase {
  std::string name;
  vdm::FlagMat fixed;                  // surface nodes x 3
  std::vector<int> moved;
  std::vector<vdm::NodeMat> targets;   // per step (k = 1..steps): moved.size() x 3 (m)
  std::vector<int> tracked;            // surface nodes whose displacement is recorded
  int steps() const { return static_cast<int>(targets.size()); }
};

// What one model did in a case; index k = 0 (rest) .. steps.
struct CaseResult {
  std::vector<vdm::NodeMat> u;         // tracked.size() x 3 displacements (m)
  std::vector<double> volume_rel;      // (V - V_0) / V_0
  std::vector<double> work;            // sum over moved nodes of reaction . displacement (J)
  std::vector<double> step_ms;
  bool converged = true;
};

struct VdmParams {
  double bulk = 20000;                 // B (Pa)
  double connectivity = 2000;          // B_ij (Pa)
  vdm::CapsuleForm capsule = vdm::CapsuleForm::membrane;
  double bending = 0;                  // the capsule's bending modulus D (N m; membrane capsules)
  vdm::SolverSettings solver;
};

CaseResult run_vdm_case(const vdm::SurfaceMesh& surface, const VdmParams& params, const LoadCase& c);
// VDM's surface on the elastic core (engine/core): Young's modulus, cell size (0: V/A), tie.
CaseResult run_core_case(const vdm::SurfaceMesh& surface, double young, double cell_size, const LoadCase& c,
                         double tie = 4);
CaseResult run_fem_case(const vdm::fem::TetMesh& mesh, double young, double poisson, const LoadCase& c,
                        const vdm::fem::FemSettings& settings = {});
CaseResult run_mass_spring_case(const vdm::SurfaceMesh& surface, const vdm::MassSpringDef& params, const LoadCase& c);

// Mean over steps k >= 1 and tracked nodes of | |u_a| - |u_b| | / |u_b| (nodes that b does not
// move, |u_b| below 1e-9 of the largest, are left out).
double mean_relative_difference(const CaseResult& a, const CaseResult& b);

}  // namespace vdmsim
