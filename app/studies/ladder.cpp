#include "app/studies/ladder.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

#include "app/studies/accuracy.hpp"
#include "app/studies/ladder_cases.hpp"
#include "engine/elastic_moduli.hpp"

namespace vdmsim {

namespace {

std::string millimetres(double metres) {
  std::ostringstream s;
  s << 1e3 * metres;
  return s.str();
}

}  // namespace

const char* to_string(LadderModel m) {
  switch (m) {
    case LadderModel::fem: return "fem";
    case LadderModel::vdm_paper: return "vdm_paper";
    case LadderModel::vdm_membrane: return "vdm_membrane";
    case LadderModel::vdm_core: return "vdm_core";
  }
  return "?";
}

std::vector<LadderConfig> ladder_configs(bool quick) {
  std::vector<LadderConfig> out;
  // One case: its reference FEM, the FEM on coarser meshes, then the surface models on
  // `model_mesh` (the VDM models at their rule's moduli, the core at each cell size).
  auto add_case = [&](const char* scenario, const char* which, int reference_mesh, const std::vector<int>& fem_meshes,
                      int model_mesh, const std::vector<double>& cells) {
    LadderConfig c;
    c.scenario = scenario;
    c.test_case = which;
    c.model = LadderModel::fem;
    c.reference = true;
    c.mesh = reference_mesh;
    out.push_back(c);
    c.reference = false;
    for (int m : fem_meshes) {
      c.mesh = m;
      out.push_back(c);
    }
    c.mesh = model_mesh;
    for (LadderModel m : {LadderModel::vdm_paper, LadderModel::vdm_membrane}) {
      c.model = m;
      out.push_back(c);
    }
    c.model = LadderModel::vdm_core;
    for (double h : cells) {
      c.cell_size = h;
      out.push_back(c);
    }
  };
  // The punch: FEM blocks graded to 0.5 / 0.35 / 0.25 mm at the rim (punch_level); the
  // surface models on the reference's surface.
  if (quick)
    add_case("punch", "punch", 1, {0}, 1, {0.01, 0.005});
  else
    add_case("punch", "punch", 2, {1, 0}, 2, {0.01, 0.005, 0.0025});
  // The beams: FEM on 2 / 4 / 6 cells across; the surface models on the 4-cell mesh's surface.
  for (const char* which : {"stretch", "bend", "twist"}) {
    if (quick)
      add_case("beams", which, 4, {2}, 4, {0.01, 0.005});
    else
      add_case("beams", which, 6, {4, 2}, 4, {0.01, 0.005, 0.0025});
  }
  // The liver probe: the FEM on the 2.5k liver (the finest whose pressing steps take seconds,
  // not minutes) and on the 642-node one; the surface models on the reference's surface, so
  // that the probe holds the same nodes. With --quick all on the 642-node liver.
  if (quick)
    add_case("liver_probe", "liver_probe", 3, {}, 3, {0.016, 0.008});
  else
    add_case("liver_probe", "liver_probe", 4, {3}, 4, {0.016, 0.008, 0.004});
  return out;
}

bool select_ladder_configs(bool quick, const std::string& scenario, std::vector<int>& indices, std::string& error) {
  const std::vector<LadderConfig> all = ladder_configs(quick);
  std::vector<std::string> known;
  for (const LadderConfig& c : all)
    if (std::find(known.begin(), known.end(), c.scenario) == known.end()) known.push_back(c.scenario);
  if (!scenario.empty() && std::find(known.begin(), known.end(), scenario) == known.end()) {
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    error = "--scenario: unknown scenario '" + scenario + "' of the model ladder; known scenarios: " + list;
    return false;
  }
  indices.clear();
  for (size_t i = 0; i < all.size(); ++i)
    if (scenario.empty() || all[i].scenario == scenario) indices.push_back(int(i));
  return true;
}

std::string ladder_config_name(const LadderConfig& c) {
  std::ostringstream s;
  s << c.test_case << "_" << to_string(c.model) << "_";
  if (c.scenario == "punch")
    s << "m" << c.mesh;
  else if (c.scenario == "beams")
    s << "c" << c.mesh;
  else
    s << "L" << c.mesh;
  if (c.model == LadderModel::vdm_core) s << "_h" << millimetres(c.cell_size) << "mm";
  if (c.reference) s << "_reference";
  return s.str();
}

std::string ladder_resolution(const LadderConfig& c) {
  std::ostringstream s;
  if (c.scenario == "punch")
    s << "block graded to " << millimetres(punch_level(c.mesh).h_min) << " mm at the rim";
  else if (c.scenario == "beams")
    s << c.mesh << " cells across";
  else
    s << "liver L" << c.mesh;
  if (c.model == LadderModel::vdm_core) s << ", cell " << millimetres(c.cell_size) << " mm";
  return s.str();
}

std::string ladder_config_text(const LadderConfig& c) {
  std::ostringstream s;
  s << std::setprecision(12) << "# A rung of `vdmsim accuracy --ladder`: what its result depends on.\n"
    << "name: " << ladder_config_name(c) << "\n"
    << "case: " << c.test_case << "\n"
    << "model: " << to_string(c.model) << "\n"
    << "mesh: " << ladder_resolution(c) << "\n"
    << "young_modulus: " << (c.scenario == "liver_probe" ? kLadderLiverYoung : kLadderCaseYoung) << "\n"
    << "poisson_ratio: " << kLadderPoisson << "\n";
  return s.str();
}

int ladder_frames() { return accuracy_frames(true); }

std::string ladder_scene_yaml(const LadderConfig& c, const std::string& mesh_dir) {
  std::ostringstream organ;
  organ << std::setprecision(12);
  const double e = kLadderLiverYoung;
  switch (c.model) {
    case LadderModel::vdm_paper: {
      // The paper's model: the VDM moduli (here the documented rule's for E and nu, so that
      // every rung is the same tissue) and the paper's capsule.
      const vdm::VdmModuli m = vdm::vdm_moduli_from_elastic(e, kLadderPoisson);
      organ << "  material: {bulk_modulus: " << m.bulk << ", connectivity_modulus: " << m.connectivity
            << ", density: 1060, capsule: paper}\n";
      break;
    }
    case LadderModel::vdm_membrane:
    case LadderModel::fem:
      organ << "  material: {young_modulus: " << e << ", poisson_ratio: " << kLadderPoisson << ", density: 1060}\n";
      break;
    case LadderModel::vdm_core:
      organ << "  cell_size: " << c.cell_size << "\n"
            << "  material: {young_modulus: " << e << ", density: 1060}\n";
      break;
  }
  const std::string model = c.model == LadderModel::fem ? "fem" : c.model == LadderModel::vdm_core ? "vdm_core" : "vdm";
  return scenario_scene_yaml(ladder_config_name(c), "`vdmsim accuracy --ladder`", "probe_poke",
                             mesh_dir + "/" + level_mesh(c.mesh), model, organ.str(), "", ladder_frames());
}

}  // namespace vdmsim
