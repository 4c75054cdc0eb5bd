#pragma once
// The model ladder of `vdmsim accuracy --ladder`: on the FEM cases (the flat punch, the beams
// stretched, bent and twisted) and on the liver probe, the tissue models side by side, each
// measured against the case's converged FEM: the paper's VDM (the VDM moduli, the paper's
// capsule), the membrane VDM (E and nu), the elastic core at several cell sizes, and the FEM
// itself at coarser meshes. This file: the rungs and what each runs; ladder_command.hpp runs
// them as the study's tasks.
#include <string>
#include <vector>

namespace vdmsim {

enum class LadderModel { fem, vdm_paper, vdm_membrane, vdm_core };
const char* to_string(LadderModel m);

struct LadderConfig {
  std::string scenario;   // punch | beams | liver_probe (--scenario)
  std::string test_case;  // punch | stretch | bend | twist | liver_probe
  LadderModel model = LadderModel::fem;
  bool reference = false; // the case's converged FEM: every rung of the case is measured against it
  int mesh = 0;           // punch: the FEM block's level (punch_level); beams: cells across the
                          // section; liver_probe: the liver's level (3: 642 ... 5: 10242 nodes)
  double cell_size = 0;   // vdm_core: the core's cell (m)
};

// The ladder's rungs, each case's reference first. With `quick` the references are one mesh
// coarser and the finest core and the coarsest FEM rung are left out.
std::vector<LadderConfig> ladder_configs(bool quick);

// Indices in ladder_configs(quick) of the rungs of `scenario` ("": all); false with `error`
// naming the known scenarios.
bool select_ladder_configs(bool quick, const std::string& scenario, std::vector<int>& indices, std::string& error);

// A rung's name, its folder's ("bend_vdm_core_c4_h5mm", "punch_fem_m2_reference").
std::string ladder_config_name(const LadderConfig& c);

// The rung's mesh and resolution in words ("rim 0.25 mm", "4 cells across, cell 5 mm", "liver L5").
std::string ladder_resolution(const LadderConfig& c);

// What the rung's result depends on, in words: one line per parameter (its run folder's
// rung.txt, hashed with the program to tell a finished rung).
std::string ladder_config_text(const LadderConfig& c);

// liver_probe rungs: the scene (the accuracy study's probe poke, kinematic contact, on the
// liver at c.mesh, E 5 kPa, to the deepest press: ladder_frames()); `mesh_dir` as the scene
// names the meshes' folder.
std::string ladder_scene_yaml(const LadderConfig& c, const std::string& mesh_dir);
int ladder_frames();

// Young's modulus and Poisson's ratio of the FEM cases (the punch and the beams: docs/model.md,
// "Against the FEM") and of the liver probe.
constexpr double kLadderCaseYoung = 3000, kLadderLiverYoung = 5000, kLadderPoisson = 0.45;

}  // namespace vdmsim
