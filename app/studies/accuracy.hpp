#pragma once
// The accuracy-versus-time study (`vdmsim accuracy`): the liver probe poke and grasp-and-lift
// run with one knob changed at a time (solver, tolerance, refresh period of the nonlinear
// terms, nonlinear iterations per step, mesh resolution, the capsule's form, model) and compared with a converged
// reference (finest mesh, tightest tolerance, refresh every step, several nonlinear
// iterations) on a common set of surface points.
#include <ostream>
#include <string>
#include <vector>

#include "engine/organ_solver.hpp"
#include "engine/settings.hpp"

namespace vdmsim {

struct AccuracyConfig {
  std::string scenario;        // probe_poke | grasp_lift
  std::string varied;          // reference | baseline | solver | tolerance | refresh | nonlinear | mesh | capsule | model
  vdm::ModelKind model = vdm::ModelKind::vdm;
  int level = 5;               // liver mesh level (3: 642, 4: 2562, 5: 10242, 6: 40962 nodes)
  vdm::SolverMethod method = vdm::SolverMethod::structured;
  double tolerance = 1e-8;
  int refresh_every = 1;
  int nonlinear_iterations = 1;
  vdm::CapsuleForm capsule = vdm::CapsuleForm::membrane;  // vdm: the capsule term's form (docs/model.md)
};

struct AccuracyRow {
  AccuracyConfig config;
  std::string scene_file;        // the scene this row ran (DIR/scenes/...)
  int nodes = 0;
  double median_ms = 0, p95_ms = 0;  // engine time per step over the loaded frames
  double rms_mm = 0, max_mm = 0;     // surface displacement error against the reference
  double rms_vs_baseline_mm = -1;    // vdm rows on the baseline's mesh: RMS error against the
                                     // baseline (the solver knobs' own error); -1: not applicable
  double force_rms_n = 0;            // RMS over loaded frames of |F - F_ref| (instrument force)
  double force_rel = 0;              // force_rms_n / peak |F_ref|
  double volume_rel_error = 0;       // max over frames of |V - V0| / V0
  double young_modulus = 0;          // fem, mass_spring: E matched to the reference force
  bool pareto = false;               // on the time-error Pareto front of its scenario
  bool failed = false;
  std::string note;
};

struct AccuracyOptions {
  std::string out_dir = "out/accuracy";
  bool quick = false;
};

// The study's configurations (the first of each scenario is its reference).
std::vector<AccuracyConfig> accuracy_configs(bool quick);

// Marks the rows on each scenario's Pareto front (median_ms, rms_mm; the reference excluded).
void mark_pareto(std::vector<AccuracyRow>& rows);

// Runs the study: DIR/accuracy.csv, DIR/accuracy.png, DIR/recommendations.md, and the scenes
// and meshes it ran in DIR/scenes, DIR/meshes. Returns the exit code.
int run_accuracy(const AccuracyOptions& options, std::ostream& out, std::ostream& err);

}  // namespace vdmsim
