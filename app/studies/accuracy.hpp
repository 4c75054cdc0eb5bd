#pragma once
// The accuracy-versus-time study (`vdmsim accuracy`): the liver probe poke and grasp-and-lift
// run with one knob changed at a time (solver, tolerance, refresh period of the nonlinear
// terms, nonlinear iterations per step, mesh resolution, the capsule's form, model) and compared with a converged
// reference (finest mesh, tightest tolerance, refresh every step, several nonlinear
// iterations) on a common set of surface points. This file: the configurations, their scenes
// and the Pareto front; accuracy_command.hpp runs them.
#include <string>
#include <vector>

#include "engine/organ_solver.hpp"
#include "engine/settings.hpp"

namespace vdmsim {

// E (Pa) the fem and mass_spring configurations run with; their stiffness is then matched to
// the reference force (accuracy_errors.hpp).
constexpr double kAccuracyStartYoung = 5000;

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
  double bending = 0;          // vdm: the capsule's bending modulus D (N m; 0: none)
};

// The capsule column of accuracy.csv: the form, "+bending" with the bending term.
std::string capsule_label(const AccuracyConfig& c);

struct AccuracyRow {
  AccuracyConfig config;
  std::string scene_file;        // the scene this row ran, relative to DIR (runs/<index>_<name>/scene.yaml)
  int nodes = 0;
  double median_ms = 0, p95_ms = 0;  // time per step over the loaded frames, on the study's typical
                                     // node: as measured, over yardstick_ms, times the median
                                     // yardstick_ms of all the study's tasks
  double measured_median_ms = 0;     // the median as measured, on the node that ran it
  double yardstick_ms = 0;           // the yardstick's median step time, measured in the same task
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
  std::string scenario;     // only this scenario ("": all; with `ladder`, a case of the ladder)
  std::string only;         // only these knobs, comma-separated ("": all); the reference and
                            // the baseline always run (the errors are measured against them)
  int jobs = 0;             // configurations at a time on this machine (0: the number of cores)
  bool slurm = false;       // as a Slurm job array instead
  std::string partition;    // --slurm: the partition ("": the cluster's default)
  int max_parallel = 0;     // --slurm: array tasks at a time (0: all)
  int task = -1;            // run only this configuration (a Slurm array task)
  bool ladder = false;      // the model ladder (ladder.hpp) in place of the knobs
};

// The study's configurations (the first of each scenario is its reference).
std::vector<AccuracyConfig> accuracy_configs(bool quick);

// The indices in accuracy_configs(options.quick) of the configurations of options.scenario
// and options.only. False with `error` naming the option and the known values.
bool select_accuracy_configs(const AccuracyOptions& options, std::vector<int>& indices, std::string& error);

// The timing yardstick every configuration's task also runs (on the same node, right after it):
// the probe poke's baseline. Step times from different nodes compare through it.
AccuracyConfig yardstick_config(bool quick);

// Frames each configuration simulates: to the end of the scripts, or with --quick to the
// deepest press and the top of the lift.
int accuracy_frames(bool quick);

// A configuration's name ("probe_poke_tolerance_vdm_L4_structured_tol1e-03_r1_n1").
std::string config_name(const AccuracyConfig& c);

// The project's liver at `level`, as the study names its file ("liver_L4.obj").
std::string level_mesh(int level);

// The configuration's scene, a file `vdmsim run` runs; `mesh_dir`: the meshes' folder as
// the scene names it (relative to the scene file).
std::string accuracy_scene_yaml(const AccuracyConfig& c, int frames, const std::string& mesh_dir);

// A scene of `scenario`'s script (probe_poke | grasp_lift) on the liver `mesh` (as the scene
// names it) with `model`: `organ_lines` are the organ's further keys (indented two spaces,
// each line ending in a newline), `solver` the simulation.solver value ("": the defaults);
// `writer` names what wrote it, in the file's first comment.
std::string scenario_scene_yaml(const std::string& name, const std::string& writer, const std::string& scenario,
                                const std::string& mesh, const std::string& model, const std::string& organ_lines,
                                const std::string& solver, int frames);

// Marks the rows on each scenario's Pareto front (median_ms, rms_mm; the reference excluded).
void mark_pareto(std::vector<AccuracyRow>& rows);

}  // namespace vdmsim
