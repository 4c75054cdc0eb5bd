#include "app/studies/paper_cube.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "engine/sim_state.hpp"
#include "engine/tissue_model.hpp"

namespace vdmsim {
namespace {

CubeResult run_cube(const CubeCompression& cfg, const vdm::NodeMat* bulk_override,
                    const std::vector<std::pair<std::string, vdm::Vec3>>& probes) {
  const double L = cfg.side;
  vdm::TissueDef def = vdm::default_tissue(vdm::make_box(vdm::Vec3(L, L, L), cfg.cells, cfg.cells, cfg.cells));
  const int n = def.mesh.node_count();
  def.bulk = cfg.bulk;
  if (bulk_override) def.bulk_modulus = *bulk_override;
  def.connectivity_modulus = cfg.connectivity;
  def.capsule = cfg.capsule;
  def.solver = cfg.solver;
  def.fixed = vdm::FlagMat::Zero(n, 3);
  const double tol = 1e-9 * L;
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -L / 2 + tol) def.fixed.row(i).setOnes();  // on the table
  vdm::TissueModel model;
  std::string err;
  if (!vdm::build_tissue_model(def, model, err)) throw std::runtime_error("cube model: " + err);

  vdm::SimState state = vdm::make_sim_state(model);
  vdm::StepInput input = vdm::make_step_input(model);
  // The plate holds the top face's z; x and y slide freely.
  for (int i = 0; i < n; ++i)
    if (model.rest.positions(i, 2) > L / 2 - tol) input.prescribed(i, 2) = 1;

  CubeResult r;
  for (const auto& p : probes) {
    PointSeries s;
    s.name = p.first;
    s.node = vdm::nearest_node(model.rest.positions, p.second);
    s.rest = model.rest.positions.row(s.node).transpose();
    r.points.push_back(s);
  }
  auto record = [&](const vdm::SimState& st) {
    for (auto& p : r.points) {
      p.displacement.push_back(st.u.row(p.node).transpose());
      p.stress.push_back(st.stress.row(p.node).transpose());
    }
    r.volume_rel_error.push_back(st.volume_rel_error);
    r.pressure.push_back(st.pressure);
    r.iterations.push_back(st.stats.iterations);
  };
  record(state);
  for (int k = 1; k <= cfg.steps; ++k) {
    const double travel = -cfg.compression * L * double(k) / cfg.steps;
    for (int i = 0; i < n; ++i)
      if (input.prescribed(i, 2)) input.prescribed_u(i, 2) = travel;
    vdm::step(model, input, state);
    record(state);
  }
  return r;
}

}  // namespace

const char* to_string(AnisotropyCase c) {
  switch (c) {
    case AnisotropyCase::uniform: return "uniform";
    case AnisotropyCase::x_infinite: return "x_infinite";
    case AnisotropyCase::prefer_y: return "prefer_y";
  }
  return "unknown";
}

vdm::SolverSettings CubeCompression::default_solver() {
  vdm::SolverSettings s;
  s.method = vdm::SolverMethod::structured;
  s.tolerance = 1e-10;
  s.nonlinear_iterations = 1;      // the paper: one update of the nonlinear terms per step
  s.nonlinear_tolerance = 1e-10;
  return s;
}

CubeResult run_cube_stress(const CubeCompression& cfg) {
  const double L = cfg.side;
  return run_cube(cfg, nullptr,
                  {{"A", vdm::Vec3(0, -L / 2, L / 4)},
                   {"B", vdm::Vec3(0, -L / 2, 0)},
                   {"C", vdm::Vec3(0, -L / 2, -L / 4)}});
}

CubeResult run_anisotropy(const CubeCompression& cfg, AnisotropyCase which) {
  const double L = cfg.side;
  const int n = vdm::make_box(vdm::Vec3(L, L, L), cfg.cells, cfg.cells, cfg.cells).node_count();
  vdm::NodeMat bulk = vdm::NodeMat::Constant(n, 3, cfg.bulk);
  if (which == AnisotropyCase::x_infinite) bulk.col(0).setConstant(std::numeric_limits<double>::infinity());
  if (which == AnisotropyCase::prefer_y) bulk.col(1).setConstant(cfg.bulk * cfg.preferred_ratio);
  return run_cube(cfg, &bulk,
                  {{"A", vdm::Vec3(0, 0, L / 2)},
                   {"B", vdm::Vec3(0, -L / 2, 0)},
                   {"C", vdm::Vec3(L / 2, 0, 0)}});
}

bool write_cube_stress_csv(const std::string& path, const CubeResult& r, std::string& error) {
  std::ofstream f(path);
  if (!f) {
    error = path + ": cannot open for writing";
    return false;
  }
  f.precision(10);
  f << "step,point,sx,sy,sz\n";
  for (size_t k = 0; k < r.volume_rel_error.size(); ++k)
    for (const auto& p : r.points)
      f << k << ',' << p.name << ',' << p.stress[k].x() << ',' << p.stress[k].y() << ','
        << p.stress[k].z() << '\n';
  f.flush();
  if (!f) {
    error = path + ": write failed";
    return false;
  }
  return true;
}

bool write_anisotropy_csv(const std::string& path, const std::vector<AnisotropyCase>& cases,
                          const std::vector<CubeResult>& results, std::string& error) {
  std::ofstream f(path);
  if (!f) {
    error = path + ": cannot open for writing";
    return false;
  }
  f.precision(10);
  f << "case,step,point,ux,uy,uz,volume_rel_error\n";
  for (size_t c = 0; c < cases.size(); ++c) {
    const CubeResult& r = results[c];
    for (size_t k = 0; k < r.volume_rel_error.size(); ++k)
      for (const auto& p : r.points)
        f << to_string(cases[c]) << ',' << k << ',' << p.name << ',' << p.displacement[k].x() << ','
          << p.displacement[k].y() << ',' << p.displacement[k].z() << ',' << r.volume_rel_error[k]
          << '\n';
  }
  f.flush();
  if (!f) {
    error = path + ": write failed";
    return false;
  }
  return true;
}

}  // namespace vdmsim
