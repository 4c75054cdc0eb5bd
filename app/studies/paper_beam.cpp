#include "app/studies/paper_beam.hpp"

#include <cmath>
#include <fstream>
#include <limits>

#include "engine/fem/tet_mesh.hpp"
#include "engine/geometry.hpp"

namespace vdmsim {
namespace {

vdm::fem::TetMesh beam_mesh(const BeamConfig& c) {
  return vdm::fem::make_box_tets(vdm::Vec3(c.width, c.length, c.width), c.cells_across, c.cells_along,
                                 c.cells_across, vdm::Vec3(0, c.length / 2, 0));
}

}  // namespace

const char* to_string(BeamCase c) {
  switch (c) {
    case BeamCase::stretch: return "stretch";
    case BeamCase::bend: return "bend";
    case BeamCase::twist: return "twist";
  }
  return "unknown";
}

BeamConfig::BeamConfig() {
  vdm.bulk = 20000;
  vdm.connectivity = 2000;
  vdm.solver.method = vdm::SolverMethod::direct;
  vdm.solver.tolerance = 1e-10;
  fem.nodal_volumetric = false;
}

LoadCase beam_load_case(const BeamConfig& c, BeamCase which) {
  const vdm::SurfaceMesh s = vdm::fem::make_box_tets(vdm::Vec3(c.width, c.length, c.width), c.cells_across,
                                                     c.cells_along, c.cells_across, vdm::Vec3(0, c.length / 2, 0))
                                 .surface;
  const int n = s.node_count();
  const double tol = 1e-9 * c.length;
  LoadCase lc;
  lc.name = to_string(which);
  lc.fixed = vdm::FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i) {
    if (s.positions(i, 1) < tol) lc.fixed.row(i).setOnes();
    if (s.positions(i, 1) > c.length - tol) lc.moved.push_back(i);
  }
  for (double f : {0.25, 0.5, 0.75}) lc.tracked.push_back(vdm::nearest_node(s.positions, vdm::Vec3(0, f * c.length, c.width / 2)));
  const vdm::Vec3 axis_point(0, c.length, 0);
  for (int k = 1; k <= c.steps; ++k) {
    const double a = double(k) / c.steps;
    vdm::NodeMat t(lc.moved.size(), 3);
    const double angle = a * c.twist_deg * 3.14159265358979323846 / 180;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, vdm::Vec3::UnitY()).toRotationMatrix();
    for (size_t j = 0; j < lc.moved.size(); ++j) {
      const vdm::Vec3 X = s.positions.row(lc.moved[j]);
      vdm::Vec3 u = vdm::Vec3::Zero();
      if (which == BeamCase::stretch) u = vdm::Vec3(0, a * c.stretch * c.length, 0);
      if (which == BeamCase::bend) u = vdm::Vec3(a * c.bend * c.length, 0, 0);
      if (which == BeamCase::twist) u = R * (X - axis_point) + axis_point - X;
      t.row(static_cast<Eigen::Index>(j)) = u.transpose();
    }
    lc.targets.push_back(t);
  }
  return lc;
}

BeamStudy run_beam_study(const BeamConfig& config, const std::vector<BeamCase>& which) {
  BeamStudy study;
  study.config = config;
  const vdm::fem::TetMesh mesh = beam_mesh(config);
  std::vector<LoadCase> cases;
  std::vector<CaseResult> fem;
  for (BeamCase w : which) {
    cases.push_back(beam_load_case(config, w));
    fem.push_back(run_fem_case(mesh, config.young, config.poisson, cases.back(), config.fem));
  }
  study.used = config.vdm;
  if (config.calibrate) {
    study.calibration = calibrate_vdm(mesh.surface, cases, fem, config.vdm);
    study.used = study.calibration.params;
  }
  for (size_t c = 0; c < which.size(); ++c) {
    BeamCaseResult r;
    r.which = which[c];
    r.fem = fem[c];
    r.vdm = run_vdm_case(mesh.surface, study.used, cases[c]);
    r.mean_relative_difference = mean_relative_difference(r.vdm, r.fem);
    study.cases.push_back(r);
  }
  return study;
}

bool write_beam_csv(const std::string& path, const BeamCaseResult& r, std::string& error) {
  std::ofstream f(path);
  if (!f) return error = path + ": cannot open for writing", false;
  f.precision(10);
  f << "step,point,vdm_disp,fem_disp,vdm_volume_rel_error,fem_volume_rel_error\n";
  const char* names[3] = {"A", "B", "C"};
  for (size_t k = 0; k < r.fem.u.size(); ++k)
    for (Eigen::Index p = 0; p < r.fem.u[k].rows(); ++p)
      f << k << ',' << names[p] << ',' << r.vdm.u[k].row(p).norm() << ',' << r.fem.u[k].row(p).norm() << ','
        << r.vdm.volume_rel[k] << ',' << r.fem.volume_rel[k] << '\n';
  f.flush();
  if (!f) return error = path + ": write failed", false;
  return true;
}

}  // namespace vdmsim
