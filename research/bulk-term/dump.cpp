// Scratch: dumps the punch block and beam surfaces, load cases, FEM and VDM fields for the Python prototype.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include "app/simulation/tet_mesher.hpp"
#include "app/studies/model_compare.hpp"
#include "app/studies/paper_beam.hpp"
#include "engine/elastic_moduli.hpp"
#include "engine/fem/tet_mesh.hpp"
using namespace vdmsim;
// Output folder: $BULK_TERM_DATA or ./data
static const std::string D = std::string(std::getenv("BULK_TERM_DATA") ? std::getenv("BULK_TERM_DATA") : "data") + "/";
template <class M> void save(const std::string& name, const M& m) {
  std::ofstream f(D + name); f.precision(17);
  for (Eigen::Index i = 0; i < m.rows(); ++i) { for (Eigen::Index j = 0; j < m.cols(); ++j) f << (j ? " " : "") << m(i, j); f << "\n"; }
}
void save_ints(const std::string& name, const std::vector<int>& v) { std::ofstream f(D + name); for (int x : v) f << x << "\n"; }
VdmParams params(vdm::CapsuleForm c) {
  const vdm::VdmModuli mod = vdm::vdm_moduli_from_elastic(3000, 0.45);
  VdmParams p; p.bulk = mod.bulk; p.connectivity = mod.connectivity; p.capsule = c;
  p.solver.method = vdm::SolverMethod::direct; p.solver.tolerance = 1e-10;
  if (c == vdm::CapsuleForm::corotational) p.solver.nonlinear_iterations = 50;
  return p;
}
int main(int argc, char** argv) {
  std::string what = argc > 1 ? argv[1] : "all";
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
    save("punch_X.txt", s.positions); save("punch_T.txt", s.triangles); save("punch_fixed.txt", lc.fixed.cast<int>()); save_ints("punch_moved.txt", lc.moved);
    CaseResult v = run_vdm_case(s, params(vdm::CapsuleForm::membrane), lc);
    save("punch_vdm_membrane_u.txt", v.u.back()); std::printf("vdm punch force %.5f\n", v.work.back() / 0.001);
    CaseResult f = run_fem_case(tets, 3000, 0.45, lc);
    save("punch_fem_u.txt", f.u.back()); std::printf("fem punch force %.5f\n", f.work.back() / 0.001);
  }
  if (what == "all" || what == "beam") {
    BeamConfig c; c.cells_across = 4; c.cells_along = 20; c.steps = 10; c.stretch = 0.2; c.bend = 0.2; c.twist_deg = 30; c.calibrate = false;
    c.fem = vdm::fem::FemSettings{};
    vdm::fem::TetMesh tets = vdm::fem::make_box_tets(vdm::Vec3(c.width, c.length, c.width), 4, 20, 4, vdm::Vec3(0, c.length / 2, 0));
    const vdm::SurfaceMesh& s = tets.surface;
    save("beam_X.txt", s.positions); save("beam_T.txt", s.triangles);
    for (BeamCase w : {BeamCase::stretch, BeamCase::bend, BeamCase::twist}) {
      LoadCase lc = beam_load_case(c, w);
      std::vector<int> abc = lc.tracked; lc.tracked.clear(); for (int i = 0; i < s.node_count(); ++i) lc.tracked.push_back(i);
      std::string nm = std::string("beam_") + to_string(w);
      save(nm + "_fixed.txt", lc.fixed.cast<int>()); save_ints(nm + "_moved.txt", lc.moved); save_ints("beam_abc.txt", abc);
      for (size_t k = 0; k < lc.targets.size(); ++k) save(nm + "_target" + std::to_string(k) + ".txt", lc.targets[k]);
      for (auto form : {vdm::CapsuleForm::membrane, vdm::CapsuleForm::corotational}) {
        CaseResult v = run_vdm_case(s, params(form), lc); save(nm + "_vdm_" + vdm::to_string(form) + "_u.txt", v.u.back());
        VdmParams sk = params(form); sk.bulk = 1e-4 * sk.connectivity;
        v = run_vdm_case(s, sk, lc); save(nm + "_vdm_" + vdm::to_string(form) + "_skin_u.txt", v.u.back());
      }
      c.steps = 5; LoadCase lf = beam_load_case(c, w); lf.tracked = lc.tracked; c.steps = 10;
      CaseResult f = run_fem_case(tets, 3000, 0.45, lf, c.fem); save(nm + "_fem4_u.txt", f.u.back());
    }
  }
  if (what == "beam6") {  // the finer beam surface (6 cells across, as the docs' finer FEM): surface and load cases only
    BeamConfig c; c.cells_across = 6; c.cells_along = 30; c.steps = 10; c.stretch = 0.2; c.bend = 0.2; c.twist_deg = 30;
    const vdm::SurfaceMesh s = vdm::fem::make_box_tets(vdm::Vec3(c.width, c.length, c.width), 6, 30, 6, vdm::Vec3(0, c.length / 2, 0)).surface;
    save("beam6_X.txt", s.positions); save("beam6_T.txt", s.triangles);
    for (BeamCase w : {BeamCase::stretch, BeamCase::bend, BeamCase::twist}) {
      LoadCase lc = beam_load_case(c, w);
      std::string nm = std::string("beam6_") + to_string(w);
      save(nm + "_fixed.txt", lc.fixed.cast<int>()); save_ints(nm + "_moved.txt", lc.moved); save_ints("beam6_abc.txt", lc.tracked);
      for (size_t k = 0; k < lc.targets.size(); ++k) save(nm + "_target" + std::to_string(k) + ".txt", lc.targets[k]);
    }
  }
  return 0;
}
