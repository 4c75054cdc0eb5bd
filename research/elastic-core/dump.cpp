// Research (not built by CMake): writes the punch block's and the 4-cell beam's tet meshes,
// load cases and the project's FEM results at nu = 0.45 and nu = 0 into $CORE_DATA (default
// ./data), for the elastic-core prototype (core.py).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include "app/scene/organ_generator.hpp"
#include "app/simulation/tet_mesher.hpp"
#include "app/studies/calibrate.hpp"
#include "app/studies/model_compare.hpp"
#include "app/studies/paper_beam.hpp"
#include "engine/elastic_moduli.hpp"
#include "engine/fem/tet_mesh.hpp"
using namespace vdmsim;
static const std::string D = std::string(std::getenv("CORE_DATA") ? std::getenv("CORE_DATA") : "data") + "/";
template <class M> void save(const std::string& name, const M& m) {
  std::ofstream f(D + name); f.precision(17);
  for (Eigen::Index i = 0; i < m.rows(); ++i) { for (Eigen::Index j = 0; j < m.cols(); ++j) f << (j ? " " : "") << m(i, j); f << "\n"; }
}
void save_ints(const std::string& name, const std::vector<int>& v) { std::ofstream f(D + name); for (int x : v) f << x << "\n"; }
void save_mesh(const std::string& nm, const vdm::fem::TetMesh& t) {
  save(nm + "_P.txt", t.positions); save(nm + "_tets.txt", t.tets); save(nm + "_T.txt", t.surface.triangles);
  std::ofstream(D + nm + "_ns.txt") << t.surface_nodes << "\n";
}
int main(int argc, char** argv) {
  std::string what = argc > 1 ? argv[1] : "all";
  const double nus[2] = {0.45, 0.0};
  if (what == "all" || what == "punch") {
    BoxWithDisk spec; spec.disk_radius = 0.005; spec.h_min = 0.25e-3; spec.grade = 0.2; spec.h_max = 0.007;
    vdm::fem::TetMesh tets; std::string err;
    if (!mesh_box_with_disk(spec, tets, err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    const vdm::SurfaceMesh& s = tets.surface; const int n = s.node_count(); const double top = 0.025, tol = 1e-9;
    LoadCase lc; lc.fixed = vdm::FlagMat::Zero(n, 3);
    for (int i = 0; i < n; ++i) { auto X = s.positions.row(i);
      if (X(2) < -top + tol) lc.fixed.row(i).setOnes();
      if (X(2) > top - tol && std::hypot(X(0), X(1)) <= 0.005 + tol) lc.moved.push_back(i);
      lc.tracked.push_back(i); }
    for (int k = 1; k <= 4; ++k) { vdm::NodeMat t = vdm::NodeMat::Zero(lc.moved.size(), 3); t.col(2).setConstant(-0.001 * k / 4); lc.targets.push_back(t); }
    save_mesh("punch", tets); save("punch_fixed.txt", lc.fixed.cast<int>()); save_ints("punch_moved.txt", lc.moved);
    for (double nu : nus) {
      CaseResult f = run_fem_case(tets, 3000, nu, lc);
      save("punch_fem_nu" + std::to_string(int(100 * nu)) + "_u.txt", f.u.back());
      std::printf("fem punch nu %.2f force %.5f\n", nu, f.work.back() / 0.001);
    }
  }
  if (what == "all" || what == "beam") {
    BeamConfig c; c.cells_across = 4; c.cells_along = 20; c.steps = 5; c.stretch = 0.2; c.bend = 0.2; c.twist_deg = 30; c.calibrate = false;
    c.fem = vdm::fem::FemSettings{};
    vdm::fem::TetMesh tets = vdm::fem::make_box_tets(vdm::Vec3(c.width, c.length, c.width), 4, 20, 4, vdm::Vec3(0, c.length / 2, 0));
    save_mesh("beam", tets);
    for (BeamCase w : {BeamCase::stretch, BeamCase::bend, BeamCase::twist}) {
      LoadCase lc = beam_load_case(c, w);
      std::vector<int> abc = lc.tracked; lc.tracked.clear(); for (int i = 0; i < tets.surface.node_count(); ++i) lc.tracked.push_back(i);
      std::string nm = std::string("beam_") + to_string(w);
      save(nm + "_fixed.txt", lc.fixed.cast<int>()); save_ints(nm + "_moved.txt", lc.moved); save_ints("beam_abc.txt", abc);
      for (size_t k = 0; k < lc.targets.size(); ++k) save(nm + "_target" + std::to_string(k) + ".txt", lc.targets[k]);
      for (double nu : nus) {
        CaseResult f = run_fem_case(tets, 3000, nu, lc, c.fem);
        save(nm + "_fem_nu" + std::to_string(int(100 * nu)) + "_u.txt", f.u.back());
        std::printf("fem %s nu %.2f done\n", nm.c_str(), nu);
      }
    }
  }
  if (what == "liver") {  // the project's liver at level 3 (642 nodes), calibrate's default load cases
    const vdm::SurfaceMesh surface = make_liver_mesh(3);
    vdm::fem::TetMesh tets; std::string err;
    if (!tetrahedralize(surface, 0, tets, err)) { std::fprintf(stderr, "%s\n", err.c_str()); return 1; }
    save_mesh("liver", tets);
    const std::vector<LoadCase> cases = organ_load_cases(tets.surface, 4);
    for (size_t c = 0; c < cases.size(); ++c) {
      const LoadCase& lc = cases[c]; const std::string nm = "liver_case" + std::to_string(c);
      save(nm + "_fixed.txt", lc.fixed.cast<int>()); save_ints(nm + "_moved.txt", lc.moved);
      for (size_t k = 0; k < lc.targets.size(); ++k) save(nm + "_target" + std::to_string(k) + ".txt", lc.targets[k]);
      CaseResult f = run_fem_case(tets, 3000, 0.45, lc);
      save(nm + "_fem_nu45_u.txt", f.u.back());
      const vdm::VdmModuli mod = vdm::vdm_moduli_from_elastic(3000, 0.45);
      VdmParams p; p.bulk = mod.bulk; p.connectivity = mod.connectivity; p.solver.method = vdm::SolverMethod::direct; p.solver.tolerance = 1e-10;
      save(nm + "_vdm_rule_u.txt", run_vdm_case(tets.surface, p, lc).u.back());
      std::printf("fem %s (%s) done, %zu tracked\n", nm.c_str(), lc.name.c_str(), lc.tracked.size());
    }
  }
  return 0;
}
